#include "physics/box_mesh.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include <stdexcept>
#include <utility>

namespace physics {

TetMesh make_box_mesh(double lx, double ly, double lz, int nx, int ny, int nz)
{
  if (!(lx > 0 && ly > 0 && lz > 0) || !std::isfinite(lx) || !std::isfinite(ly) || !std::isfinite(lz) ||
      nx < 1 || ny < 1 || nz < 1)
    throw std::invalid_argument("box mesh: sizes must be positive and finite, counts >= 1");
  // 6 tetrahedra per cell, their node indices in int: a count past that ran on for hours filling memory
  if ((double)nx * ny * nz * 6 > 2e9) {
    char count[32];
    std::snprintf(count, sizeof count, "%.3g", (double)nx * ny * nz * 6);
    throw std::invalid_argument(std::string("box mesh: ") + count +
                                " tetrahedra, more than 32-bit indices hold");
  }
  TetMesh m;
  m.order = 1;
  auto id = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        m.nodes.push_back(lx * i / nx);
        m.nodes.push_back(ly * j / ny);
        m.nodes.push_back(lz * k / nz);
      }
  // The 6 monotone paths from corner (0,0,0) to (1,1,1): one tetrahedron each.
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto &p : perms) {
          int c[3] = {i, j, k}, t[4];
          t[0]     = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          const size_t first = m.elements.size();
          m.elements.insert(m.elements.end(), t, t + 4);
          if (element_signed_volume(m, m.nodes.data(), static_cast<int>(first / 4)) < 0)
            std::swap(m.elements[first + 2], m.elements[first + 3]);
        }
  return m;
}

} // namespace physics
