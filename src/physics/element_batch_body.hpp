// The batch loop of the element kernels, the one source of every body set: element_batch_portable.cpp,
// element_batch_avx2.cpp and element_batch_avx512.cpp each define BINBCSR_ELEMENT_SET (the set's name,
// an inline namespace: each set gets its own symbols, element_kernels.hpp) and include this header
// once, before anything else, and are compiled with their set's target flags (CMakeLists.txt).
//
// Everything here works on ElementBatchArgs' plain arrays, so a body instantiates no Eigen or STL code
// that the linker could share with a translation unit of another set; the one call out is the scalar
// rotation (element_fallback_rotation, compiled at the baseline) for the rare elements the fixed
// Newton steps refuse.
//
// A batch holds kElementLanes elements as structure of arrays (gathered positions, rest shapes,
// rotations, outputs), one `omp simd` loop over the lanes per step, then the batch's blocks and forces
// are written out lane after lane in element order (lanes may share nodes and COO blocks).
#pragma once
#if !defined(BINBCSR_ELEMENT_SET)
  #error "define BINBCSR_ELEMENT_SET (the body set's name) before including element_batch_body.hpp"
#endif
#include "physics/element_batch.hpp"

namespace physics {
namespace kernels {
inline namespace BINBCSR_ELEMENT_SET {
namespace batch {

constexpr int W = kElementLanes;

// One batch as structure of arrays: entry k of lane l at [k * W + l].
template <int N> struct alignas(64) Batch {
  static constexpr int NB = N * (N + 1) / 2; // the upper blocks (fem_model.hpp's packed_block_count)
  double               x[3 * N * W], v[3 * N * W], X[3 * N * W];
  double               Dinv[9 * W], F[9 * W], R[9 * W], vol[W];
  double               rhs[3 * N * W], blocks[NB * 9 * W];
  double               Q[N == 10 ? 16 * 9 * W : 1]; // P2: the rotated gradient pairs
  double               ok[W];                       // polar_rotation's acceptance per lane
};

// Lane l <- element e: its nodes' positions, velocities and rest positions, Dm^-1 and volume.
template <int N> inline void gather(const ElementBatchArgs &a, int e, int l, Batch<N> &b)
{
  const int *nodes = a.element_nodes + static_cast<std::size_t>(e) * N;
  for (int c = 0; c < N; ++c) {
    const std::size_t n = 3 * static_cast<std::size_t>(nodes[c]);
    for (int d = 0; d < 3; ++d) {
      b.x[(3 * c + d) * W + l] = a.x[n + d];
      b.v[(3 * c + d) * W + l] = a.v[n + d];
      b.X[(3 * c + d) * W + l] = a.rest_positions[n + d];
    }
  }
  const double *Dinv = a.rest_shape_inverse + 9 * static_cast<std::size_t>(e);
  for (int j = 0; j < 9; ++j) b.Dinv[j * W + l] = Dinv[j];
  b.vol[l] = a.volume[e];
}

// Asks for the cache lines batch [start, start + m) will touch: its nodes' entries of x, v, X and rhs and
// its COO blocks. The write-out adds into blocks spread over several MB (6.7 MB of values for
// linear_38k): one batch ahead took the loop from 12-14 to 10.3-10.7 ms there (further ahead: no
// better).
template <int N, bool Blocks> inline void prefetch_batch(const ElementBatchArgs &a, std::size_t start, int m)
{
  for (int l = 0; l < m; ++l) {
    const int *nodes = a.element_nodes + static_cast<std::size_t>(a.elements[start + l]) * N;
    for (int c = 0; c < N; ++c) {
      const std::size_t n = 3 * static_cast<std::size_t>(nodes[c]);
      __builtin_prefetch(a.x + n);
      __builtin_prefetch(a.v + n);
      __builtin_prefetch(a.rest_positions + n);
      __builtin_prefetch(a.rhs + n, 1);
    }
    if (!Blocks) continue;
    const int *slot = a.element_slots + (start + l) * N * N;
    for (int k = 0; k < N * N; ++k) {
      if (slot[k] < 0) continue;
      const double *out = a.values + 9 * static_cast<std::size_t>(slot[k] & kSlotIndexMask);
      __builtin_prefetch(out, 1);
      __builtin_prefetch(out + 8, 1);
    }
  }
}

// Adds the row-major 3x3 block B (entry j at B[j * W]) into COO block s, or stores it where s is the
// block's first write (kFirstContribution); transposed: B^T.
inline void write_block(double *values, int s, const double *B, bool transposed)
{
  double *out = values + 9 * static_cast<std::size_t>(s & kSlotIndexMask);
  double  t[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t[3 * i + j] = transposed ? B[(3 * j + i) * W] : B[(3 * i + j) * W];
  if (s & kFirstContribution)
    for (int j = 0; j < 9; ++j) out[j] = t[j];
  else
    for (int j = 0; j < 9; ++j) out[j] += t[j];
}

template <int N, bool Blocks, bool MassDamping> long long run(const ElementBatchArgs &a)
{
  const ElementConstants &k = a.k;
  double                  Mref[N * N];
  for (int j = 0; j < N * N; ++j) Mref[j] = a.reference_mass[j];
  Batch<N>  b;
  long long fallbacks = 0;
  if (!a.corotational)
    for (int j = 0; j < 9; ++j)
      for (int l = 0; l < W; ++l) b.R[j * W + l] = j % 4 == 0 ? 1.0 : 0.0;
  const std::size_t n = a.count;
  for (std::size_t start = 0; start < n; start += W) {
    const int m = n - start < W ? static_cast<int>(n - start) : W;
    if (start + W < n) prefetch_batch<N, Blocks>(a, start + W, n - start - W < W ? int(n - start - W) : W);
    // Lanes past the end repeat the last element; nothing of theirs is written out.
    for (int l = 0; l < W; ++l) gather<N>(a, a.elements[start + (l < m ? l : m - 1)], l, b);
    if (a.corotational) {
#pragma omp simd
      for (int l = 0; l < W; ++l) deformation_gradient<W>(b.x + l, b.Dinv + l, b.F + l);
#pragma omp simd
      for (int l = 0; l < W; ++l) b.ok[l] = polar_rotation<W>(b.F + l, b.R + l);
      for (int l = 0; l < m; ++l) {
        if (b.ok[l] != 0) continue; // rare: inverted, flat or strongly stretched elements
        double F[9], R[9];
        for (int j = 0; j < 9; ++j) F[j] = b.F[j * W + l];
        element_fallback_rotation(F, R);
        for (int j = 0; j < 9; ++j) b.R[j * W + l] = R[j];
        ++fallbacks;
      }
    }
    if constexpr (N == 4) {
#pragma omp simd
      for (int l = 0; l < W; ++l)
        p1_element<W, Blocks, MassDamping>(b.x + l, b.v + l, b.X + l, b.Dinv + l, b.R + l, b.vol[l], k,
                                           b.rhs + l, b.blocks + l);
    } else {
#pragma omp simd
      for (int l = 0; l < W; ++l)
        p2_forces<W, MassDamping>(b.x + l, b.v + l, b.X + l, b.Dinv + l, b.R + l, b.vol[l], k, Mref,
                                  b.rhs + l);
      if (Blocks) {
#pragma omp simd
        for (int l = 0; l < W; ++l) p2_gradient_pairs<W>(b.Dinv + l, b.R + l, b.vol[l], k, b.Q + l);
        for (int p = 0; p < 55; ++p) {
#pragma omp simd
          for (int l = 0; l < W; ++l) p2_block<W>(p, b.Q + l, b.vol[l], k, Mref, b.blocks + 9 * p * W + l);
        }
      }
    }
    // Out in element order, lane after lane: the first-write marks of the slot map follow that order.
    for (int l = 0; l < m; ++l) {
      const std::size_t i     = start + l;
      const int        *nodes = a.element_nodes + static_cast<std::size_t>(a.elements[i]) * N;
      if (a.rotations)
        for (int j = 0; j < 9; ++j) a.rotations[9 * i + j] = b.R[j * W + l];
      for (int c = 0; c < N; ++c)
        for (int d = 0; d < 3; ++d)
          a.rhs[3 * static_cast<std::size_t>(nodes[c]) + d] += b.rhs[(3 * c + d) * W + l];
      if (!Blocks) continue;
      const int *slot = a.element_slots + i * N * N;
      int        p    = 0;
      for (int r = 0; r < N; ++r)
        for (int c = r; c < N; ++c, ++p) {
          const int src = slot[r * N + c], scr = slot[c * N + r];
          if (src >= 0) write_block(a.values, src, b.blocks + 9 * p * W + l, false);
          if (c != r && scr >= 0) write_block(a.values, scr, b.blocks + 9 * p * W + l, true);
        }
    }
  }
  return fallbacks;
}

template <int N> long long run_order(const ElementBatchArgs &a)
{
  const bool damping = a.k.mass_rhs != 0;
  if (a.values && damping) return run<N, true, true>(a);
  if (a.values) return run<N, true, false>(a);
  if (damping) return run<N, false, true>(a);
  return run<N, false, false>(a);
}

// The set's ElementBatchBody.
inline long long run_batches(const ElementBatchArgs &a)
{
  if (a.count == 0) return 0;
  return a.npe == 4 ? run_order<4>(a) : run_order<10>(a);
}

} // namespace batch
} // namespace BINBCSR_ELEMENT_SET
} // namespace kernels
} // namespace physics
