#include "physics/cloth_model.hpp"

#include <cmath>
#include <stdexcept>

namespace physics {

Cloth make_cloth(const ClothOptions &opt)
{
  if (opt.n < 2) throw std::invalid_argument("cloth needs at least 2 x 2 particles");
  if (!(opt.size > 0) || !(opt.total_mass > 0))
    throw std::invalid_argument("cloth size and mass must be positive");
  if (!(opt.k_stretch >= 0 && opt.k_shear >= 0 && opt.k_bend >= 0 && opt.damping >= 0))
    throw std::invalid_argument("spring stiffness and damping must be non-negative");
  Cloth        c;
  const int    n = opt.n;
  const double h = opt.size / (n - 1);
  c.n            = n;
  c.damping      = opt.damping;
  c.position.resize(n * n);
  c.velocity.assign(n * n, Eigen::Vector3d::Zero());
  c.mass.assign(n * n, opt.total_mass / (n * n));
  c.fixed.assign(n * n, 0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      c.position[i * n + j] = opt.hanging ? Eigen::Vector3d(j * h - opt.size / 2, -i * h, 0)
                                          : Eigen::Vector3d(j * h - opt.size / 2, 0, i * h - opt.size / 2);
  switch (opt.pins) {
  case ClothPins::FourCorners:
    c.fixed[(n - 1) * n] = c.fixed[n * n - 1] = 1;
    [[fallthrough]];
  case ClothPins::TwoCorners:
    c.fixed[0] = c.fixed[n - 1] = 1;
    break;
  case ClothPins::TopRow:
    for (int j = 0; j < n; ++j) c.fixed[j] = 1;
    break;
  case ClothPins::None:
    break;
  }
  auto add = [&](int i0, int j0, int i1, int j1, double k, SpringKind kind) {
    if (i1 < 0 || i1 >= n || j1 < 0 || j1 >= n || k == 0) return;
    Spring s;
    s.a = i0 * n + j0, s.b = i1 * n + j1, s.stiffness = k, s.kind = kind;
    s.rest_length = (c.position[s.b] - c.position[s.a]).norm();
    c.springs.push_back(s);
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      add(i, j, i, j + 1, opt.k_stretch, SpringKind::Stretch);
      add(i, j, i + 1, j, opt.k_stretch, SpringKind::Stretch);
      add(i, j, i + 1, j + 1, opt.k_shear, SpringKind::Shear);
      add(i, j + 1, i + 1, j, opt.k_shear, SpringKind::Shear);
      add(i, j, i, j + 2, opt.k_bend, SpringKind::Bend);
      add(i, j, i + 2, j, opt.k_bend, SpringKind::Bend);
    }
  return c;
}

std::string validate_cloth(const Cloth &c)
{
  const int np = c.particle_count();
  if (np == 0) return "cloth has no particles";
  if ((int)c.velocity.size() != np || (int)c.mass.size() != np || (int)c.fixed.size() != np)
    return "per-particle arrays differ in length";
  for (int p = 0; p < np; ++p) {
    if (!(c.mass[p] > 0) || !std::isfinite(c.mass[p]))
      return "particle " + std::to_string(p) + ": mass must be positive and finite";
    if (!c.position[p].allFinite() || !c.velocity[p].allFinite())
      return "particle " + std::to_string(p) + ": state is not finite";
  }
  for (size_t s = 0; s < c.springs.size(); ++s) {
    const Spring &sp = c.springs[s];
    if (sp.a < 0 || sp.a >= np || sp.b < 0 || sp.b >= np || sp.a == sp.b)
      return "spring " + std::to_string(s) + ": particle index out of range or repeated";
    if (!(sp.rest_length > 0) || !(sp.stiffness >= 0) || !std::isfinite(sp.rest_length) ||
        !std::isfinite(sp.stiffness))
      return "spring " + std::to_string(s) +
             ": rest length must be positive, stiffness non-negative, both finite";
  }
  if (!(c.damping >= 0) || !std::isfinite(c.damping)) return "damping must be non-negative and finite";
  if (c.sphere.enabled &&
      (!c.sphere.centre.allFinite() || !(c.sphere.radius > 0) || !std::isfinite(c.sphere.radius)))
    return "the sphere needs a finite centre and a positive finite radius";
  return "";
}

double cloth_energy(const Cloth &c)
{
  double e = 0;
  for (int p = 0; p < c.particle_count(); ++p)
    e += 0.5 * c.mass[p] * c.velocity[p].squaredNorm() - c.mass[p] * c.gravity.dot(c.position[p]);
  for (const Spring &s : c.springs) {
    const double stretch = (c.position[s.b] - c.position[s.a]).norm() - s.rest_length;
    e += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

double max_stretch_ratio(const Cloth &c)
{
  double worst = 0;
  for (const Spring &s : c.springs)
    if (s.kind == SpringKind::Stretch)
      worst = std::max(worst, (c.position[s.b] - c.position[s.a]).norm() / s.rest_length);
  return worst;
}

double max_stretch_ratio(const Cloth &c, const std::vector<int> &springs)
{
  double worst = 0;
  for (int k : springs) {
    const Spring &s = c.springs[k];
    worst           = std::max(worst, (c.position[s.b] - c.position[s.a]).norm() / s.rest_length);
  }
  return worst;
}

} // namespace physics
