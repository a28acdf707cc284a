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
// rotations, outputs), one `omp simd` loop over the lanes per step, then the batch's forces are added
// lane after lane in element order (lanes may share nodes) and its blocks go to the stage of its
// write group (element_batch.hpp); after the group's last batch each COO block the group touches
// gets the sum of the group's contributions to it, once (BlockPattern::plan).
#pragma once
#if !defined(BINBCSR_ELEMENT_SET)
  #error "define BINBCSR_ELEMENT_SET (the body set's name) before including element_batch_body.hpp"
#endif
#include "physics/element_batch.hpp"
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
  #define BINBCSR_ELEMENT_BATCH_AVX512 1
  #include "physics/element_batch_avx512.hpp"
#else
  #define BINBCSR_ELEMENT_BATCH_AVX512 0
#endif
#if !BINBCSR_ELEMENT_BATCH_AVX512 && defined(__AVX2__) && defined(__FMA__)
  #define BINBCSR_ELEMENT_BATCH_AVX2 1
  #include "physics/element_batch_avx2.hpp"
#else
  #define BINBCSR_ELEMENT_BATCH_AVX2 0
#endif

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
  double               Q[N == 10 ? 16 * 9 * W : W]; // P2: the rotated gradient pairs (W: rows stay aligned)
  double PX[9 * W], PC[9 * W], pdet[W], pflag[W], pchange[W], pnear[W]; // the polar iteration's state
  double ok[W];                                                         // its acceptance per lane
  double elastic[W], kinetic[W], inverted[W]; // the state's figures (ElementBatchArgs::energy)
};

// Lane l <- listed element i: its nodes' positions, velocities and rest positions.
template <int N> inline void gather_lane(const ElementBatchArgs &a, std::size_t i, int l, Batch<N> &b)
{
  const int *nodes = a.listed_nodes + i * N;
  for (int c = 0; c < N; ++c) {
    const std::size_t n = 3 * static_cast<std::size_t>(nodes[c]);
    for (int d = 0; d < 3; ++d) {
      b.x[(3 * c + d) * W + l] = a.x[n + d];
      b.v[(3 * c + d) * W + l] = a.v[n + d];
      b.X[(3 * c + d) * W + l] = a.rest_positions[n + d];
    }
  }
}

// The lanes <- listed elements [start, start + m); lanes past the end repeat the last element (nothing
// of theirs is written out). AVX-512: a full batch's node rows by 4-wide loads (avx512::gather_nodes).
template <int N> inline void gather(const ElementBatchArgs &a, std::size_t start, int m, Batch<N> &b)
{
#if BINBCSR_ELEMENT_BATCH_AVX512
  static_assert(W == 8, "a batch's row is one AVX-512 register");
  if (m == W) {
    avx512::gather_nodes<N>(a.listed_nodes + start * N, a.nodes, a.x, a.v, a.rest_positions, b.x, b.v, b.X);
    return;
  }
#endif
  for (int l = 0; l < W; ++l) gather_lane<N>(a, start + (l < m ? l : m - 1), l, b);
}

// Asks for the cache lines batch [start, start + m) will touch in x, v, X and rhs (its nodes'
// entries), one batch ahead.
template <int N> inline void prefetch_nodes(const ElementBatchArgs &a, std::size_t start, int m)
{
  for (int l = 0; l < m; ++l) {
    const int *nodes = a.listed_nodes + (start + l) * N;
    for (int c = 0; c < N; ++c) {
      const std::size_t n = 3 * static_cast<std::size_t>(nodes[c]);
      __builtin_prefetch(a.x + n);
      __builtin_prefetch(a.v + n);
      __builtin_prefetch(a.rest_positions + n);
      __builtin_prefetch(a.rhs + n, 1);
    }
  }
}

// The value array the blocks go to: ElementBatchArgs::values (double) or values_single (float).
template <typename V> inline V *block_values(const ElementBatchArgs &a);
template <> inline double      *block_values<double>(const ElementBatchArgs &a) { return a.values; }
template <> inline float       *block_values<float>(const ElementBatchArgs &a) { return a.values_single; }

// And the COO blocks write_slots[k0, k1) (the group's write-out, a share per batch: the values are
// several MB, 6.7 for linear_38k in double, so most blocks come from L3).
template <typename V> inline void prefetch_blocks(const ElementBatchArgs &a, int k0, int k1)
{
  const V *const values = block_values<V>(a);
  for (int k = k0; k < k1; ++k) {
    const V *out = values + 9 * static_cast<std::size_t>(a.write_slots[k] & kSlotIndexMask);
    __builtin_prefetch(out, 1);
    __builtin_prefetch(out + 8, 1);
  }
}

// 1 where the first m lanes of f are all non-zero.
inline double all_lanes(const double *f, int m)
{
  double all = 1;
  for (int l = 0; l < m; ++l) all *= f[l];
  return all;
}

// The iteration's start on every lane, and whether the lane starts near a rotation (b.pnear).
template <int N> inline __attribute__((always_inline)) void batch_polar_start(Batch<N> &b)
{
#pragma omp simd
  for (int l = 0; l < W; ++l) {
    polar_start<W, W>(b.F + l, b.PX + l, b.PC + l, b.pdet + l, b.pflag + l);
    b.pnear[l] = b.pdet[l] > kPolarNearDet ? b.pflag[l] : 0.0;
  }
}

// Newton steps First .. Last - 1 on every lane (the first Scaled of the iteration scaled) and each
// lane's acceptance (b.ok); 1 where the first m lanes all pass.
template <int First, int Last, int Scaled = kPolarScaledSteps, int N>
inline __attribute__((always_inline)) double batch_polar_steps(Batch<N> &b, int m)
{
#pragma omp simd
  for (int l = 0; l < W; ++l) {
    polar_steps<W, First, Last, Scaled>(b.PX + l, b.PC + l, b.pdet + l, b.pflag + l, b.pchange + l);
    b.ok[l] = polar_accepted(b.pdet[l], b.pflag[l], b.pchange[l]);
  }
  return all_lanes(b.ok, m);
}

// The batch's rotations b.R from b.F and their acceptance b.ok: polar_rotation in pieces, one test per
// batch, not per lane. A batch whose first m lanes all start near a rotation runs kPolarEarlySteps
// unscaled steps and stops there if all pass (the scenes' elements); otherwise, and for every other
// batch, polar_rotation's steps from the start: kPolarEarlySteps, and the rest only when a lane has
// not passed. So the rotations accepted are those of polar_rotation, to its tolerance, and so are the
// lanes it refuses.
template <int N> inline __attribute__((always_inline)) void batch_rotations(Batch<N> &b, int m)
{
  batch_polar_start(b);
  double passed = 0;
  if (all_lanes(b.pnear, m) != 0) {
    passed = batch_polar_steps<0, kPolarEarlySteps, 0>(b, m);
    if (passed == 0) batch_polar_start(b); // again, for the scaled steps
  }
  if (passed == 0) passed = batch_polar_steps<0, kPolarEarlySteps>(b, m);
  if (passed == 0) batch_polar_steps<kPolarEarlySteps, kPolarSteps>(b, m);
#pragma omp simd
  for (int l = 0; l < W; ++l) polar_finish<W, W>(b.PX + l, b.ok[l], b.R + l);
}

// A write group's blocks, lane-major: entries 0..7 of (element in the group e, packed pair p) at
// head[e * NB + p], entry 8 at tail[e * NB + p] (the AVX-512 body moves 8 entries as one register,
// the AVX2 one as two).
template <int N> struct alignas(64) Stage {
  static constexpr int G = W * write_group_batches(N), NB = N * (N + 1) / 2;
  double               head[G * NB][8], tail[G * NB];
};

// Batch j of the group into the stage.
template <int N> inline void stage_batch(const Batch<N> &b, int j, Stage<N> &st)
{
  constexpr int NB = Batch<N>::NB;
  for (int p = 0; p < NB; ++p) {
#if BINBCSR_ELEMENT_BATCH_AVX512
    __m512d r[8];
    for (int e = 0; e < 8; ++e) r[e] = _mm512_load_pd(b.blocks + (9 * p + e) * W);
    avx512::transpose8(r);
    for (int l = 0; l < W; ++l) _mm512_store_pd(st.head[(j * W + l) * NB + p], r[l]);
#elif BINBCSR_ELEMENT_BATCH_AVX2
    static_assert(W % 4 == 0, "lanes in fours");
    for (int l0 = 0; l0 < W; l0 += 4)
      for (int e0 = 0; e0 < 8; e0 += 4) {
        __m256d r[4];
        for (int e = 0; e < 4; ++e) r[e] = _mm256_load_pd(b.blocks + (9 * p + e0 + e) * W + l0);
        avx2::transpose4(r);
        for (int l = 0; l < 4; ++l) _mm256_store_pd(st.head[(j * W + l0 + l) * NB + p] + e0, r[l]);
      }
#else
    for (int l = 0; l < W; ++l)
      for (int e = 0; e < 8; ++e) st.head[(j * W + l) * NB + p][e] = b.blocks[(9 * p + e) * W + l];
#endif
    for (int l = 0; l < W; ++l) st.tail[(j * W + l) * NB + p] = b.blocks[(9 * p + 8) * W + l];
  }
}

// Group g's write-out: each of its COO blocks gets the sum of its terms (stored where the group is the
// first to write the block, added otherwise).
template <int N, typename V>
inline void write_group(const ElementBatchArgs &a, std::size_t g, const Stage<N> &st)
{
  // (Locals: the stores into the values may alias anything, so fields of `a` would be read again.)
  const int *const slots = a.write_slots, *const runs = a.runs;
  const unsigned short *t      = a.write_terms + a.group_terms[g];
  V *const              values = block_values<V>(a);
  int                   k      = a.group_offsets[g];
  for (int r = a.run_offsets[g], r1 = a.run_offsets[g + 1]; r < r1; ++r) {
    const int count = runs[2 * r], k1 = k + runs[2 * r + 1];
    for (; k < k1; ++k, t += count) {
#if BINBCSR_ELEMENT_BATCH_AVX512
      __m512d acc  = avx512::term(st.head[t[0] >> 1], t[0] & 1);
      double  acc8 = st.tail[t[0] >> 1];
      for (int i = 1; i < count; ++i) {
        acc = _mm512_add_pd(acc, avx512::term(st.head[t[i] >> 1], t[i] & 1));
        acc8 += st.tail[t[i] >> 1];
      }
      avx512::write_block(values, slots[k], acc, acc8);
#elif BINBCSR_ELEMENT_BATCH_AVX2
      __m256d lo, hi, tlo, thi;
      avx2::term(st.head[t[0] >> 1], t[0] & 1, lo, hi);
      double acc8 = st.tail[t[0] >> 1];
      for (int i = 1; i < count; ++i) {
        avx2::term(st.head[t[i] >> 1], t[i] & 1, tlo, thi);
        lo = _mm256_add_pd(lo, tlo);
        hi = _mm256_add_pd(hi, thi);
        acc8 += st.tail[t[i] >> 1];
      }
      avx2::write_block(values, slots[k], lo, hi, acc8);
#else
      constexpr int kT[2][8] = {{0, 1, 2, 3, 4, 5, 6, 7}, {0, 3, 6, 1, 4, 7, 2, 5}}; // B, B^T
      double        acc[9];
      for (int e = 0; e < 8; ++e) acc[e] = st.head[t[0] >> 1][kT[t[0] & 1][e]];
      acc[8] = st.tail[t[0] >> 1];
      for (int i = 1; i < count; ++i) {
        for (int e = 0; e < 8; ++e) acc[e] += st.head[t[i] >> 1][kT[t[i] & 1][e]];
        acc[8] += st.tail[t[i] >> 1];
      }
      V *out = values + 9 * static_cast<std::size_t>(slots[k] & kSlotIndexMask);
      if (slots[k] & kFirstContribution)
        for (int e = 0; e < 9; ++e) out[e] = static_cast<V>(acc[e]);
      else
        for (int e = 0; e < 9; ++e) out[e] = static_cast<V>(out[e] + acc[e]);
#endif
    }
  }
}

// The state's figures of batch [start, start + m) from what the batch holds (R included), added to
// sums (and per element to a.element_energy). Not inlined into run: inlined, it left the element
// kernels' code slower by ~1 ms per step (quadratic_47k, Zen 5) even with the figures not asked for.
template <int N>
__attribute__((noinline)) void batch_energy(const ElementBatchArgs &a, Batch<N> &b, const double *Mref,
                                            std::size_t start, int m, double sums[3])
{
  const ElementConstants &k = a.k;
#pragma omp simd
  for (int l = 0; l < W; ++l) {
    if constexpr (N == 4) b.elastic[l] = p1_elastic_energy<W>(b.F + l, b.R + l, b.vol[l], k.lambda, k.mu);
    else b.elastic[l] = p2_elastic_energy<W>(b.x + l, b.X + l, b.Dinv + l, b.R + l, b.vol[l], k.lambda, k.mu);
    b.inverted[l] = corner_inverted<W>(b.x + l);
  }
  if (a.diagonal_mass) {
#pragma omp simd
    for (int l = 0; l < W; ++l)
      b.kinetic[l] = kinetic_energy_lumped<W, N>(b.v + l, Mref, b.vol[l], k.density);
  } else {
#pragma omp simd
    for (int l = 0; l < W; ++l) b.kinetic[l] = kinetic_energy<W, N>(b.v + l, Mref, b.vol[l], k.density);
  }
  for (int l = 0; l < m; ++l) {
    sums[0] += b.elastic[l];
    sums[1] += b.kinetic[l];
    sums[2] += b.inverted[l];
    if (a.element_energy) {
      double *out = a.element_energy + 3 * (start + l);
      out[0] = b.elastic[l], out[1] = b.kinetic[l], out[2] = b.inverted[l];
    }
  }
}

template <int N, bool Blocks, bool MassDamping, typename V = double> long long run(const ElementBatchArgs &a)
{
  const ElementConstants &k = a.k;
  double                  Mref[N * N];
  for (int j = 0; j < N * N; ++j) Mref[j] = a.reference_mass[j];
  Batch<N>  b;
  long long fallbacks = 0;
  if (!a.corotational)
    for (int j = 0; j < 9; ++j)
      for (int l = 0; l < W; ++l) b.R[j * W + l] = j % 4 == 0 ? 1.0 : 0.0;
  const std::size_t n  = a.count;
  constexpr int     GB = write_group_batches(N);
  Stage<N>          st;
  double            sums[3] = {0, 0, 0}; // elastic, kinetic, inverted (ElementBatchArgs::energy)
  for (std::size_t g = 0, start = 0; start < n; ++g) {
    const int k0 = Blocks ? a.group_offsets[g] : 0, kn = Blocks ? a.group_offsets[g + 1] - k0 : 0;
    for (int jb = 0; jb < GB && start < n; ++jb, start += W) {
      const int m = n - start < W ? static_cast<int>(n - start) : W;
      if (start + W < n) prefetch_nodes<N>(a, start + W, n - start - W < W ? int(n - start - W) : W);
      if (Blocks) prefetch_blocks<V>(a, k0 + kn * jb / GB, k0 + kn * (jb + 1) / GB);
      gather<N>(a, start, m, b);
#pragma omp simd
      for (int l = 0; l < W; ++l) rest_shape<W>(b.X + l, b.Dinv + l, b.vol + l);
#pragma omp simd
      for (int l = 0; l < W; ++l) deformation_gradient<W>(b.x + l, b.Dinv + l, b.F + l);
      if (a.corotational) {
        batch_rotations<N>(b, m);
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
      if (a.energy) batch_energy<N>(a, b, Mref, start, m, sums);
      // Forces (and rotations) out in element order, lane after lane; the blocks to the stage.
      for (int l = 0; l < m; ++l) {
        const std::size_t i     = start + l;
        const int        *nodes = a.listed_nodes + i * N;
        if (a.rotations)
          for (int q = 0; q < 9; ++q) a.rotations[9 * i + q] = b.R[q * W + l];
        for (int c = 0; c < N; ++c)
          for (int d = 0; d < 3; ++d)
            a.rhs[3 * static_cast<std::size_t>(nodes[c]) + d] += b.rhs[(3 * c + d) * W + l];
      }
      if (Blocks) stage_batch<N>(b, jb, st);
    }
    if (Blocks) write_group<N, V>(a, g, st);
  }
  if (a.energy)
    for (int j = 0; j < 3; ++j) a.energy[j] += sums[j];
  return fallbacks;
}

template <int N> long long run_order(const ElementBatchArgs &a)
{
  const bool damping = a.k.mass_rhs != 0;
  if (a.values_single) return damping ? run<N, true, true, float>(a) : run<N, true, false, float>(a);
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
