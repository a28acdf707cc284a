#include <catch2/catch.hpp>

#include "physics/row_order.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

using namespace physics;

namespace {

// Hexahedral grid of nx*ny*nz cells as 8-node elements.
AdjacencyGraph hex_grid_graph(int nx, int ny, int nz)
{
  auto             node = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  std::vector<int> conn;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int c = 0; c < 8; ++c) conn.push_back(node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)));
  return graph_from_elements((nx + 1) * (ny + 1) * (nz + 1), 8, conn);
}

void check_permutation(const Renumbering &r, int n)
{
  REQUIRE(r.new_of_old.size() == static_cast<std::size_t>(n));
  REQUIRE(r.old_of_new.size() == static_cast<std::size_t>(n));
  std::vector<char> seen(n, 0);
  for (int k = 0; k < n; ++k) {
    REQUIRE(r.old_of_new[k] >= 0);
    REQUIRE(r.old_of_new[k] < n);
    REQUIRE_FALSE(seen[r.old_of_new[k]]);
    seen[r.old_of_new[k]] = 1;
  }
  for (int v = 0; v < n; ++v) REQUIRE(r.old_of_new[r.new_of_old[v]] == v);
}

// Path 0-1-...-(n-1) where every even vertex also links to a hub-like clique of extra edges, so
// consecutive vertices alternate between a long and a short row.
AdjacencyGraph alternating_degree_graph(int n, int extra)
{
  std::vector<std::pair<int, int>> edges;
  for (int v = 0; v + 1 < n; ++v) edges.push_back({v, v + 1});
  for (int v = 0; v < n; v += 2)
    for (int d = 2; d <= 2 * extra; d += 2)
      if (v + d < n) edges.push_back({v, v + d});
  return graph_from_edges(n, edges);
}

} // namespace

TEST_CASE("group_by_degree: a permutation, non-increasing degree inside each window", "[row_order]")
{
  const AdjacencyGraph g    = hex_grid_graph(6, 5, 4);
  const int            n    = g.vertex_count();
  const Renumbering    base = reorder_for_locality(g);
  for (int window : {1, 3, 8, 32, 1000}) {
    const Renumbering r = group_by_degree(g, base, window);
    check_permutation(r, n);
    CHECK(r.part_offsets == base.part_offsets);
    for (int begin = 0; begin < n; begin += window) {
      const int end = std::min(n, begin + window);
      // same set as the base window: rows move only inside their window
      std::set<int> a(base.old_of_new.begin() + begin, base.old_of_new.begin() + end),
        b(r.old_of_new.begin() + begin, r.old_of_new.begin() + end);
      CHECK(a == b);
      for (int k = begin; k + 1 < end; ++k) {
        const int u = r.old_of_new[k], v = r.old_of_new[k + 1];
        const int du = g.xadj[u + 1] - g.xadj[u], dv = g.xadj[v + 1] - g.xadj[v];
        REQUIRE(du >= dv);
        if (du == dv) REQUIRE(base.new_of_old[u] < base.new_of_old[v]); // stable
      }
    }
  }
  // window 1 is the identity on top of base
  CHECK(group_by_degree(g, base, 1).old_of_new == base.old_of_new);
}

TEST_CASE("group_by_degree: parts stay contiguous and unchanged as sets", "[row_order]")
{
  const AdjacencyGraph g = hex_grid_graph(8, 6, 5);
  const int            n = g.vertex_count();
  PartitionOptions     po;
  po.local_order         = LocalOrder::ReverseCuthillMcKee;
  const Renumbering base = partition_graph(g, 3, po);
  const Renumbering r    = group_by_degree(g, base, 16);
  check_permutation(r, n);
  REQUIRE(r.part_offsets == base.part_offsets);
  REQUIRE(r.part_of_old == base.part_of_old);
  for (int v = 0; v < n; ++v) {
    const int p = r.part_of_old[v];
    CHECK(r.new_of_old[v] >= r.part_offsets[p]);
    CHECK(r.new_of_old[v] < r.part_offsets[p + 1]);
  }
  // windows are aligned to each part's start: sorted runs restart at every part offset
  for (int p = 0; p < r.part_count(); ++p)
    for (int begin = r.part_offsets[p]; begin < r.part_offsets[p + 1]; begin += 16) {
      const int end = std::min(r.part_offsets[p + 1], begin + 16);
      for (int k = begin; k + 1 < end; ++k) {
        const int u = r.old_of_new[k], v = r.old_of_new[k + 1];
        REQUIRE(g.xadj[u + 1] - g.xadj[u] >= g.xadj[v + 1] - g.xadj[v]);
      }
    }
}

TEST_CASE("group_by_degree: padding of alternating row lengths drops", "[row_order]")
{
  // rows alternate 1 + (2 + 2*extra) (even) and 1 + 2..(2+2*extra)/... : build and measure
  const int            n = 4096, extra = 4;
  const AdjacencyGraph g = alternating_degree_graph(n, extra);
  std::vector<int>     length(n);
  for (int v = 0; v < n; ++v) length[v] = 1 + g.xadj[v + 1] - g.xadj[v];
  Renumbering identity;
  identity.new_of_old.resize(n);
  for (int v = 0; v < n; ++v) identity.new_of_old[v] = v;
  identity.old_of_new   = identity.new_of_old;
  identity.part_offsets = {0, n};
  // interior rows: even 1 + 2 + 2*extra = 11, odd 1 + 2 = 3: every bin of 8 holds both, so padding
  // is about 8*11 / (4*11 + 4*3) - 1 = 57%; windows of 16 split them into bins of only 11 or only 3.
  const double before = bin_padding_overhead(length, 8);
  CHECK(before == Approx(88.0 / 56.0 - 1.0).epsilon(0.02));
  const Renumbering r     = group_by_degree(g, identity, 16);
  const double      after = bin_padding_overhead(row_lengths_in_new_order(length, r), 8);
  CHECK(after < 0.02);
  // window 8 (= bin width) cannot help: a sorted bin still has the same longest row
  CHECK(bin_padding_overhead(row_lengths_in_new_order(length, group_by_degree(g, identity, 8)), 8) ==
        Approx(before));
}

TEST_CASE("row lengths with fixed nodes, padding formula", "[row_order]")
{
  const AdjacencyGraph g = graph_from_edges(4, {{0, 1}, {1, 2}, {2, 3}, {0, 3}});
  const auto           l = row_lengths_without_fixed(g, {1, 0, 0, 0});
  CHECK(l == std::vector<int>{1, 2, 3, 2});
  CHECK(bin_padding_overhead({1, 2, 3}, 2) == Approx(10.0 / 6.0 - 1.0)); // bins {1,2}->4, {3,phantom}->6
  CHECK(bin_padding_overhead({}, 8) == 0.0);
}

TEST_CASE("group_by_row_length: bad input throws", "[row_order]")
{
  const AdjacencyGraph g = graph_from_edges(3, {{0, 1}, {1, 2}});
  const Renumbering    b = reorder_for_locality(g);
  CHECK_THROWS_AS(group_by_degree(g, b, 0), std::invalid_argument);
  CHECK_THROWS_AS(group_by_row_length({1, 2}, b, 4), std::invalid_argument);
  Renumbering broken = b;
  broken.old_of_new  = {0, 0, 1};
  CHECK_THROWS_AS(group_by_row_length({1, 2, 3}, broken, 4), std::invalid_argument);
  broken              = b;
  broken.part_offsets = {0, 2};
  CHECK_THROWS_AS(group_by_row_length({1, 2, 3}, broken, 4), std::invalid_argument);
  CHECK_THROWS_AS(row_lengths_without_fixed(g, {0, 1}), std::invalid_argument);
}

TEST_CASE("upper_row_lengths: the upper triangle of the pattern, per part, fixed rows alone", "[row_order]")
{
  // path 0-1-2-3 in two parts {0,1} {2,3}, identity order; vertex 3 fixed
  const AdjacencyGraph g = graph_from_edges(4, {{0, 1}, {1, 2}, {2, 3}});
  Renumbering          r;
  r.new_of_old                  = {0, 1, 2, 3};
  r.old_of_new                  = {0, 1, 2, 3};
  r.part_offsets                = {0, 2, 4};
  const std::vector<char> fixed = {0, 0, 0, 1};
  // 0: diag + 1; 1: diag only (2 is in the other part); 2: diag only (3 is fixed); 3: fixed
  CHECK(upper_row_lengths(g, fixed, r) == std::vector<int>{2, 1, 1, 1});
  // reversed order: the neighbours "after" a vertex are now the lower-numbered old ones
  r.new_of_old   = {3, 2, 1, 0};
  r.old_of_new   = {3, 2, 1, 0};
  r.part_offsets = {0, 4};
  CHECK(upper_row_lengths(g, {0, 0, 0, 0}, r) == std::vector<int>{1, 2, 2, 2});
  CHECK_THROWS_AS(upper_row_lengths(g, {0, 0}, r), std::invalid_argument);
}

TEST_CASE(
  "group_by_upper_row_length: a permutation inside the parts, upper padding no worse and lower than degree grouping",
  "[row_order]")
{
  const AdjacencyGraph    g = hex_grid_graph(12, 10, 9);
  const int               n = g.vertex_count();
  const std::vector<char> fixed(n, 0);
  PartitionOptions        po;
  po.local_order              = LocalOrder::ReverseCuthillMcKee;
  const Renumbering base      = partition_graph(g, 2, po);
  const Renumbering by_degree = group_by_degree(g, base, 64);
  const Renumbering by_upper  = group_by_upper_row_length(g, fixed, by_degree, 64, 8);
  check_permutation(by_upper, n);
  REQUIRE(by_upper.part_offsets == base.part_offsets);
  for (int v = 0; v < n; ++v) {
    const int p = base.part_of_old[v];
    CHECK(by_upper.new_of_old[v] >= base.part_offsets[p]);
    CHECK(by_upper.new_of_old[v] < base.part_offsets[p + 1]);
  }
  auto upper_padding = [&](const Renumbering &r) {
    return bin_padding_overhead(row_lengths_in_new_order(upper_row_lengths(g, fixed, r), r), 8);
  };
  // the stored upper triangle is the same size in every order of one partition: n + edges inside parts
  long long stored_degree = 0, stored_upper = 0;
  for (int l : upper_row_lengths(g, fixed, by_degree)) stored_degree += l;
  for (int l : upper_row_lengths(g, fixed, by_upper)) stored_upper += l;
  CHECK(stored_upper == stored_degree);
  CHECK(upper_padding(by_upper) <= upper_padding(by_degree));
  CHECK(upper_padding(by_upper) < 0.75 * upper_padding(by_degree));
  INFO("upper padding by degree " << upper_padding(by_degree) << ", by upper length "
                                  << upper_padding(by_upper));
}
