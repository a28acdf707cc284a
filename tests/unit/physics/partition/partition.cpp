#include <catch2/catch.hpp>

#include "physics/partition.hpp"

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>

using namespace physics;

namespace {

// Hexahedral grid of nx*ny*nz cells as 8-node elements: node (i,j,k) = i + (nx+1)*(j + (ny+1)*k).
std::vector<int> hex_grid(int nx, int ny, int nz, int &node_count)
{
  auto             node = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  std::vector<int> conn;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int c = 0; c < 8; ++c) conn.push_back(node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)));
  node_count = (nx + 1) * (ny + 1) * (nz + 1);
  return conn;
}

void check_permutation(const Renumbering &r, int n)
{
  REQUIRE(r.new_of_old.size() == static_cast<std::size_t>(n));
  REQUIRE(r.old_of_new.size() == static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) REQUIRE(r.old_of_new[r.new_of_old[v]] == v);
}

} // namespace

TEST_CASE("mesh graph: a hex element links its 8 nodes", "[partition]")
{
  int        n;
  const auto conn = hex_grid(2, 2, 2, n);
  const auto g    = graph_from_elements(n, 8, conn);
  REQUIRE(g.vertex_count() == 27);
  REQUIRE_NOTHROW(validate_graph(g));
  // corner node touches 1 element -> 7 neighbours; centre node touches 8 -> 26.
  CHECK(g.xadj[1] - g.xadj[0] == 7);
  CHECK(g.xadj[14] - g.xadj[13] == 26);
}

TEST_CASE("partition: parts are contiguous, balanced, and cut far fewer edges than a random split",
          "[partition]")
{
  int        n;
  const auto conn = hex_grid(12, 12, 12, n);
  const auto g    = graph_from_elements(n, 8, conn);
  for (int parts : {1, 2, 3, 4, 7}) {
    const Renumbering r = partition_graph(g, parts);
    check_permutation(r, n);
    REQUIRE(r.part_count() == parts);
    REQUIRE(r.part_offsets.back() == n);
    // contiguity: new number of v lies in its part's range
    for (int v = 0; v < n; ++v) {
      const int p = r.part_of_old[v];
      REQUIRE(r.new_of_old[v] >= r.part_offsets[p]);
      REQUIRE(r.new_of_old[v] < r.part_offsets[p + 1]);
    }
    // balance within METIS' default 3% imbalance (+1 vertex)
    for (int p = 0; p < parts; ++p) CHECK(r.part_size(p) <= 1.03 * n / parts + 1);
    if (parts > 1) {
      Renumbering  random = r;
      std::mt19937 rng(7);
      for (int v = 0; v < n; ++v) random.part_of_old[v] = static_cast<int>(rng() % parts);
      CHECK(cut_edges(g, r) * 3 < cut_edges(g, random));
    }
  }
}

TEST_CASE("partition: the answer is deterministic (every rank computes the same)", "[partition]")
{
  int        n;
  const auto conn = hex_grid(6, 5, 4, n);
  const auto g    = graph_from_elements(n, 8, conn);
  CHECK(partition_graph(g, 3).new_of_old == partition_graph(g, 3).new_of_old);
}

TEST_CASE("partition: body/joint chains, more parts than vertices, no edges", "[partition]")
{
  std::vector<std::pair<int, int>> joints;
  for (int b = 0; b + 1 < 20; ++b) joints.push_back({b, b + 1});
  const auto  chain = graph_from_edges(20, joints);
  Renumbering r     = partition_graph(chain, 2);
  check_permutation(r, 20);
  CHECK(cut_edges(chain, r) == 1); // a chain splits with one cut

  const auto tiny = graph_from_edges(3, {{0, 1}});
  r               = partition_graph(tiny, 5);
  check_permutation(r, 3);
  REQUIRE(r.part_count() == 5);
  CHECK(r.part_size(3) == 0);
  CHECK(r.part_size(4) == 0);

  const auto isolated = graph_from_edges(10, {});
  r                   = partition_graph(isolated, 3);
  check_permutation(r, 10);
  CHECK(r.part_size(0) + r.part_size(1) + r.part_size(2) == 10);
}

TEST_CASE("partition: bad input is refused with an exception", "[partition]")
{
  AdjacencyGraph g;
  g.xadj   = {0, 1, 1};
  g.adjncy = {1}; // 0->1 without 1->0
  CHECK_THROWS_AS(validate_graph(g), std::invalid_argument);
  CHECK_THROWS_AS(partition_graph(g, 2), std::invalid_argument);
  CHECK_THROWS_AS(graph_from_edges(2, {{0, 2}}), std::invalid_argument);
  CHECK_THROWS_AS(graph_from_elements(4, 3, {0, 1}), std::invalid_argument);
  CHECK_THROWS_AS(partition_graph(graph_from_edges(2, {{0, 1}}), 0), std::invalid_argument);
}

TEST_CASE("locality: RCM and nested dissection undo a random shuffle", "[partition]")
{
  int        n;
  const auto conn = hex_grid(10, 10, 10, n);
  auto       g    = graph_from_elements(n, 8, conn);
  // shuffle
  Renumbering shuffle;
  shuffle.old_of_new.resize(n);
  std::iota(shuffle.old_of_new.begin(), shuffle.old_of_new.end(), 0);
  std::shuffle(shuffle.old_of_new.begin(), shuffle.old_of_new.end(), std::mt19937(3));
  shuffle.new_of_old.resize(n);
  for (int k = 0; k < n; ++k) shuffle.new_of_old[shuffle.old_of_new[k]] = k;
  const auto shuffled = renumber_graph(g, shuffle);
  REQUIRE_NOTHROW(validate_graph(shuffled));
  const int bw_shuffled = graph_bandwidth(shuffled);
  CHECK(bw_shuffled > n / 2);

  const auto rcm = reorder_for_locality(shuffled, LocalOrder::ReverseCuthillMcKee);
  check_permutation(rcm, n);
  const int bw_rcm = graph_bandwidth(renumber_graph(shuffled, rcm));
  // an 11^3-node grid has an optimal half bandwidth about one 11x11 plane (+ diagonal links)
  CHECK(bw_rcm < 3 * 11 * 11);

  const auto nd = reorder_for_locality(shuffled, LocalOrder::NestedDissection);
  check_permutation(nd, n);

  // partition with RCM inside each part keeps parts contiguous
  PartitionOptions opt;
  opt.local_order   = LocalOrder::ReverseCuthillMcKee;
  const auto parted = partition_graph(shuffled, 2, opt);
  check_permutation(parted, n);
  for (int v = 0; v < n; ++v) {
    const int p = parted.part_of_old[v];
    REQUIRE(parted.new_of_old[v] >= parted.part_offsets[p]);
    REQUIRE(parted.new_of_old[v] < parted.part_offsets[p + 1]);
  }
}

TEST_CASE("assign_elements_to_parts: uncut elements stay, cut ones balance the parts", "[partition]")
{
  // A chain of 2-node "elements" over 12 nodes split 0-5 | 6-11, plus many elements cut by the split.
  std::vector<int> conn;
  for (int v = 0; v + 1 < 12; ++v) conn.insert(conn.end(), {v, v + 1});
  for (int k = 0; k < 20; ++k) conn.insert(conn.end(), {k % 6, 6 + k % 6});
  const std::vector<int> offsets{0, 6, 12};
  const std::vector<int> owner = physics::assign_elements_to_parts(conn, 2, offsets);
  REQUIRE(owner.size() == conn.size() / 2);
  int count[2] = {0, 0};
  for (size_t e = 0; e < owner.size(); ++e) {
    const int a = conn[2 * e] < 6 ? 0 : 1, b = conn[2 * e + 1] < 6 ? 0 : 1;
    CHECK((owner[e] == a || owner[e] == b));
    if (a == b) CHECK(owner[e] == a);
    ++count[owner[e]];
  }
  CHECK(std::abs(count[0] - count[1]) <= 1);
  CHECK_THROWS_AS(physics::assign_elements_to_parts(conn, 2, {0, 6, 11}), std::invalid_argument);
}
