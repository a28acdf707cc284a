// The batched loop's grouped write-out (BlockPattern::plan): on a mesh whose elements share blocks
// within and across write groups, the plan lists every element block contribution once and marks one
// first write per COO block, each block once per group in runs of equal term count (the write-out's
// branches taken alike block after block), and the batched loop's sums equal the scalar loop's (element order) to
// rounding, in every body set, merged or not, whole matrix or upper triangle.
#include <catch2/catch.hpp>

#include "physics/box_mesh.hpp"
#include "physics/corotational_assembly.hpp"
#include "physics/element_batch.hpp"
#include "physics/tet_mesh.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>

using namespace physics;

TEST_CASE("grouped write-out: one term per element block, one first write per COO block, the scalar sums",
          "[fem][kernel][batch]")
{
  for (int order : {1, 2})
    for (bool merge : {true, false})
      for (bool drop : {false, true}) {
        INFO("order " << order << " merge " << merge << " drop lower " << drop);
        TetMesh mesh = make_box_mesh(1.0, 0.8, 0.6, 6, 5, 4);
        if (order == 2) mesh = promote_to_quadratic(mesh);
        const FemModel   m = make_fem_model(mesh, FemSettings{});
        const int        n = m.element_count(), npe = m.npe;
        std::vector<int> elements(n);
        std::iota(elements.begin(), elements.end(), 0);
        std::reverse(elements.begin() + n / 3, elements.end()); // far apart and near in one list
        std::vector<char> fixed(mesh.node_count(), 0);
        fixed[0] = fixed[7] = 1;
        LowerTriangle lower;
        lower.drop               = drop;
        const BlockPattern p     = make_block_pattern(m, elements, fixed, 0, mesh.node_count(), merge, lower);
        const int          group = kElementLanes * write_group_batches(npe);
        REQUIRE(n > 3 * group);
        const BlockPattern::WritePlan &w = p.plan;
        REQUIRE(w.group_offsets.size() == static_cast<size_t>((n + group - 1) / group + 1));
        REQUIRE(w.group_terms.size() == w.group_offsets.size());
        REQUIRE(w.run_offsets.size() == w.group_offsets.size());
        CHECK(w.group_terms.back() == static_cast<int>(w.write_terms.size()));
        CHECK(2 * static_cast<size_t>(w.run_offsets.back()) == w.runs.size());
        // Each block's term count, from the runs: they cover every block and every term of its group.
        std::vector<int> term_count;
        for (size_t g = 0; g + 1 < w.group_offsets.size(); ++g) {
          int blocks = 0, group_terms = 0;
          for (int r = w.run_offsets[g]; r < w.run_offsets[g + 1]; ++r) {
            CHECK(w.runs[2 * r] > 0);
            CHECK(w.runs[2 * r + 1] > 0);
            if (r > w.run_offsets[g]) CHECK(w.runs[2 * r] > w.runs[2 * r - 2]);
            term_count.insert(term_count.end(), w.runs[2 * r + 1], w.runs[2 * r]);
            blocks += w.runs[2 * r + 1];
            group_terms += w.runs[2 * r] * w.runs[2 * r + 1];
          }
          CHECK(blocks == w.group_offsets[g + 1] - w.group_offsets[g]);
          CHECK(group_terms == w.group_terms[g + 1] - w.group_terms[g]);
        }
        REQUIRE(term_count.size() == w.write_slots.size());
        size_t contributions = 0;
        for (int s : p.element_slots) contributions += s >= 0;
        // (the diagonal entry (a, a) of element_slots is one contribution, like any other)
        CHECK(w.write_terms.size() == contributions);
        std::vector<int> firsts(p.rows.size(), 0);
        for (size_t g = 0; g + 1 < w.group_offsets.size(); ++g)
          for (int k = w.group_offsets[g]; k < w.group_offsets[g + 1]; ++k) {
            const int s = w.write_slots[k];
            if (s & kFirstContribution) ++firsts[s & kSlotIndexMask];
            // runs of equal term count (growing), first writes before the others, ascending within a
            // run: every block of the group once
            if (k > w.group_offsets[g]) {
              const int  prev = w.write_slots[k - 1];
              const int  n0 = term_count[k - 1], n1 = term_count[k];
              const bool f0 = prev & kFirstContribution, f1 = s & kFirstContribution;
              CHECK(n0 <= n1);
              if (n0 == n1) CHECK(f0 >= f1);
              if (n0 == n1 && f0 == f1) CHECK((prev & kSlotIndexMask) < (s & kSlotIndexMask));
            }
          }
        for (size_t g = 0; g + 1 < w.group_offsets.size(); ++g) {
          std::vector<int> group_blocks;
          for (int k = w.group_offsets[g]; k < w.group_offsets[g + 1]; ++k)
            group_blocks.push_back(w.write_slots[k] & kSlotIndexMask);
          std::sort(group_blocks.begin(), group_blocks.end());
          CHECK(std::adjacent_find(group_blocks.begin(), group_blocks.end()) == group_blocks.end());
        }
        for (int s : p.identity_slots) firsts[s] = 1;
        CHECK(std::count(firsts.begin(), firsts.end(), 1) == static_cast<long>(p.rows.size()));

        std::vector<double> x(mesh.nodes), v(x.size());
        for (size_t k = 0; k < x.size(); ++k)
          x[k] = x[k] * 1.03 + 0.01 * std::sin(1.7 * k), v[k] = std::cos(0.3 * k);
        const StepCoefficients c   = implicit_euler_coefficients(0.01, 0.2, 0.001);
        auto                   run = [&](ElementKernel kernel, binbcsr::BodySet body) {
          std::vector<double> values(9 * p.rows.size(), std::nan("")), rhs(x.size(), 0.0);
          reset_block_values(p, values);
          assemble_elements(m, elements, x.data(), v.data(), c, &p, values.data(), rhs.data(), nullptr,
                                              kernel, body);
          return values;
        };
        const std::vector<double> scalar = run(ElementKernel::Scalar, binbcsr::BodySet::Auto);
        double                    scale  = 0;
        for (double e : scalar) scale = std::max(scale, std::fabs(e));
        for (binbcsr::BodySet body :
             {binbcsr::BodySet::Portable, binbcsr::BodySet::AVX2, binbcsr::BodySet::AVX512}) {
          if (element_body_used(body) != body) continue;
          INFO("element body " << binbcsr::body_set_name(body));
          const std::vector<double> batched = run(ElementKernel::Batched, body);
          double                    diff    = 0;
          for (size_t k = 0; k < scalar.size(); ++k) {
            REQUIRE(std::isfinite(batched[k]));
            diff = std::max(diff, std::fabs(batched[k] - scalar[k]));
          }
          CHECK(diff <= 1e-12 * scale);
          // In single precision (a float matrix's COO values): the same sums rounded where they are
          // written. A block written once (every block unmerged) is the double block rounded, to the bit;
          // a merged block is rounded at each group's write, a few float roundings of partial sums.
          std::vector<float>  single(9 * p.rows.size(), std::nanf("")); // every block written or reset
          std::vector<double> rhs(x.size(), 0.0);
          reset_block_values(p, single);
          assemble_elements_single(m, elements, x.data(), v.data(), c, &p, single.data(), rhs.data(), nullptr,
                                   ElementKernel::Batched, body);
          double single_diff = 0;
          size_t exact       = 0;
          for (size_t k = 0; k < batched.size(); ++k) {
            REQUIRE(std::isfinite(single[k]));
            single_diff = std::max(single_diff, std::fabs(single[k] - batched[k]));
            exact += single[k] == static_cast<float>(batched[k]);
          }
          if (!merge) CHECK(exact == batched.size());
          CHECK(single_diff <= 8 * FLT_EPSILON * scale);
        }
        // The reference loop in single precision goes through double blocks: its blocks rounded.
        std::vector<float>  single(9 * p.rows.size(), std::nanf(""));
        std::vector<double> rhs(x.size(), 0.0);
        reset_block_values(p, single);
        assemble_elements_single(m, elements, x.data(), v.data(), c, &p, single.data(), rhs.data(), nullptr,
                                 ElementKernel::Scalar);
        for (size_t k = 0; k < scalar.size(); ++k) REQUIRE(single[k] == static_cast<float>(scalar[k]));
      }
}

TEST_CASE("clustered element order: the same elements, fewer block writes per write group", "[fem][batch]")
{
  for (int order : {1, 2}) {
    INFO("order " << order);
    TetMesh mesh = make_box_mesh(1.0, 0.8, 0.6, 12, 10, 8);
    if (order == 2) mesh = promote_to_quadratic(mesh);
    sort_elements_by_lowest_node(mesh);
    const int              npe = mesh.nodes_per_element(), group = kElementLanes * write_group_batches(npe);
    const std::vector<int> before = mesh.elements;
    cluster_elements(mesh, group);
    // a permutation of whole elements (each keeps its node order: its orientation)
    std::vector<std::vector<int>> a, b;
    for (size_t e = 0; e < before.size(); e += npe) {
      a.emplace_back(before.begin() + e, before.begin() + e + npe);
      b.emplace_back(mesh.elements.begin() + e, mesh.elements.begin() + e + npe);
    }
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    CHECK(a == b);
    // the write groups of the clustered order touch fewer blocks (linear_38k: 19% fewer writes)
    const auto writes = [&](const std::vector<int> &elements) {
      TetMesh m              = mesh;
      m.elements             = elements;
      const FemModel   model = make_fem_model(m, FemSettings{});
      std::vector<int> list(model.element_count());
      std::iota(list.begin(), list.end(), 0);
      const BlockPattern p = make_block_pattern(model, list, std::vector<char>(m.node_count(), 0), 0,
                                                m.node_count(), true, LowerTriangle{});
      return p.plan.write_slots.size();
    };
    const size_t sorted = writes(before), clustered = writes(mesh.elements);
    INFO("block writes: sorted " << sorted << ", clustered " << clustered);
    CHECK(clustered < 0.97 * sorted);
  }
  // a group of one, or a mesh of at most one group, keeps the order
  TetMesh                mesh   = make_box_mesh(1, 1, 1, 2, 2, 2);
  const std::vector<int> before = mesh.elements;
  cluster_elements(mesh, 1);
  CHECK(mesh.elements == before);
  cluster_elements(mesh, mesh.element_count());
  CHECK(mesh.elements == before);
}
