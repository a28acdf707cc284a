// Tetrahedral meshes with 4-node (linear) or 10-node (quadratic) elements, and the operations every
// FEM caller needs on them: promotion of a linear mesh to quadratic, renumbering, volume checks and
// node selection by box or plane (for fixed nodes).
#pragma once
#include <array>
#include <string>
#include <vector>

namespace physics {

// Node order inside an element is VTK's (also used for output): corners 0..3, then for order 2 the
// edge midpoints (0,1) (1,2) (2,0) (0,3) (1,3) (2,3). Positive orientation: (x1-x0, x2-x0, x3-x0) is
// a right-handed frame, i.e. signed volume > 0.
struct TetMesh {
  int                 order = 1;
  std::vector<double> nodes;    // 3 per node (rest positions)
  std::vector<int>    elements; // nodes_per_element() per element

  int nodes_per_element() const { return order == 1 ? 4 : 10; }
  int node_count() const { return static_cast<int>(nodes.size() / 3); }
  int element_count() const { return static_cast<int>(elements.size()) / nodes_per_element(); }
};

// The corner pairs of the 6 edges, in the order of the edge nodes 4..9.
constexpr std::array<std::array<int, 2>, 6> kTetEdges{{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};

// Signed volume of the corner tetrahedron of element e with positions pos (3 per node).
double element_signed_volume(const TetMesh &mesh, const double *pos, int e);

// A quadratic mesh with a midpoint node on every edge (shared by neighbours); corner nodes keep
// their numbers, edge nodes are appended. A quadratic input is returned unchanged.
TetMesh promote_to_quadratic(const TetMesh &mesh);

// Node n becomes new_of_old[n] (a permutation of 0..node_count-1).
void renumber_nodes(TetMesh &mesh, const std::vector<int> &new_of_old);

// Reorders the elements by their lowest node number (stable; each element keeps its node order, so
// its orientation). After a locality numbering of the nodes, consecutive elements then touch nearby
// rows of the matrix, and the element loop's writes into the row-sorted block values hit cache
// instead of memory (in mesh-file order they missed on most of the 16 blocks of every P1 element).
void sort_elements_by_lowest_node(TetMesh &mesh);

// Regroups the elements into runs of `group` (the batched element loop's write groups, element_batch.hpp)
// that share nodes: each run starts at the first element left in the current order and grows by the
// element sharing the most nodes with the run so far. A write group then touches fewer distinct blocks
// of the matrix (linear_38k: 247k -> 199k block writes per step for its 93k blocks; quadratic_47k,
// groups of 16: 344k -> 317k), and the runs still follow the order they were taken from.
void cluster_elements(TetMesh &mesh, int group);

// Throws std::runtime_error naming the first offending element when an element's rest volume is not
// positive (inverted or flat) or a node index is out of range, and when nodes are unused. With
// element_tags (one per element, e.g. the tags of a .msh file) elements are named by their tag, so
// that the user finds them in the file; otherwise by their index.
void validate_mesh(const TetMesh &mesh, const std::string &what,
                   const std::vector<long long> &element_tags = {});

// Nodes whose rest position lies in the axis-aligned box [lo, hi] (inclusive, tolerance tol).
std::vector<int> nodes_in_box(const TetMesh &mesh, const std::array<double, 3> &lo,
                              const std::array<double, 3> &hi, double tol = 1e-9);

// Nodes with rest coordinate `axis` (0,1,2) <= value + tol (side < 0) or >= value - tol (side > 0).
std::vector<int> nodes_beyond_plane(const TetMesh &mesh, int axis, double value, int side, double tol);

// Axis-aligned bounding box of the rest positions: {min x, min y, min z, max x, max y, max z}.
std::array<double, 6> bounding_box(const TetMesh &mesh);

} // namespace physics
