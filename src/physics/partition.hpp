// Graph partitioning and renumbering for running a simulation on several MPI ranks (METIS), and a
// locality (bandwidth) reordering for one rank. No PETSc here: drivers call this on the global mesh
// (or body/joint graph), renumber their nodes with the result, and then give rank p the rows
// [part_offsets[p], part_offsets[p+1]) (times the block size) of every matrix and vector.
//
// Typical use in a driver with P ranks (every rank computes the same answer, METIS is deterministic
// for a fixed seed, so no communication is needed):
//
//     physics::AdjacencyGraph g = physics::graph_from_elements(n_nodes, 4, tets);   // or from joints
//     physics::Renumbering    r = physics::partition_graph(g, P);
//     // node n becomes r.new_of_old[n]; rank p owns new nodes r.part_offsets[p] .. r.part_offsets[p+1]-1
//     PetscCall(VecSetSizes(x, 3 * r.part_size(rank), PETSC_DECIDE));
//
// For one rank, reorder_for_locality() returns an RCM (or METIS nested-dissection) numbering that
// shrinks the matrix bandwidth, so the x entries one bin of rows reads stay in cache.
#pragma once
#include <utility>
#include <vector>

namespace physics {

// Undirected graph in CSR form: the neighbours of vertex v are adjncy[xadj[v] .. xadj[v+1]-1].
// No self loops, each edge stored in both directions, neighbour lists sorted.
struct AdjacencyGraph {
  std::vector<int> xadj{0};
  std::vector<int> adjncy;
  int              vertex_count() const { return static_cast<int>(xadj.size()) - 1; }
};

// A permutation of the vertices. new_of_old[v] is the new number of old vertex v, old_of_new its
// inverse. For a partition, part_of_old[v] is v's part and new numbers are grouped by part: part p
// holds new numbers [part_offsets[p], part_offsets[p+1]); inside a part the old order is kept
// (or locality-reordered, see PartitionOptions).
struct Renumbering {
  std::vector<int> new_of_old;
  std::vector<int> old_of_new;
  std::vector<int> part_of_old;  // empty for a pure reordering
  std::vector<int> part_offsets; // parts + 1 entries; {0, n} for a pure reordering
  int              part_count() const { return static_cast<int>(part_offsets.size()) - 1; }
  int              part_size(int p) const { return part_offsets[p + 1] - part_offsets[p]; }
};

// Graph of a mesh: nodes that share an element are neighbours. `connectivity` holds
// nodes_per_element node numbers per element (0-based, < node_count).
AdjacencyGraph graph_from_elements(int node_count, int nodes_per_element,
                                   const std::vector<int> &connectivity);

// Graph from explicit edges (e.g. rigid bodies joined by joints). Duplicates and self loops are dropped.
AdjacencyGraph graph_from_edges(int vertex_count, const std::vector<std::pair<int, int>> &edges);

// Graph of a square sparse pattern given in CSR (row_start[n+1], col): i and j are neighbours when
// (i,j) or (j,i) is stored, i != j.
AdjacencyGraph graph_from_csr(int n, const std::vector<int> &row_start, const std::vector<int> &col);

enum class LocalOrder {
  Keep,
  ReverseCuthillMcKee,
  NestedDissection
};

struct PartitionOptions {
  // Optional vertex weights (work per vertex, e.g. 1 + degree); empty = all 1.
  std::vector<int> vertex_weights;
  // Reordering applied inside each part after partitioning.
  LocalOrder local_order = LocalOrder::Keep;
  // Seed of METIS' randomised heuristics: the same seed gives the same partition on every rank.
  int seed = 1;
};

// Partitions g into `parts` parts of about equal weight with few cut edges (METIS k-way; recursive
// bisection for parts <= 8, which balances better on small graphs) and renumbers the vertices so that
// each part owns a contiguous range. parts >= 1; parts may exceed the vertex count (then some parts
// are empty). Throws std::invalid_argument on a malformed graph or parts < 1, std::runtime_error if
// METIS fails.
Renumbering partition_graph(const AdjacencyGraph &g, int parts, const PartitionOptions &options = {});

// A bandwidth/locality reordering of the whole graph for one rank.
Renumbering reorder_for_locality(const AdjacencyGraph &g, LocalOrder order = LocalOrder::ReverseCuthillMcKee);

// Graph renumbered by r: vertex r.new_of_old[v] of the result has the renumbered neighbours of v.
AdjacencyGraph renumber_graph(const AdjacencyGraph &g, const Renumbering &r);

// Largest |i - j| over the edges (i,j): the half bandwidth of the matrix with this pattern.
int graph_bandwidth(const AdjacencyGraph &g);

// Number of edges (counted once) whose ends lie in different parts of r.
long long cut_edges(const AdjacencyGraph &g, const Renumbering &r);

// Which part assembles each element of a mesh whose nodes are split into contiguous parts
// [part_offsets[p], part_offsets[p+1]): an element whose nodes all lie in one part goes to that part;
// an element cut by the partition goes to the least-loaded (fewest elements so far, then lowest) of
// the parts holding its nodes, in element order. Taking the part of the first corner instead left
// the two ranks of linear_38k with 53% and 47% of the elements. Deterministic, so every rank computes
// the same answer. `connectivity`: nodes_per_element node numbers per element.
std::vector<int> assign_elements_to_parts(const std::vector<int> &connectivity, int nodes_per_element,
                                          const std::vector<int> &part_offsets);

// Checks the CSR invariants listed at AdjacencyGraph; throws std::invalid_argument with the reason.
void validate_graph(const AdjacencyGraph &g);

} // namespace physics
