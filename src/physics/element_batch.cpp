#include "physics/element_batch.hpp"
#include "physics/element_kernels.hpp"
#include "physics/polar_decomposition.hpp"

#include <algorithm>

namespace physics {

namespace {

constexpr int W = kElementLanes;

// One batch as structure of arrays: entry k of lane l at [k * W + l].
template <int N> struct alignas(64) Batch {
  static constexpr int NB = packed_block_count(N);
  double               x[3 * N * W], v[3 * N * W], X[3 * N * W];
  double               Dinv[9 * W], F[9 * W], R[9 * W], vol[W];
  double               rhs[3 * N * W], blocks[NB * 9 * W];
  double               Q[N == 10 ? 16 * 9 * W : 1]; // P2: the rotated gradient pairs
  double               ok[W];                       // polar_rotation's acceptance per lane
};

// Lane l <- element e: its nodes' positions, velocities and rest positions, Dm^-1 and volume.
template <int N>
void gather(const FemModel &model, int e, int l, const double *x, const double *v, Batch<N> &b)
{
  const int    *nodes = &model.mesh.elements[static_cast<size_t>(e) * N];
  const double *X     = model.mesh.nodes.data();
  for (int a = 0; a < N; ++a) {
    const size_t n = 3 * static_cast<size_t>(nodes[a]);
    for (int d = 0; d < 3; ++d) {
      b.x[(3 * a + d) * W + l] = x[n + d];
      b.v[(3 * a + d) * W + l] = v[n + d];
      b.X[(3 * a + d) * W + l] = X[n + d];
    }
  }
  const double *Dinv = model.rest_shape_inverse[e].data();
  for (int j = 0; j < 9; ++j) b.Dinv[j * W + l] = Dinv[j];
  b.vol[l] = model.volume[e];
}

// Asks for the cache lines batch [start, start + m) will touch: its nodes' entries of x, v, X and rhs and
// its COO blocks. The write-out adds into blocks spread over several MB (6.7 MB of values for
// linear_38k): one batch ahead took the loop from 12-14 to 10.3-10.7 ms there (further ahead: no
// better).
template <int N, bool Blocks>
void prefetch_batch(const FemModel &model, const std::vector<int> &elements, size_t start, int m,
                    const double *x, const double *v, const double *rhs, const BlockPattern *pattern,
                    const double *values)
{
  const double *X = model.mesh.nodes.data();
  for (int l = 0; l < m; ++l) {
    const int *nodes = &model.mesh.elements[static_cast<size_t>(elements[start + l]) * N];
    for (int a = 0; a < N; ++a) {
      const size_t n = 3 * static_cast<size_t>(nodes[a]);
      __builtin_prefetch(x + n);
      __builtin_prefetch(v + n);
      __builtin_prefetch(X + n);
      __builtin_prefetch(rhs + n, 1);
    }
    if (!Blocks) continue;
    const int *slot = &pattern->element_slots[(start + l) * N * N];
    for (int k = 0; k < N * N; ++k) {
      if (slot[k] < 0) continue;
      const double *out = values + 9 * static_cast<size_t>(slot[k] & kSlotIndexMask);
      __builtin_prefetch(out, 1);
      __builtin_prefetch(out + 8, 1);
    }
  }
}

// Adds the row-major 3x3 block B (entry j at B[j * W]) into COO block s, or stores it where s is the
// block's first write (kFirstContribution); transposed: B^T.
inline void write_block(double *values, int s, const double *B, bool transposed)
{
  double *out = values + 9 * static_cast<size_t>(s & kSlotIndexMask);
  double  t[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t[3 * i + j] = transposed ? B[(3 * j + i) * W] : B[(3 * i + j) * W];
  if (s & kFirstContribution)
    for (int j = 0; j < 9; ++j) out[j] = t[j];
  else
    for (int j = 0; j < 9; ++j) out[j] += t[j];
}

template <int N, bool Blocks, bool MassDamping>
long long assemble_batched(const FemModel &model, const std::vector<int> &elements, const double *x,
                           const double *v, const kernels::ElementConstants &k, const BlockPattern *pattern,
                           double *values, double *rhs, Eigen::Matrix3d *rotations)
{
  double Mref[N * N];
  for (int a = 0; a < N; ++a)
    for (int c = 0; c < N; ++c) Mref[N * a + c] = model.reference_mass(a, c);
  const bool corotational = model.settings.corotational;
  Batch<N>   b;
  long long  fallbacks = 0;
  if (!corotational)
    for (int j = 0; j < 9; ++j)
      for (int l = 0; l < W; ++l) b.R[j * W + l] = j % 4 == 0 ? 1.0 : 0.0;
  const size_t n = elements.size();
  for (size_t start = 0; start < n; start += W) {
    const int m = static_cast<int>(std::min<size_t>(W, n - start));
    if (start + W < n)
      prefetch_batch<N, Blocks>(model, elements, start + W,
                                static_cast<int>(std::min<size_t>(W, n - start - W)), x, v, rhs, pattern,
                                values);
    // Lanes past the end repeat the last element; nothing of theirs is written out.
    for (int l = 0; l < W; ++l) gather<N>(model, elements[start + std::min(l, m - 1)], l, x, v, b);
    if (corotational) {
#pragma omp simd
      for (int l = 0; l < W; ++l) kernels::deformation_gradient<W>(b.x + l, b.Dinv + l, b.F + l);
#pragma omp simd
      for (int l = 0; l < W; ++l) b.ok[l] = kernels::polar_rotation<W>(b.F + l, b.R + l);
      for (int l = 0; l < m; ++l) {
        if (b.ok[l] != 0) continue; // rare: inverted, flat or strongly stretched elements
        Eigen::Matrix3d F;
        for (int j = 0; j < 9; ++j) F.data()[j] = b.F[j * W + l];
        const Eigen::Matrix3d R = rotation_from_deformation(F);
        for (int j = 0; j < 9; ++j) b.R[j * W + l] = R.data()[j];
        ++fallbacks;
      }
    }
    if constexpr (N == 4) {
#pragma omp simd
      for (int l = 0; l < W; ++l)
        kernels::p1_element<W, Blocks, MassDamping>(b.x + l, b.v + l, b.X + l, b.Dinv + l, b.R + l, b.vol[l],
                                                    k, b.rhs + l, b.blocks + l);
    } else {
#pragma omp simd
      for (int l = 0; l < W; ++l)
        kernels::p2_forces<W, MassDamping>(b.x + l, b.v + l, b.X + l, b.Dinv + l, b.R + l, b.vol[l], k, Mref,
                                           b.rhs + l);
      if (Blocks) {
#pragma omp simd
        for (int l = 0; l < W; ++l) kernels::p2_gradient_pairs<W>(b.Dinv + l, b.R + l, b.vol[l], k, b.Q + l);
        for (int p = 0; p < 55; ++p) {
#pragma omp simd
          for (int l = 0; l < W; ++l)
            kernels::p2_block<W>(p, b.Q + l, b.vol[l], k, Mref, b.blocks + 9 * p * W + l);
        }
      }
    }
    // Out in element order, lane after lane: the first-write marks of the slot map follow that order.
    for (int l = 0; l < m; ++l) {
      const size_t i     = start + l;
      const int   *nodes = &model.mesh.elements[static_cast<size_t>(elements[i]) * N];
      if (rotations)
        for (int j = 0; j < 9; ++j) rotations[i].data()[j] = b.R[j * W + l];
      for (int a = 0; a < N; ++a)
        for (int d = 0; d < 3; ++d) rhs[3 * static_cast<size_t>(nodes[a]) + d] += b.rhs[(3 * a + d) * W + l];
      if (!Blocks) continue;
      const int *slot = &pattern->element_slots[i * N * N];
      int        p    = 0;
      for (int a = 0; a < N; ++a)
        for (int c = a; c < N; ++c, ++p) {
          const int sab = slot[a * N + c], sba = slot[c * N + a];
          if (sab >= 0) write_block(values, sab, b.blocks + 9 * p * W + l, false);
          if (c != a && sba >= 0) write_block(values, sba, b.blocks + 9 * p * W + l, true);
        }
    }
  }
  return fallbacks;
}

template <int N>
long long assemble_order(const FemModel &model, const std::vector<int> &elements, const double *x,
                         const double *v, const kernels::ElementConstants &k, const BlockPattern *pattern,
                         double *values, double *rhs, Eigen::Matrix3d *rotations)
{
  const bool damping = k.mass_rhs != 0;
  if (values && damping)
    return assemble_batched<N, true, true>(model, elements, x, v, k, pattern, values, rhs, rotations);
  if (values)
    return assemble_batched<N, true, false>(model, elements, x, v, k, pattern, values, rhs, rotations);
  if (damping)
    return assemble_batched<N, false, true>(model, elements, x, v, k, pattern, values, rhs, rotations);
  return assemble_batched<N, false, false>(model, elements, x, v, k, pattern, values, rhs, rotations);
}

} // namespace

long long assemble_elements_batched(const FemModel &model, const std::vector<int> &elements, const double *x,
                                    const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                                    double *values, double *rhs, Eigen::Matrix3d *rotations)
{
  if (elements.empty()) return 0;
  const kernels::ElementConstants k{c.force,       c.stiffness_rhs,       c.mass_rhs,
                                    c.mass_matrix, c.stiffness_matrix,    model.lame.lambda,
                                    model.lame.mu, model.settings.density};
  if (model.npe == 4) return assemble_order<4>(model, elements, x, v, k, pattern, values, rhs, rotations);
  return assemble_order<10>(model, elements, x, v, k, pattern, values, rhs, rotations);
}

double element_kernel_flops(int order, bool with_blocks)
{
  // Counted from the kernels, a multiply-add as 2: deformation gradient 63; Newton 2 scaled steps of
  // about 110 and 3 plain ones of about 80. P1: forces about 360, blocks 670. P2: forces about 1,650;
  // blocks: 16 rotated gradient pairs of 40, 55 blocks of 4 (padded) terms of 18, and the mass.
  const double rotation = 63 + 2 * 110 + 3 * 80;
  if (order == 1) return rotation + 360 + (with_blocks ? 670 : 0);
  return rotation + 1650 + (with_blocks ? 16 * 40 + 55 * (4 * 18 + 10) : 0);
}

} // namespace physics
