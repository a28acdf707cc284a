#include "physics/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace physics {

double element_signed_volume(const TetMesh &mesh, const double *pos, int e)
{
  const int *n = &mesh.elements[static_cast<size_t>(e) * mesh.nodes_per_element()];
  double     d[3][3];
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) d[k][c] = pos[3 * n[k + 1] + c] - pos[3 * n[0] + c];
  const double det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                     d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                     d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
  return det / 6.0;
}

TetMesh promote_to_quadratic(const TetMesh &mesh)
{
  if (mesh.order == 2) return mesh;
  TetMesh out;
  out.order    = 2;
  out.nodes    = mesh.nodes;
  const int ne = mesh.element_count();
  out.elements.resize(static_cast<size_t>(ne) * 10);
  std::unordered_map<unsigned long long, int> edge_node;
  edge_node.reserve(static_cast<size_t>(ne) * 2);
  for (int e = 0; e < ne; ++e) {
    const int *c = &mesh.elements[4 * static_cast<size_t>(e)];
    int       *o = &out.elements[10 * static_cast<size_t>(e)];
    for (int k = 0; k < 4; ++k) o[k] = c[k];
    for (int k = 0; k < 6; ++k) {
      const int                a = c[kTetEdges[k][0]], b = c[kTetEdges[k][1]];
      const unsigned long long key =
        (static_cast<unsigned long long>(std::min(a, b)) << 32) | static_cast<unsigned>(std::max(a, b));
      auto it = edge_node.find(key);
      if (it == edge_node.end()) {
        const int id = out.node_count();
        for (int d = 0; d < 3; ++d)
          out.nodes.push_back(0.5 * (mesh.nodes[3 * a + d] + mesh.nodes[3 * b + d]));
        it = edge_node.emplace(key, id).first;
      }
      o[4 + k] = it->second;
    }
  }
  return out;
}

void renumber_nodes(TetMesh &mesh, const std::vector<int> &new_of_old)
{
  const int n = mesh.node_count();
  if (static_cast<int>(new_of_old.size()) != n)
    throw std::invalid_argument("renumber_nodes: permutation has wrong size");
  std::vector<double> nodes(mesh.nodes.size());
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) nodes[3 * new_of_old[i] + d] = mesh.nodes[3 * i + d];
  mesh.nodes.swap(nodes);
  for (int &v : mesh.elements) v = new_of_old[v];
}

namespace {

// The elements in the given order (order[k]: the element that becomes element k), each node list whole.
void reorder_elements(TetMesh &mesh, const std::vector<int> &order)
{
  const int        npe = mesh.nodes_per_element();
  std::vector<int> sorted(mesh.elements.size());
  for (size_t k = 0; k < order.size(); ++k)
    std::copy_n(mesh.elements.begin() + static_cast<size_t>(order[k]) * npe, npe, sorted.begin() + k * npe);
  mesh.elements.swap(sorted);
}

} // namespace

void sort_elements_by_lowest_node(TetMesh &mesh)
{
  const int        npe = mesh.nodes_per_element(), ne = mesh.element_count();
  std::vector<int> lowest(ne), order(ne);
  for (int e = 0; e < ne; ++e) {
    lowest[e] = *std::min_element(mesh.elements.begin() + static_cast<size_t>(e) * npe,
                                  mesh.elements.begin() + static_cast<size_t>(e + 1) * npe);
    order[e]  = e;
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return lowest[a] < lowest[b]; });
  reorder_elements(mesh, order);
}

void cluster_elements(TetMesh &mesh, int group)
{
  const int npe = mesh.nodes_per_element(), ne = mesh.element_count(), nn = mesh.node_count();
  if (group < 2 || ne <= group) return;
  std::vector<std::vector<int>> of_node(nn);
  for (int e = 0; e < ne; ++e)
    for (int c = 0; c < npe; ++c) of_node[mesh.elements[(size_t)e * npe + c]].push_back(e);
  std::vector<char> taken(ne, 0), in_group(nn, 0);
  std::vector<int>  score(ne, 0), order, touched, nodes;
  order.reserve(ne);
  int next = 0; // the first element (in the current order) not yet taken
  while ((int)order.size() < ne) {
    while (taken[next]) ++next;
    int pick = next;
    touched.clear();
    nodes.clear();
    for (int k = 0; k < group && pick >= 0; ++k) {
      taken[pick] = 1;
      order.push_back(pick);
      // the group's new nodes raise the score of the elements around them: the next element is the
      // one sharing the most nodes with the group (ties: the earliest in the current order)
      for (int c = 0; c < npe; ++c) {
        const int n = mesh.elements[(size_t)pick * npe + c];
        if (in_group[n]) continue;
        in_group[n] = 1;
        nodes.push_back(n);
        for (int e : of_node[n])
          if (!taken[e]) {
            if (score[e]++ == 0) touched.push_back(e);
          }
      }
      pick     = -1;
      int best = 0;
      for (int e : touched)
        if (!taken[e] && (score[e] > best || (score[e] == best && e < pick))) best = score[e], pick = e;
    }
    for (int e : touched) score[e] = 0;
    for (int n : nodes) in_group[n] = 0;
  }
  reorder_elements(mesh, order);
}

void validate_mesh(const TetMesh &mesh, const std::string &what, const std::vector<long long> &element_tags)
{
  const int n = mesh.node_count(), npe = mesh.nodes_per_element();
  auto      name = [&](size_t e) {
    return (int)element_tags.size() == mesh.element_count()
                  ? "element with tag " + std::to_string(element_tags[e])
                  : "element " + std::to_string(e);
  };
  if (mesh.order != 1 && mesh.order != 2) throw std::runtime_error(what + ": element order must be 1 or 2");
  if (mesh.element_count() == 0) throw std::runtime_error(what + ": mesh has no tetrahedra");
  if (mesh.elements.size() % npe)
    throw std::runtime_error(what + ": element list length is not a multiple of the element size");
  // an element's volume is a product of three coordinate differences: beyond this it overflows, and the
  // check below would call a sound element degenerate
  constexpr double coordinate_limit = 1e100;
  for (size_t k = 0; k < mesh.nodes.size(); ++k)
    if (!(std::fabs(mesh.nodes[k]) <= coordinate_limit)) {
      char text[96];
      std::snprintf(text, sizeof text, ": node %zu has coordinate %.6g, outside [-1e100, 1e100]", k / 3,
                    mesh.nodes[k]);
      throw std::runtime_error(what + text);
    }
  std::vector<char> used(n, 0);
  for (size_t k = 0; k < mesh.elements.size(); ++k) {
    const int v = mesh.elements[k];
    if (v < 0 || v >= n)
      throw std::runtime_error(what + ": " + name(k / npe) + " refers to node " + std::to_string(v) +
                               ", outside [0, " + std::to_string(n) + ")");
    used[v] = 1;
  }
  const int unused = static_cast<int>(std::count(used.begin(), used.end(), 0));
  if (unused) throw std::runtime_error(what + ": " + std::to_string(unused) + " nodes belong to no element");
  // Relative to the element's size, so that a tiny but well-shaped element passes.
  int    bad = 0, first_bad = -1;
  double first_volume = 0;
  for (int e = 0; e < mesh.element_count(); ++e) {
    const double vol = element_signed_volume(mesh, mesh.nodes.data(), e);
    const int   *c   = &mesh.elements[static_cast<size_t>(e) * npe];
    double       h2  = 0;
    for (const auto &ed : kTetEdges) {
      double l2 = 0;
      for (int d = 0; d < 3; ++d) {
        const double t = mesh.nodes[3 * c[ed[0]] + d] - mesh.nodes[3 * c[ed[1]] + d];
        l2 += t * t;
      }
      h2 = std::max(h2, l2);
    }
    if (!(vol > 1e-12 * h2 * std::sqrt(h2))) {
      if (first_bad < 0) {
        first_bad    = e;
        first_volume = vol;
      }
      ++bad;
    }
  }
  if (bad) {
    char volume[32];
    std::snprintf(volume, sizeof volume, "%.6g", first_volume);
    throw std::runtime_error(what + ": " + std::to_string(bad) +
                             " element(s) inverted or of zero volume; first: " + name(first_bad) +
                             " with signed volume " + volume);
  }
}

std::vector<int> nodes_in_box(const TetMesh &mesh, const std::array<double, 3> &lo,
                              const std::array<double, 3> &hi, double tol)
{
  std::vector<int> out;
  for (int i = 0; i < mesh.node_count(); ++i) {
    bool in = true;
    for (int d = 0; d < 3; ++d)
      in = in && mesh.nodes[3 * i + d] >= lo[d] - tol && mesh.nodes[3 * i + d] <= hi[d] + tol;
    if (in) out.push_back(i);
  }
  return out;
}

std::vector<int> nodes_beyond_plane(const TetMesh &mesh, int axis, double value, int side, double tol)
{
  std::vector<int> out;
  for (int i = 0; i < mesh.node_count(); ++i) {
    const double c = mesh.nodes[3 * i + axis];
    if ((side < 0 && c <= value + tol) || (side > 0 && c >= value - tol)) out.push_back(i);
  }
  return out;
}

std::array<double, 6> bounding_box(const TetMesh &mesh)
{
  const double          inf = std::numeric_limits<double>::infinity();
  std::array<double, 6> b{inf, inf, inf, -inf, -inf, -inf};
  for (int i = 0; i < mesh.node_count(); ++i)
    for (int d = 0; d < 3; ++d) {
      b[d]     = std::min(b[d], mesh.nodes[3 * i + d]);
      b[3 + d] = std::max(b[3 + d], mesh.nodes[3 * i + d]);
    }
  return b;
}

} // namespace physics
