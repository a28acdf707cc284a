// AVX-512 pieces of the element batch loop's gather and write-out (element_batch_body.hpp, included
// there when the body set targets AVX-512). An 8x8 transpose turns 8 lane rows of a batch's block into the 8
// lanes' blocks (entries 0..7, one register each; entry 8, the (2,2) entry, is the same in B and B^T),
// a transposed block is one permute and a select away (no branch on which of (a, b), (b, a) the matrix
// stores, an even bet per pair), and the first write to a COO block is a masked add.
#pragma once
#include <immintrin.h>

#include <cstddef>

namespace physics {
namespace kernels {
inline namespace BINBCSR_ELEMENT_SET {
namespace batch {
namespace avx512 {

// Rows r[0..7] (row e: entry e of 8 lanes) -> r[l]: lane l's entries 0..7.
inline void transpose8(__m512d r[8])
{
  __m512d t[8], u[8];
  for (int k = 0; k < 4; ++k) {
    t[2 * k]     = _mm512_unpacklo_pd(r[2 * k], r[2 * k + 1]);
    t[2 * k + 1] = _mm512_unpackhi_pd(r[2 * k], r[2 * k + 1]);
  }
  for (int k = 0; k < 2; ++k) {
    u[4 * k]     = _mm512_shuffle_f64x2(t[4 * k], t[4 * k + 2], 0x88);
    u[4 * k + 1] = _mm512_shuffle_f64x2(t[4 * k + 1], t[4 * k + 3], 0x88);
    u[4 * k + 2] = _mm512_shuffle_f64x2(t[4 * k], t[4 * k + 2], 0xDD);
    u[4 * k + 3] = _mm512_shuffle_f64x2(t[4 * k + 1], t[4 * k + 3], 0xDD);
  }
  for (int k = 0; k < 4; ++k) {
    r[k]     = _mm512_shuffle_f64x2(u[k], u[k + 4], 0x88);
    r[k + 4] = _mm512_shuffle_f64x2(u[k], u[k + 4], 0xDD);
  }
}

// A write term's block (entries 0..7 at b): B, or B^T where transpose is 1 (a permute either way: a
// select here became a branch, an even bet per term).
inline __m512d term(const double *b, int transpose)
{
  alignas(64) static constexpr long long kOrder[2][8] = {{0, 1, 2, 3, 4, 5, 6, 7}, {0, 3, 6, 1, 4, 7, 2, 5}};
  return _mm512_permutexvar_pd(_mm512_load_si512(kOrder[transpose]), _mm512_load_pd(b));
}

// COO block s (kFirstContribution: store) += the block with entries 0..7 in b and entry 8 in b8. The
// first write loads what it overwrites, and the masked add keeps b there (NaN or not): no branch.
inline void write_block(double *values, int s, __m512d b, double b8)
{
  double        *out = values + 9 * static_cast<std::size_t>(s & kSlotIndexMask);
  const __mmask8 add = static_cast<__mmask8>(((s & kFirstContribution) != 0) - 1); // first: 0, else all
  _mm512_storeu_pd(out, _mm512_mask_add_pd(b, add, _mm512_loadu_pd(out), b));
  const __m128d t = _mm_set_sd(b8);
  _mm_store_sd(out + 8, _mm_mask_add_sd(t, add, _mm_load_sd(out + 8), t));
}

// The same into single-precision values (MatBinBCSRSetValuesCOOSingle): the sum is formed in double and
// rounded once per write.
inline void write_block(float *values, int s, __m512d b, double b8)
{
  float         *out = values + 9 * static_cast<std::size_t>(s & kSlotIndexMask);
  const __mmask8 add = static_cast<__mmask8>(((s & kFirstContribution) != 0) - 1); // first: 0, else all
  _mm256_storeu_ps(out,
                   _mm512_cvtpd_ps(_mm512_mask_add_pd(b, add, _mm512_cvtps_pd(_mm256_loadu_ps(out)), b)));
  const __m128d t = _mm_set_sd(b8);
  const __m128d r = _mm_mask_add_sd(t, add, _mm_cvtss_sd(t, _mm_load_ss(out + 8)), t);
  _mm_store_ss(out + 8, _mm_cvtsd_ss(_mm_setzero_ps(), r));
}

// Rows r0, r1, r2 <- entries 0, 1, 2 of 8 lanes' triples base[off[l] .. off[l] + 3): a 4-wide load
// per lane and a transpose. The load reads one entry past the triple, so the triple that ends the
// array (off[l] == end - 3) is loaded masked; masked loads throughout made the batch loop ~20%
// slower than the scalar moves (Zen 5), unmasked ones ~10% faster.
inline void load_triples(const double *base, std::size_t end, const std::size_t off[8], __m512d &r0,
                         __m512d &r1, __m512d &r2)
{
  __m256d q[8];
  for (int l = 0; l < 8; ++l)
    q[l] = off[l] + 3 < end ? _mm256_loadu_pd(base + off[l]) : _mm256_maskz_loadu_pd(7, base + off[l]);
  __m512d z[4]; // z[l] = (lane l: x y z -, lane l + 4: x y z -)
  for (int l = 0; l < 4; ++l) z[l] = _mm512_insertf64x4(_mm512_castpd256_pd512(q[l]), q[l + 4], 1);
  const __m512d t0 = _mm512_unpacklo_pd(z[0], z[1]), t1 = _mm512_unpackhi_pd(z[0], z[1]);
  const __m512d t2 = _mm512_unpacklo_pd(z[2], z[3]), t3 = _mm512_unpackhi_pd(z[2], z[3]);
  const __m512i lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13),
                hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  r0               = _mm512_permutex2var_pd(t0, lo, t2);
  r1               = _mm512_permutex2var_pd(t1, lo, t3);
  r2               = _mm512_permutex2var_pd(t0, hi, t2);
}

// A full batch's nodal rows (entry k of lane l at [k * 8 + l]) from its 8 elements' nodes (N each,
// in lane order) and the 3-per-node arrays x, v, X of `nodes` nodes.
template <int N>
inline void gather_nodes(const int *element_nodes, std::size_t nodes, const double *x, const double *v,
                         const double *X, double *bx, double *bv, double *bX)
{
  const std::size_t end = 3 * nodes;
  for (int c = 0; c < N; ++c) {
    std::size_t off[8];
    for (int l = 0; l < 8; ++l) off[l] = 3 * static_cast<std::size_t>(element_nodes[l * N + c]);
    const double *from[3] = {x, v, X};
    double       *to[3]   = {bx, bv, bX};
    for (int q = 0; q < 3; ++q) {
      __m512d r[3];
      load_triples(from[q], end, off, r[0], r[1], r[2]);
      for (int d = 0; d < 3; ++d) _mm512_store_pd(to[q] + (3 * c + d) * 8, r[d]);
    }
  }
}

} // namespace avx512
} // namespace batch
} // namespace BINBCSR_ELEMENT_SET
} // namespace kernels
} // namespace physics
