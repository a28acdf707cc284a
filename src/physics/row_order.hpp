// Row-length grouping on top of a locality numbering (SELL-C-sigma style sorting).
//
// Why: BIN-BCSR (and SELL) pads every bin of bw consecutive rows to its longest row. A locality order
// such as RCM puts neighbours next to each other but ignores row lengths, and on unstructured FE
// meshes neighbouring rows differ a lot (P2 vertex vs edge-midpoint nodes, fixed nodes whose row is
// a single diagonal block), so most of a bin is padding. Sorting the rows by length inside short
// windows of `window` consecutive rows makes every bin hold rows of similar length, while a row moves
// by less than `window` positions, so the x entries a bin reads stay as local as in the base order.
// A larger window removes more padding but scatters the x accesses of a bin; see docs/row_order.md
// for the measured trade-off.
//
// Composable with any Renumbering (reorder_for_locality, partition_graph): windows start at every
// part's first row and never cross a part boundary, so parts keep their contiguous ranges and their
// sets of vertices; only the order inside a part changes.
//
//     physics::Renumbering r = physics::reorder_for_locality(g);        // or partition_graph(g, P, po)
//     r = physics::group_by_degree(g, r, 64);
#pragma once
#include "physics/partition.hpp"

#include <vector>

namespace physics {

// Reorders base inside consecutive windows of `window` new numbers (aligned to each part's start)
// by descending row_length_old[old vertex], stable (ties keep base's order). row_length_old has one
// entry per vertex, in old numbering. Returns base with new_of_old/old_of_new changed; part_of_old
// and part_offsets are kept. Throws std::invalid_argument if window < 1, the sizes differ or base is
// not a permutation.
Renumbering group_by_row_length(const std::vector<int> &row_length_old, const Renumbering &base, int window);

// group_by_row_length with the row length of a matrix with this graph's pattern: 1 + degree.
Renumbering group_by_degree(const AdjacencyGraph &g, const Renumbering &base, int window);

// Row lengths in blocks when the rows and columns of `fixed` vertices are eliminated (a fixed row
// keeps only its diagonal): 1 for a fixed vertex, 1 + its number of free neighbours otherwise.
std::vector<int> row_lengths_without_fixed(const AdjacencyGraph &g, const std::vector<char> &fixed);

// Padding overhead of a bin layout of bin_width rows over rows of these lengths (new numbering,
// bins starting at row 0): sum over bins of bin_width * longest row, divided by the sum of lengths,
// minus 1. The figure MATBINBCSR reports for the same pattern on one rank.
double bin_padding_overhead(const std::vector<int> &row_length_new, int bin_width);

// row_length_old permuted to the new numbering of r.
std::vector<int> row_lengths_in_new_order(const std::vector<int> &row_length_old, const Renumbering &r);

// Upper-triangle storage (sbaij, binbcsr symmetric storage) keeps, per row, the diagonal and the
// neighbours numbered after it, so its row lengths depend on the order itself: grouping by the full
// degree leaves rows of very different upper lengths side by side (42-45% padding on the FE bodies).
// Upper row length of every vertex (old numbering) under r: 1 + its free neighbours in the same part
// with a higher new number; 1 for a fixed vertex (its row keeps only the diagonal).
std::vector<int> upper_row_lengths(const AdjacencyGraph &g, const std::vector<char> &fixed,
                                   const Renumbering &r);

// group_by_row_length on upper row lengths. Sorting moves rows and so changes the lengths it sorted
// by; it is repeated `sweeps` times and the order with the least padding for bins of bin_width rows
// is kept (base included).
Renumbering group_by_upper_row_length(const AdjacencyGraph &g, const std::vector<char> &fixed,
                                      const Renumbering &base, int window, int bin_width, int sweeps = 4);

} // namespace physics
