#include "physics/corotational_assembly.hpp"
#include "physics/element_batch.hpp"
#include "physics/polar_decomposition.hpp"

#include <algorithm>
#include <stdexcept>

namespace physics {

StepCoefficients implicit_euler_coefficients(double dt, double alpha, double beta)
{
  StepCoefficients c;
  c.force            = dt;
  c.stiffness_rhs    = dt * dt + dt * beta;
  c.mass_rhs         = dt * alpha;
  c.mass_matrix      = 1 + dt * alpha;
  c.stiffness_matrix = dt * dt + dt * beta;
  return c;
}

namespace {

// BlockPattern::plan from the element slots (marks ignored) of `count` listed elements.
BlockPattern::WritePlan make_write_plan(const std::vector<int> &element_slots, int npe, size_t count,
                                        size_t blocks)
{
  BlockPattern::WritePlan plan;
  const int               nb = packed_block_count(npe), group = kElementLanes * write_group_batches(npe);
  static_assert(2 * kElementLanes * write_group_batches(4) * packed_block_count(4) <= 65536 &&
                  2 * kElementLanes * write_group_batches(10) * packed_block_count(10) <= 65536,
                "a write term must fit 16 bits");
  std::vector<char>                           written(blocks, 0);
  std::vector<std::pair<int, unsigned short>> terms; // (COO block, term) of one group
  struct Run {
    int start, count, first; // the block's terms in `terms`, and whether the group writes it first
  };
  std::vector<Run> runs;
  plan.group_offsets.push_back(0);
  plan.group_terms.push_back(0);
  plan.run_offsets.push_back(0);
  for (size_t g0 = 0; g0 < count; g0 += group) {
    terms.clear();
    for (size_t i = g0; i < std::min(count, g0 + group); ++i) {
      const int *slot = &element_slots[i * npe * npe];
      int        p    = 0;
      for (int a = 0; a < npe; ++a)
        for (int b = a; b < npe; ++b, ++p) {
          const int term = 2 * (static_cast<int>(i - g0) * nb + p);
          const int sab = slot[a * npe + b] & kSlotIndexMask, sba = slot[b * npe + a] & kSlotIndexMask;
          if (slot[a * npe + b] >= 0) terms.emplace_back(sab, static_cast<unsigned short>(term));
          if (b != a && slot[b * npe + a] >= 0)
            terms.emplace_back(sba, static_cast<unsigned short>(term + 1));
        }
    }
    std::stable_sort(terms.begin(), terms.end(),
                     [](const auto &x, const auto &y) { return x.first < y.first; });
    // The group's blocks (first term, term count), then in runs of equal term count and first write,
    // ascending within a run: the write-out's loop over a block's terms and its store-or-add then take
    // the same branches block after block. In ascending order alone they changed from block to block
    // (of quadratic_47k's 344k block writes 230k have one term, 93k two) and the mispredictions
    // serialised the write-out (~17 ns per block written). Each block's terms keep element order.
    runs.clear();
    for (size_t k = 0; k < terms.size(); ++k) {
      if (k == 0 || terms[k].first != terms[k - 1].first)
        runs.push_back({static_cast<int>(k), 0, written[terms[k].first] ? 0 : 1});
      runs.back().count++;
    }
    std::stable_sort(runs.begin(), runs.end(), [](const Run &x, const Run &y) {
      return x.count != y.count ? x.count < y.count : x.first > y.first;
    });
    for (size_t r = 0; r < runs.size(); ++r) {
      const Run &b = runs[r];
      const int  s = terms[b.start].first;
      plan.write_slots.push_back(b.first ? s | kFirstContribution : s);
      written[s] = 1;
      for (int t = 0; t < b.count; ++t) plan.write_terms.push_back(terms[b.start + t].second);
      if (r == 0 || b.count != runs[r - 1].count) plan.runs.insert(plan.runs.end(), {b.count, 0});
      ++plan.runs.back();
    }
    plan.group_offsets.push_back(static_cast<int>(plan.write_slots.size()));
    plan.group_terms.push_back(static_cast<int>(plan.write_terms.size()));
    plan.run_offsets.push_back(static_cast<int>(plan.runs.size() / 2));
  }
  return plan;
}

// The plan of the same element slots with the COO blocks renumbered (renumber: old -> new), made from
// the plan itself: the groups, their blocks, term counts and first writes do not change, only the order
// within a run of blocks the group does not write first (ascending in the new numbers; the first
// writes are numbered in the order the plan makes them, so they are ascending already). The same
// plan as make_write_plan of the renumbered slots, without sorting every group's terms again.
void renumber_write_plan(BlockPattern::WritePlan &plan, const std::vector<int> &renumber)
{
  std::vector<int>            order, slots;
  std::vector<unsigned short> terms;
  for (size_t g = 0; g + 1 < plan.group_offsets.size(); ++g) {
    int    k = plan.group_offsets[g];
    size_t t = plan.group_terms[g];
    for (int r = plan.run_offsets[g]; r < plan.run_offsets[g + 1]; ++r) {
      const int count = plan.runs[2 * r], k1 = k + plan.runs[2 * r + 1];
      int       j0 = k1;
      for (int j = k; j < k1; ++j) {
        const int s         = plan.write_slots[j];
        plan.write_slots[j] = renumber[s & kSlotIndexMask] | (s & kFirstContribution);
        if (!(s & kFirstContribution) && j0 == k1) j0 = j;
      }
      if (k1 - j0 > 1) {
        order.resize(k1 - j0);
        for (int i = 0; i < k1 - j0; ++i) order[i] = i;
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return plan.write_slots[j0 + a] < plan.write_slots[j0 + b]; });
        slots.assign(plan.write_slots.begin() + j0, plan.write_slots.begin() + k1);
        const auto first_term = plan.write_terms.begin() + static_cast<std::ptrdiff_t>(t) +
                                static_cast<std::ptrdiff_t>(j0 - k) * count;
        terms.assign(first_term, first_term + static_cast<std::ptrdiff_t>(k1 - j0) * count);
        for (int i = 0; i < k1 - j0; ++i) {
          plan.write_slots[j0 + i] = slots[order[i]];
          std::copy_n(terms.begin() + static_cast<std::ptrdiff_t>(order[i]) * count, count,
                      first_term + static_cast<std::ptrdiff_t>(i) * count);
        }
      }
      t += static_cast<size_t>(k1 - k) * count;
      k = k1;
    }
  }
}

} // namespace

std::vector<int> listed_element_nodes(const FemModel &model, const std::vector<int> &elements)
{
  const int        npe = model.npe;
  std::vector<int> nodes(elements.size() * npe);
  for (size_t i = 0; i < elements.size(); ++i)
    std::copy_n(&model.mesh.elements[static_cast<size_t>(elements[i]) * npe], npe, &nodes[i * npe]);
  return nodes;
}

BlockPattern make_block_pattern(const FemModel &model, const std::vector<int> &elements,
                                const std::vector<char> &fixed, int owned_begin, int owned_end, bool merge,
                                const LowerTriangle &lower)
{
  BlockPattern p;
  p.merged      = merge;
  const int npe = model.npe;
  if (static_cast<int>(fixed.size()) != model.node_count())
    throw std::invalid_argument("fixed flags: wrong size");
  p.element_slots.assign(elements.size() * npe * npe, -1);
  std::vector<std::pair<long long, size_t>> keyed; // (row * n + col, position in element_slots)
  const long long                           n = model.node_count();
  std::vector<int> part; // part of each node, when lower blocks across parts are kept
  if (lower.drop && !lower.part_offsets.empty()) {
    part.assign(n, 0);
    for (size_t p = 0; p + 1 < lower.part_offsets.size(); ++p)
      for (int v = lower.part_offsets[p]; v < lower.part_offsets[p + 1]; ++v) part[v] = static_cast<int>(p);
  }
  const auto listed = [&](const int *nodes, int a, int b) {
    return !fixed[nodes[a]] && !fixed[nodes[b]] &&
           !(lower.drop && nodes[a] > nodes[b] && (part.empty() || part[nodes[a]] == part[nodes[b]]));
  };
  size_t count = 0; // sized first: grown as it went, its copies took ~6% of a one-step linear_38k run
  for (size_t i = 0; i < elements.size(); ++i) {
    const int *nodes = &model.mesh.elements[static_cast<size_t>(elements[i]) * npe];
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b) count += listed(nodes, a, b);
  }
  keyed.reserve(count);
  for (size_t i = 0; i < elements.size(); ++i) {
    const int *nodes = &model.mesh.elements[static_cast<size_t>(elements[i]) * npe];
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b)
        if (listed(nodes, a, b)) keyed.emplace_back(nodes[a] * n + nodes[b], (i * npe + a) * npe + b);
  }
  if (merge) std::sort(keyed.begin(), keyed.end());
  long long last = -1;
  for (const auto &kv : keyed) {
    if (!merge || kv.first != last) {
      p.rows.push_back(static_cast<int>(kv.first / n));
      p.cols.push_back(static_cast<int>(kv.first % n));
      last = kv.first;
    }
    p.element_slots[kv.second] = static_cast<int>(p.rows.size()) - 1;
  }
  // Mark the kernels' first write to each COO block (their loop order: elements, then a <= b, (a,b)
  // before (b,a)).
  std::vector<char> written(p.rows.size(), 0);
  for (size_t i = 0; i < elements.size(); ++i)
    for (int a = 0; a < npe; ++a)
      for (int b = a; b < npe; ++b)
        for (int *s :
             {&p.element_slots[(i * npe + a) * npe + b], &p.element_slots[(i * npe + b) * npe + a]}) {
          if (*s < 0 || written[*s & kSlotIndexMask]) continue; // (a == b: the same entry twice)
          written[*s] = 1;
          *s |= kFirstContribution;
        }
  p.plan = make_write_plan(p.element_slots, npe, elements.size(), p.rows.size());
  if (merge) {
    // Number the COO blocks in the order the batched loop first writes them: its first writes then
    // run along the values instead of jumping about them in row order, and its later additions find
    // blocks written a few groups before (quadratic_47k's 14.5 MB of values exceed the caches).
    std::vector<int> renumber(p.rows.size(), -1);
    int              next = 0;
    for (int s : p.plan.write_slots)
      if (renumber[s & kSlotIndexMask] < 0) renumber[s & kSlotIndexMask] = next++;
    for (int &r : renumber)
      if (r < 0) r = next++; // (no element writes it: not expected, kept for completeness)
    std::vector<int> rows(p.rows.size()), cols(p.cols.size());
    for (size_t k = 0; k < p.rows.size(); ++k) rows[renumber[k]] = p.rows[k], cols[renumber[k]] = p.cols[k];
    p.rows.swap(rows);
    p.cols.swap(cols);
    for (int &s : p.element_slots)
      if (s >= 0) s = renumber[s & kSlotIndexMask] | (s & kFirstContribution);
    renumber_write_plan(p.plan, renumber);
  }
  p.plan.element_nodes = listed_element_nodes(model, elements);
  for (int v = owned_begin; v < owned_end; ++v)
    if (fixed[v]) {
      p.identity_slots.push_back(static_cast<int>(p.rows.size()));
      p.rows.push_back(v);
      p.cols.push_back(v);
    }
  return p;
}

namespace {
template <typename V> void reset_values(const BlockPattern &pattern, std::vector<V> &values)
{
  values.resize(9 * pattern.rows.size());
  for (int s : pattern.identity_slots)
    for (int k = 0; k < 9; ++k) values[9 * static_cast<size_t>(s) + k] = k % 4 == 0 ? 1 : 0;
}
} // namespace

void reset_block_values(const BlockPattern &pattern, std::vector<double> &values)
{
  reset_values(pattern, values);
}
void reset_block_values(const BlockPattern &pattern, std::vector<float> &values)
{
  reset_values(pattern, values);
}

namespace {

// Adds B (a 3x3 expression) into the row-major block of element slot s, or stores it where s is the
// first write to that block.
template <typename Block> inline void write_block(double *values, int s, const Block &B)
{
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> out(values +
                                                               9 * static_cast<size_t>(s & kSlotIndexMask));
  if (s & kFirstContribution) out = B;
  else out += B;
}

// Elements are processed in chunks: the rotations of a chunk first (batched, see
// rotations_from_deformations), then the chunk's blocks and forces.
constexpr size_t kRotationChunk = 64;

// R[j] for elements[j], j < n (at most kRotationChunk): the rotation of the corner deformation
// gradient F = Ds Dm^-1, or I for plain linear elasticity.
void element_rotations(const FemModel &model, const int *elements, size_t n, const double *x,
                       Eigen::Matrix3d *R)
{
  using Vec3 = Eigen::Vector3d;
  if (!model.settings.corotational) {
    for (size_t j = 0; j < n; ++j) R[j].setIdentity();
    return;
  }
  Eigen::Matrix3d F[kRotationChunk];
  const int       npe = model.npe;
  for (size_t j = 0; j < n; ++j) {
    const int      *nodes = &model.mesh.elements[static_cast<size_t>(elements[j]) * npe];
    Eigen::Matrix3d Ds;
    for (int k = 0; k < 3; ++k) Ds.col(k) = Vec3::Map(x + 3 * nodes[k + 1]) - Vec3::Map(x + 3 * nodes[0]);
    F[j].noalias() = Ds * model.rest_shape_inverse[elements[j]];
  }
  rotations_from_deformations(F, R, n);
}

template <int N>
void assemble_kernel(const FemModel &model, const std::vector<int> &elements, const double *x,
                     const double *v, const StepCoefficients &c, const BlockPattern *pattern, double *values,
                     double *rhs, Eigen::Matrix3d *rotations)
{
  using Vec3                                     = Eigen::Vector3d;
  using Mat3                                     = Eigen::Matrix3d;
  constexpr int                     NB           = packed_block_count(N);
  const double                     *X            = model.mesh.nodes.data();
  const bool                        corotational = model.settings.corotational;
  const bool                        mass_damping = c.mass_rhs != 0;
  const Eigen::Matrix<double, N, N> Mref         = model.reference_mass;
  Mat3                              chunk_rotations[kRotationChunk];
  for (size_t i = 0; i < elements.size(); ++i) {
    if (i % kRotationChunk == 0)
      element_rotations(model, &elements[i], std::min(kRotationChunk, elements.size() - i), x,
                        chunk_rotations);
    const int     e     = elements[i];
    const int    *nodes = &model.mesh.elements[static_cast<size_t>(e) * N];
    const double *K0    = element_stiffness_blocks(model, e);
    const Mat3    R     = chunk_rotations[i % kRotationChunk];
    if (rotations) rotations[i] = R;
    // z = a_f (R^T x - X) + a_K R^T v, so that rhs_a = -R sum_b K0_ab z_b in one product with K0.
    Vec3 z[N], s[N];
    for (int b = 0; b < N; ++b) {
      z[b] = R.transpose() *
               (c.force * Vec3::Map(x + 3 * nodes[b]) + c.stiffness_rhs * Vec3::Map(v + 3 * nodes[b])) -
             c.force * Vec3::Map(X + 3 * nodes[b]);
      s[b].setZero();
    }
    const double mass = model.settings.density * model.volume[e];
    const int   *slot = values ? &pattern->element_slots[i * N * N] : nullptr;
    // One pass over the upper blocks of K0: force products and (optionally) the rotated blocks.
    for (int a = 0; a < N; ++a)
      for (int b = a; b < N; ++b) {
        const Eigen::Map<const Mat3> K(K0 + 9 * packed_block(a, b, N));
        s[a].noalias() += K * z[b];
        if (b != a) s[b].noalias() += K.transpose() * z[a];
        if (!slot) continue;
        const int sab = slot[a * N + b], sba = slot[b * N + a];
        if (sab < 0 && sba < 0) continue; // a or b is fixed (eliminated)
        Mat3 B;
        if (corotational) {
          const Mat3 RK = R * K;
          B.noalias()   = c.stiffness_matrix * RK * R.transpose();
        } else {
          B = c.stiffness_matrix * K;
        }
        B.diagonal().array() += c.mass_matrix * mass * Mref(a, b);
        // Stored row-major: the Map of a row-major matrix over the slot takes B as is. One of the
        // pair may be a lower block the matrix does not store (-1).
        if (sab >= 0) write_block(values, sab, B);
        if (b != a && sba >= 0) write_block(values, sba, B.transpose());
      }
    for (int a = 0; a < N; ++a) {
      Vec3 r = -(R * s[a]);
      if (mass_damping)
        for (int b = 0; b < N; ++b) r -= c.mass_rhs * mass * Mref(a, b) * Vec3::Map(v + 3 * nodes[b]);
      Vec3::Map(rhs + 3 * nodes[a]) += r;
    }
  }
}

// Linear tetrahedra: K0_ab = V (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I) with g the
// barycentric gradients, so R K0_ab R^T needs only the rotated gradients r = R g, and
// sum_b K0_ab z_b = V sigma g_a with sigma = lambda tr(G) I + mu (G + G^T), G = sum_b z_b g_b^T
// (the stress of the displacement z). Same results as assemble_kernel<4>, about a third of the work,
// and K0 is not read.
void assemble_kernel_p1(const FemModel &model, const std::vector<int> &elements, const double *x,
                        const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                        double *values, double *rhs, Eigen::Matrix3d *rotations)
{
  using Vec3           = Eigen::Vector3d;
  using Mat3           = Eigen::Matrix3d;
  const double *X      = model.mesh.nodes.data();
  const double  lambda = model.lame.lambda, mu = model.lame.mu;
  const double  mass_per_node = 0.25; // lumped: reference_mass = I / 4
  Mat3          chunk_rotations[kRotationChunk];
  for (size_t i = 0; i < elements.size(); ++i) {
    if (i % kRotationChunk == 0)
      element_rotations(model, &elements[i], std::min(kRotationChunk, elements.size() - i), x,
                        chunk_rotations);
    const int     e     = elements[i];
    const int    *nodes = &model.mesh.elements[static_cast<size_t>(e) * 4];
    const double *grad  = &model.gradients[static_cast<size_t>(e) * 12];
    const double  vol   = model.volume[e];
    const Mat3    R     = chunk_rotations[i % kRotationChunk];
    if (rotations) rotations[i] = R;
    Vec3 g[4];
    for (int a = 0; a < 4; ++a) g[a] = Vec3::Map(grad + 3 * a);
    Mat3 G = Mat3::Zero();
    for (int b = 0; b < 4; ++b) {
      const Vec3 z = R.transpose() * (c.force * Vec3::Map(x + 3 * nodes[b]) +
                                      c.stiffness_rhs * Vec3::Map(v + 3 * nodes[b])) -
                     c.force * Vec3::Map(X + 3 * nodes[b]);
      G.noalias() += z * g[b].transpose();
    }
    Mat3 sigma = mu * (G + G.transpose());
    sigma.diagonal().array() += lambda * G.trace();
    const Mat3   Rsigma = R * sigma;
    const double m      = model.settings.density * vol * mass_per_node;
    for (int a = 0; a < 4; ++a) {
      Vec3 r = -vol * (Rsigma * g[a]);
      if (c.mass_rhs != 0) r -= c.mass_rhs * m * Vec3::Map(v + 3 * nodes[a]);
      Vec3::Map(rhs + 3 * nodes[a]) += r;
    }
    if (!values) continue;
    Vec3 rg[4];
    for (int a = 0; a < 4; ++a) rg[a] = R * g[a];
    const double kv   = c.stiffness_matrix * vol;
    const int   *slot = &pattern->element_slots[i * 16];
    for (int a = 0; a < 4; ++a)
      for (int b = a; b < 4; ++b) {
        const int sab = slot[a * 4 + b], sba = slot[b * 4 + a];
        if (sab < 0 && sba < 0) continue;
        Mat3 B = (kv * lambda) * rg[a] * rg[b].transpose() + (kv * mu) * rg[b] * rg[a].transpose();
        B.diagonal().array() += kv * mu * g[a].dot(g[b]) + (a == b ? c.mass_matrix * m : 0.0);
        if (sab >= 0) write_block(values, sab, B);
        if (b != a && sba >= 0) write_block(values, sba, B.transpose());
      }
  }
}

} // namespace

// The batched loop writes the rotations as 9 doubles each, into the caller's array of Matrix3d.
static_assert(sizeof(Eigen::Matrix3d) == 9 * sizeof(double), "Matrix3d is not 9 packed doubles");

namespace {
// assemble_elements' argument checks (both precisions of the blocks).
void check_pattern(const FemModel &model, const std::vector<int> &elements, const BlockPattern *pattern,
                   bool block_values)
{
  if (block_values && !pattern) throw std::invalid_argument("assemble_elements: block values need a pattern");
  if (pattern && pattern->element_slots.size() != elements.size() * model.npe * model.npe)
    throw std::invalid_argument("assemble_elements: pattern was built for another element list");
}
} // namespace

long long assemble_elements(const FemModel &model, const std::vector<int> &elements, const double *x,
                            const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                            double *block_values, double *rhs, Eigen::Matrix3d *rotations,
                            ElementKernel kernel, binbcsr::BodySet body, ElementEnergy *energy)
{
  check_pattern(model, elements, pattern, block_values != nullptr);
  if (kernel == ElementKernel::Batched)
    return assemble_elements_batched(model, elements, x, v, c, block_values ? pattern : nullptr, block_values,
                                     rhs, rotations ? rotations->data() : nullptr, body, energy);
  if (energy) // the reference loop's figures: the definition, element by element
    for (size_t i = 0; i < elements.size(); ++i) {
      const FemEnergy E   = element_energy(model, x, v, elements[i]);
      const double    inv = element_signed_volume(model.mesh, x, elements[i]) > 0 ? 0.0 : 1.0;
      energy->elastic += E.elastic;
      energy->kinetic += E.kinetic;
      energy->inverted += inv;
      if (energy->per_element) {
        double *out = energy->per_element + 3 * i;
        out[0] = E.elastic, out[1] = E.kinetic, out[2] = inv;
      }
    }
  if (model.npe == 4 && !model.gradients.empty())
    assemble_kernel_p1(model, elements, x, v, c, pattern, block_values, rhs, rotations);
  else if (model.npe == 4)
    assemble_kernel<4>(model, elements, x, v, c, pattern, block_values, rhs, rotations);
  else assemble_kernel<10>(model, elements, x, v, c, pattern, block_values, rhs, rotations);
  return 0;
}

long long assemble_elements_single(const FemModel &model, const std::vector<int> &elements, const double *x,
                                   const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                                   float *block_values, double *rhs, Eigen::Matrix3d *rotations,
                                   ElementKernel kernel, binbcsr::BodySet body, ElementEnergy *energy)
{
  check_pattern(model, elements, pattern, block_values != nullptr);
  if (!block_values)
    return assemble_elements(model, elements, x, v, c, pattern, nullptr, rhs, rotations, kernel, body,
                             energy);
  if (kernel == ElementKernel::Batched)
    return assemble_elements_batched_single(model, elements, x, v, c, pattern, block_values, rhs,
                                            rotations ? rotations->data() : nullptr, body, energy);
  // The reference loop writes double blocks: through a copy (the identity blocks included).
  std::vector<double> wide(block_values, block_values + 9 * pattern->rows.size());
  const long long     n =
    assemble_elements(model, elements, x, v, c, pattern, wide.data(), rhs, rotations, kernel, body, energy);
  std::copy(wide.begin(), wide.end(), block_values);
  return n;
}

std::vector<double> elastic_forces(const FemModel &model, const double *x)
{
  std::vector<int> all(model.element_count());
  for (int e = 0; e < model.element_count(); ++e) all[e] = e;
  std::vector<double> f(3 * static_cast<size_t>(model.node_count()), 0.0), zero_v(f.size(), 0.0);
  StepCoefficients    c; // a_f = 1, nothing else
  assemble_elements(model, all, x, zero_v.data(), c, nullptr, nullptr, f.data());
  return f;
}

} // namespace physics
