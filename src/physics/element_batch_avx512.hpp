// AVX-512 pieces of the element batch loop's write-out (element_batch_body.hpp, included there when
// the body set targets AVX-512). An 8x8 transpose turns 8 lane rows of a batch's block into the 8
// lanes' blocks (entries 0..7, one register each; entry 8, the (2,2) entry, is the same in B and B^T),
// a transposed block is one permute and a select away (no branch on which of (a, b), (b, a) the matrix
// stores, an even bet per pair), and the first write to a COO block is a masked add.
#pragma once
#include <immintrin.h>

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

} // namespace avx512
} // namespace batch
} // namespace BINBCSR_ELEMENT_SET
} // namespace kernels
} // namespace physics
