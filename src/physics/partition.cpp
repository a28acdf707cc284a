#include "physics/partition.hpp"

#include <metis.h>

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <string>

namespace physics {

namespace {

AdjacencyGraph graph_from_neighbour_lists(std::vector<std::vector<int>> &nbrs)
{
  AdjacencyGraph g;
  g.xadj.assign(nbrs.size() + 1, 0);
  for (std::size_t v = 0; v < nbrs.size(); ++v) {
    std::sort(nbrs[v].begin(), nbrs[v].end());
    nbrs[v].erase(std::unique(nbrs[v].begin(), nbrs[v].end()), nbrs[v].end());
    g.xadj[v + 1] = g.xadj[v] + static_cast<int>(nbrs[v].size());
  }
  g.adjncy.reserve(g.xadj.back());
  for (auto &list : nbrs) g.adjncy.insert(g.adjncy.end(), list.begin(), list.end());
  return g;
}

Renumbering identity_renumbering(int n)
{
  Renumbering r;
  r.new_of_old.resize(n);
  std::iota(r.new_of_old.begin(), r.new_of_old.end(), 0);
  r.old_of_new   = r.new_of_old;
  r.part_offsets = {0, n};
  return r;
}

// Subgraph induced by `vertices` (old numbers), numbered by their position in `vertices`.
AdjacencyGraph induced_subgraph(const AdjacencyGraph &g, const std::vector<int> &vertices,
                                std::vector<int> &local_of)
{
  for (std::size_t k = 0; k < vertices.size(); ++k) local_of[vertices[k]] = static_cast<int>(k);
  AdjacencyGraph s;
  s.xadj.assign(vertices.size() + 1, 0);
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const int v = vertices[k];
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e)
      if (local_of[g.adjncy[e]] >= 0) s.adjncy.push_back(local_of[g.adjncy[e]]);
    std::sort(s.adjncy.begin() + s.xadj[k], s.adjncy.end());
    s.xadj[k + 1] = static_cast<int>(s.adjncy.size());
  }
  for (int v : vertices) local_of[v] = -1;
  return s;
}

// Breadth-first levels from `root` inside the component; returns the visit order and the last level's
// vertex of smallest degree (the next candidate for a pseudo-peripheral start).
int bfs_far_vertex(const AdjacencyGraph &g, int root, std::vector<int> &level, int &depth)
{
  std::vector<int> queue{root};
  level[root] = 0;
  for (std::size_t h = 0; h < queue.size(); ++h) {
    const int v = queue[h];
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e)
      if (level[g.adjncy[e]] < 0) {
        level[g.adjncy[e]] = level[v] + 1;
        queue.push_back(g.adjncy[e]);
      }
  }
  depth    = level[queue.back()];
  int best = queue.back();
  for (int v : queue) {
    if (level[v] == depth && g.xadj[v + 1] - g.xadj[v] < g.xadj[best + 1] - g.xadj[best]) best = v;
  }
  for (int v : queue) level[v] = -1;
  return best;
}

std::vector<int> rcm_old_of_new(const AdjacencyGraph &g)
{
  const int        n = g.vertex_count();
  std::vector<int> order;
  order.reserve(n);
  std::vector<int>  level(n, -1);
  std::vector<char> placed(n, 0);
  auto              degree = [&](int v) { return g.xadj[v + 1] - g.xadj[v]; };
  for (int start = 0; start < n; ++start) {
    if (placed[start]) continue;
    // George-Liu pseudo-peripheral vertex: walk to the far end of the BFS until the depth stops growing.
    int root = start, depth = 0;
    for (int iter = 0; iter < 8; ++iter) {
      int       d;
      const int far = bfs_far_vertex(g, root, level, d);
      if (iter > 0 && d <= depth) break;
      depth = d;
      root  = far;
    }
    const std::size_t first = order.size();
    order.push_back(root);
    placed[root] = 1;
    std::vector<int> nbrs;
    for (std::size_t h = first; h < order.size(); ++h) {
      const int v = order[h];
      nbrs.clear();
      for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e)
        if (!placed[g.adjncy[e]]) {
          nbrs.push_back(g.adjncy[e]);
          placed[g.adjncy[e]] = 1;
        }
      std::stable_sort(nbrs.begin(), nbrs.end(), [&](int a, int b) { return degree(a) < degree(b); });
      order.insert(order.end(), nbrs.begin(), nbrs.end());
    }
  }
  std::reverse(order.begin(), order.end());
  return order;
}

std::vector<int> nested_dissection_old_of_new(const AdjacencyGraph &g)
{
  idx_t n = g.vertex_count();
  if (n == 0) return {};
  if (g.adjncy.empty()) {
    std::vector<int> id(n);
    std::iota(id.begin(), id.end(), 0);
    return id;
  }
  std::vector<idx_t> xadj(g.xadj.begin(), g.xadj.end()), adjncy(g.adjncy.begin(), g.adjncy.end());
  std::vector<idx_t> perm(n), iperm(n);
  idx_t              options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  const int status =
    METIS_NodeND(&n, xadj.data(), adjncy.data(), nullptr, options, perm.data(), iperm.data());
  if (status != METIS_OK)
    throw std::runtime_error("METIS_NodeND failed with status " + std::to_string(status));
  // METIS: row i of the permuted matrix is row perm[i] of the original.
  return std::vector<int>(perm.begin(), perm.end());
}

std::vector<int> local_old_of_new(const AdjacencyGraph &g, LocalOrder order)
{
  switch (order) {
  case LocalOrder::ReverseCuthillMcKee:
    return rcm_old_of_new(g);
  case LocalOrder::NestedDissection:
    return nested_dissection_old_of_new(g);
  case LocalOrder::Keep:
    break;
  }
  std::vector<int> id(g.vertex_count());
  std::iota(id.begin(), id.end(), 0);
  return id;
}

// Parts by METIS. Small cases METIS refuses or handles badly are answered directly.
std::vector<int> metis_parts(const AdjacencyGraph &g, int parts, const PartitionOptions &opt)
{
  const int        n = g.vertex_count();
  std::vector<int> part(n, 0);
  if (parts == 1 || n == 0) return part;
  if (parts >= n) {
    std::iota(part.begin(), part.end(), 0);
    return part;
  }
  if (g.adjncy.empty()) { // no edges: contiguous blocks of equal size
    for (int v = 0; v < n; ++v) part[v] = static_cast<int>(static_cast<long long>(v) * parts / n);
    return part;
  }
  idx_t              nv = n, ncon = 1, np = parts, objval = 0;
  std::vector<idx_t> xadj(g.xadj.begin(), g.xadj.end()), adjncy(g.adjncy.begin(), g.adjncy.end());
  std::vector<idx_t> vwgt(opt.vertex_weights.begin(), opt.vertex_weights.end()), where(n);
  idx_t              options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_SEED]      = opt.seed;
  options[METIS_OPTION_CONTIG]    = 0;
  idx_t    *w                     = vwgt.empty() ? nullptr : vwgt.data();
  const int status                = parts <= 8
                                      ? METIS_PartGraphRecursive(&nv, &ncon, xadj.data(), adjncy.data(), w, nullptr, nullptr,
                                                                 &np, nullptr, nullptr, options, &objval, where.data())
                                      : METIS_PartGraphKway(&nv, &ncon, xadj.data(), adjncy.data(), w, nullptr, nullptr, &np,
                                                            nullptr, nullptr, options, &objval, where.data());
  if (status != METIS_OK)
    throw std::runtime_error("METIS partitioning failed with status " + std::to_string(status));
  for (int v = 0; v < n; ++v) part[v] = static_cast<int>(where[v]);
  return part;
}

} // namespace

void validate_graph(const AdjacencyGraph &g)
{
  const int n = g.vertex_count();
  if (n < 0 || g.xadj.empty() || g.xadj[0] != 0) throw std::invalid_argument("graph: xadj must start with 0");
  if (static_cast<std::size_t>(g.xadj.back()) != g.adjncy.size())
    throw std::invalid_argument("graph: xadj[n] != adjncy size");
  for (int v = 0; v < n; ++v) {
    if (g.xadj[v + 1] < g.xadj[v])
      throw std::invalid_argument("graph: xadj not monotone at vertex " + std::to_string(v));
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e) {
      const int u = g.adjncy[e];
      if (u < 0 || u >= n)
        throw std::invalid_argument("graph: neighbour " + std::to_string(u) + " of vertex " +
                                    std::to_string(v) + " out of range");
      if (u == v) throw std::invalid_argument("graph: self loop at vertex " + std::to_string(v));
      if (e > g.xadj[v] && g.adjncy[e - 1] >= u)
        throw std::invalid_argument("graph: neighbours of vertex " + std::to_string(v) +
                                    " not sorted/unique");
      if (!std::binary_search(g.adjncy.begin() + g.xadj[u], g.adjncy.begin() + g.xadj[u + 1], v))
        throw std::invalid_argument("graph: edge (" + std::to_string(v) + "," + std::to_string(u) +
                                    ") stored in one direction only");
    }
  }
}

AdjacencyGraph graph_from_elements(int node_count, int nodes_per_element,
                                   const std::vector<int> &connectivity)
{
  if (node_count < 0 || nodes_per_element < 1 || connectivity.size() % nodes_per_element)
    throw std::invalid_argument(
      "graph_from_elements: connectivity size is not a multiple of nodes_per_element");
  std::vector<std::vector<int>> nbrs(node_count);
  for (std::size_t e = 0; e < connectivity.size(); e += nodes_per_element) {
    for (int a = 0; a < nodes_per_element; ++a) {
      const int u = connectivity[e + a];
      if (u < 0 || u >= node_count)
        throw std::invalid_argument("graph_from_elements: node " + std::to_string(u) + " out of range");
      for (int b = 0; b < nodes_per_element; ++b)
        if (connectivity[e + b] != u) nbrs[u].push_back(connectivity[e + b]);
    }
  }
  return graph_from_neighbour_lists(nbrs);
}

AdjacencyGraph graph_from_edges(int vertex_count, const std::vector<std::pair<int, int>> &edges)
{
  if (vertex_count < 0) throw std::invalid_argument("graph_from_edges: negative vertex count");
  std::vector<std::vector<int>> nbrs(vertex_count);
  for (const auto &[a, b] : edges) {
    if (a < 0 || b < 0 || a >= vertex_count || b >= vertex_count)
      throw std::invalid_argument("graph_from_edges: edge (" + std::to_string(a) + "," + std::to_string(b) +
                                  ") out of range");
    if (a == b) continue;
    nbrs[a].push_back(b);
    nbrs[b].push_back(a);
  }
  return graph_from_neighbour_lists(nbrs);
}

AdjacencyGraph graph_from_csr(int n, const std::vector<int> &row_start, const std::vector<int> &col)
{
  if (n < 0 || row_start.size() != static_cast<std::size_t>(n) + 1 || row_start[0] != 0 ||
      static_cast<std::size_t>(row_start[n]) != col.size())
    throw std::invalid_argument("graph_from_csr: malformed row_start");
  std::vector<std::vector<int>> nbrs(n);
  for (int i = 0; i < n; ++i)
    for (int k = row_start[i]; k < row_start[i + 1]; ++k) {
      const int j = col[k];
      if (j < 0 || j >= n)
        throw std::invalid_argument("graph_from_csr: column " + std::to_string(j) + " out of range");
      if (j == i) continue;
      nbrs[i].push_back(j);
      nbrs[j].push_back(i);
    }
  return graph_from_neighbour_lists(nbrs);
}

Renumbering partition_graph(const AdjacencyGraph &g, int parts, const PartitionOptions &options)
{
  validate_graph(g);
  if (parts < 1) throw std::invalid_argument("partition_graph: parts must be >= 1");
  const int n = g.vertex_count();
  if (!options.vertex_weights.empty() && options.vertex_weights.size() != static_cast<std::size_t>(n))
    throw std::invalid_argument("partition_graph: vertex_weights must have one entry per vertex");

  Renumbering r;
  r.part_of_old = metis_parts(g, parts, options);
  r.part_offsets.assign(parts + 1, 0);
  for (int p : r.part_of_old) r.part_offsets[p + 1]++;
  std::partial_sum(r.part_offsets.begin(), r.part_offsets.end(), r.part_offsets.begin());

  // Group by part, keeping the old order inside a part (stable), then reorder each part if asked.
  r.old_of_new.resize(n);
  std::vector<int> fill(r.part_offsets.begin(), r.part_offsets.end() - 1);
  for (int v = 0; v < n; ++v) r.old_of_new[fill[r.part_of_old[v]]++] = v;
  if (options.local_order != LocalOrder::Keep) {
    std::vector<int> local_of(n, -1);
    for (int p = 0; p < parts; ++p) {
      std::vector<int>     members(r.old_of_new.begin() + r.part_offsets[p],
                                   r.old_of_new.begin() + r.part_offsets[p + 1]);
      const AdjacencyGraph sub   = induced_subgraph(g, members, local_of);
      const auto           order = local_old_of_new(sub, options.local_order);
      for (std::size_t k = 0; k < order.size(); ++k) r.old_of_new[r.part_offsets[p] + k] = members[order[k]];
    }
  }
  r.new_of_old.resize(n);
  for (int k = 0; k < n; ++k) r.new_of_old[r.old_of_new[k]] = k;
  return r;
}

Renumbering reorder_for_locality(const AdjacencyGraph &g, LocalOrder order)
{
  validate_graph(g);
  Renumbering r = identity_renumbering(g.vertex_count());
  r.old_of_new  = local_old_of_new(g, order);
  for (int k = 0; k < g.vertex_count(); ++k) r.new_of_old[r.old_of_new[k]] = k;
  return r;
}

AdjacencyGraph renumber_graph(const AdjacencyGraph &g, const Renumbering &r)
{
  const int                     n = g.vertex_count();
  std::vector<std::vector<int>> nbrs(n);
  for (int v = 0; v < n; ++v)
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e)
      nbrs[r.new_of_old[v]].push_back(r.new_of_old[g.adjncy[e]]);
  return graph_from_neighbour_lists(nbrs);
}

int graph_bandwidth(const AdjacencyGraph &g)
{
  int bw = 0;
  for (int v = 0; v < g.vertex_count(); ++v)
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e) bw = std::max(bw, std::abs(g.adjncy[e] - v));
  return bw;
}

long long cut_edges(const AdjacencyGraph &g, const Renumbering &r)
{
  long long cut = 0;
  for (int v = 0; v < g.vertex_count(); ++v)
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e)
      if (g.adjncy[e] > v && r.part_of_old[v] != r.part_of_old[g.adjncy[e]]) ++cut;
  return cut;
}

std::vector<int> assign_elements_to_parts(const std::vector<int> &connectivity, int npe,
                                          const std::vector<int> &part_offsets)
{
  if (npe <= 0 || connectivity.size() % npe)
    throw std::invalid_argument("assign_elements_to_parts: bad element size");
  if (part_offsets.size() < 2)
    throw std::invalid_argument("assign_elements_to_parts: need at least one part");
  const int parts   = static_cast<int>(part_offsets.size()) - 1;
  const int ne      = static_cast<int>(connectivity.size() / npe);
  auto      part_of = [&](int v) {
    if (v < part_offsets.front() || v >= part_offsets.back())
      throw std::invalid_argument("assign_elements_to_parts: node outside the parts");
    return static_cast<int>(std::upper_bound(part_offsets.begin(), part_offsets.end(), v) -
                            part_offsets.begin()) -
           1;
  };
  std::vector<int>       owner(ne, -1);
  std::vector<long long> load(parts, 0);
  for (int e = 0; e < ne; ++e) {
    const int p        = part_of(connectivity[static_cast<size_t>(e) * npe]);
    bool      one_part = true;
    for (int k = 1; k < npe && one_part; ++k)
      one_part = part_of(connectivity[static_cast<size_t>(e) * npe + k]) == p;
    if (one_part) owner[e] = p, ++load[p];
  }
  for (int e = 0; e < ne; ++e) {
    if (owner[e] >= 0) continue;
    int best = -1;
    for (int k = 0; k < npe; ++k) {
      const int p = part_of(connectivity[static_cast<size_t>(e) * npe + k]);
      if (best < 0 || load[p] < load[best] || (load[p] == load[best] && p < best)) best = p;
    }
    owner[e] = best;
    ++load[best];
  }
  return owner;
}

} // namespace physics
