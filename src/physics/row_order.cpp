#include "physics/row_order.hpp"

#include <algorithm>
#include <stdexcept>

namespace physics {

Renumbering group_by_row_length(const std::vector<int> &row_length_old, const Renumbering &base, int window)
{
  const int n = static_cast<int>(base.old_of_new.size());
  if (window < 1) throw std::invalid_argument("group_by_row_length: window must be >= 1");
  if (static_cast<int>(row_length_old.size()) != n || static_cast<int>(base.new_of_old.size()) != n)
    throw std::invalid_argument("group_by_row_length: row lengths and renumbering differ in size");
  std::vector<char> seen(n, 0);
  for (int v : base.old_of_new) {
    if (v < 0 || v >= n || seen[v])
      throw std::invalid_argument("group_by_row_length: base is not a permutation");
    seen[v] = 1;
  }
  std::vector<int> offsets = base.part_offsets;
  if (offsets.size() < 2 || offsets.front() != 0 || offsets.back() != n ||
      !std::is_sorted(offsets.begin(), offsets.end()))
    throw std::invalid_argument("group_by_row_length: base has malformed part offsets");

  Renumbering r = base;
  for (std::size_t p = 0; p + 1 < offsets.size(); ++p)
    for (int begin = offsets[p]; begin < offsets[p + 1]; begin += window) {
      const int end = std::min(offsets[p + 1], begin + window);
      std::stable_sort(r.old_of_new.begin() + begin, r.old_of_new.begin() + end,
                       [&](int a, int b) { return row_length_old[a] > row_length_old[b]; });
    }
  for (int k = 0; k < n; ++k) r.new_of_old[r.old_of_new[k]] = k;
  return r;
}

Renumbering group_by_degree(const AdjacencyGraph &g, const Renumbering &base, int window)
{
  validate_graph(g);
  std::vector<int> length(g.vertex_count());
  for (int v = 0; v < g.vertex_count(); ++v) length[v] = 1 + g.xadj[v + 1] - g.xadj[v];
  return group_by_row_length(length, base, window);
}

std::vector<int> row_lengths_without_fixed(const AdjacencyGraph &g, const std::vector<char> &fixed)
{
  if (static_cast<int>(fixed.size()) != g.vertex_count())
    throw std::invalid_argument("row_lengths_without_fixed: fixed flags: wrong size");
  std::vector<int> length(g.vertex_count(), 1);
  for (int v = 0; v < g.vertex_count(); ++v)
    if (!fixed[v])
      for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e) length[v] += fixed[g.adjncy[e]] ? 0 : 1;
  return length;
}

double bin_padding_overhead(const std::vector<int> &row_length_new, int bin_width)
{
  if (bin_width < 1) throw std::invalid_argument("bin_padding_overhead: bin_width must be >= 1");
  long long slots = 0, stored = 0;
  for (std::size_t begin = 0; begin < row_length_new.size(); begin += bin_width) {
    const std::size_t end = std::min(row_length_new.size(), begin + bin_width);
    slots += static_cast<long long>(bin_width) *
             *std::max_element(row_length_new.begin() + begin, row_length_new.begin() + end);
    for (std::size_t i = begin; i < end; ++i) stored += row_length_new[i];
  }
  return stored ? static_cast<double>(slots) / stored - 1.0 : 0.0;
}

std::vector<int> row_lengths_in_new_order(const std::vector<int> &row_length_old, const Renumbering &r)
{
  if (row_length_old.size() != r.new_of_old.size())
    throw std::invalid_argument("row_lengths_in_new_order: sizes differ");
  std::vector<int> out(row_length_old.size());
  for (std::size_t v = 0; v < row_length_old.size(); ++v) out[r.new_of_old[v]] = row_length_old[v];
  return out;
}

std::vector<int> upper_row_lengths(const AdjacencyGraph &g, const std::vector<char> &fixed,
                                   const Renumbering &r)
{
  const int n = g.vertex_count();
  if (static_cast<int>(fixed.size()) != n || static_cast<int>(r.new_of_old.size()) != n)
    throw std::invalid_argument("upper_row_lengths: fixed flags or renumbering: wrong size");
  // part of a new number: parts are contiguous ranges of new numbers
  std::vector<int> part_of_new(n, 0);
  for (std::size_t p = 0; p + 1 < r.part_offsets.size(); ++p)
    for (int k = r.part_offsets[p]; k < r.part_offsets[p + 1]; ++k) part_of_new[k] = static_cast<int>(p);
  std::vector<int> length(n, 1);
  for (int v = 0; v < n; ++v) {
    if (fixed[v]) continue;
    const int nv = r.new_of_old[v];
    for (int e = g.xadj[v]; e < g.xadj[v + 1]; ++e) {
      const int w = g.adjncy[e], nw = r.new_of_old[w];
      if (!fixed[w] && nw > nv && part_of_new[nw] == part_of_new[nv]) ++length[v];
    }
  }
  return length;
}

Renumbering group_by_upper_row_length(const AdjacencyGraph &g, const std::vector<char> &fixed,
                                      const Renumbering &base, int window, int bin_width, int sweeps)
{
  validate_graph(g);
  // the lengths counted to measure one order are the ones the next sweep sorts by
  std::vector<int> length       = upper_row_lengths(g, fixed, base);
  Renumbering      best         = base;
  double           best_padding = bin_padding_overhead(row_lengths_in_new_order(length, base), bin_width);
  Renumbering      r            = base;
  for (int s = 0; s < sweeps; ++s) {
    r                    = group_by_row_length(length, r, window);
    length               = upper_row_lengths(g, fixed, r);
    const double padding = bin_padding_overhead(row_lengths_in_new_order(length, r), bin_width);
    if (padding < best_padding) {
      best_padding = padding;
      best         = r;
    }
  }
  return best;
}

} // namespace physics
