// AVX2 pieces of the element batch loop's write-out (element_batch_body.hpp, included there when the
// body set targets AVX2 but not AVX-512): the AVX-512 ones (element_batch_avx512.hpp) on two 4-wide
// halves. 4x4 transposes turn 4 lane rows of a batch's block into 4 lanes' entries; a transposed
// block is two permutes and two blends away (no branch on which of (a, b), (b, a) the matrix stores);
// the first write to a COO block adds to zero instead of what it overwrites (a mask, no branch).
// Without them GCC wrote the stage and summed the terms one double at a time: about a third of the
// linear_38k element loop on a Zen 3 core.
#pragma once
#include <immintrin.h>

namespace physics {
namespace kernels {
inline namespace BINBCSR_ELEMENT_SET {
namespace batch {
namespace avx2 {

// Rows r[0..3] (row e: entry e of 4 lanes) -> r[l]: lane l's entries 0..3.
inline void transpose4(__m256d r[4])
{
  const __m256d t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
  const __m256d t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
  r[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  r[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  r[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  r[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// A write term's block, entries 0..3 in lo and 4..7 in hi (from b): B, or B^T where transpose is 1
// (entries 0 3 6 1 | 4 7 2 5).
inline void term(const double *b, int transpose, __m256d &lo, __m256d &hi)
{
  lo              = _mm256_load_pd(b);
  hi              = _mm256_load_pd(b + 4);
  const __m256d p = _mm256_permute4x64_pd(lo, _MM_SHUFFLE(1, 2, 3, 0)); /* 0 3 2 1 */
  const __m256d q = _mm256_permute4x64_pd(hi, _MM_SHUFFLE(1, 2, 3, 0)); /* 4 7 6 5 */
  const __m256d m = _mm256_castsi256_pd(_mm256_set1_epi64x(-(long long)transpose));
  lo              = _mm256_blendv_pd(lo, _mm256_blend_pd(p, q, 0x4), m);
  hi              = _mm256_blendv_pd(hi, _mm256_blend_pd(q, p, 0x4), m);
}

// COO block s (kFirstContribution: store) += the block with entries 0..7 in lo, hi and entry 8 in b8.
inline void write_block(double *values, int s, __m256d lo, __m256d hi, double b8)
{
  double       *out  = values + 9 * static_cast<std::size_t>(s & kSlotIndexMask);
  const __m256d keep = _mm256_castsi256_pd(_mm256_set1_epi64x((s & kFirstContribution) ? 0 : -1));
  _mm256_storeu_pd(out, _mm256_add_pd(lo, _mm256_and_pd(keep, _mm256_loadu_pd(out))));
  _mm256_storeu_pd(out + 4, _mm256_add_pd(hi, _mm256_and_pd(keep, _mm256_loadu_pd(out + 4))));
  out[8] = (s & kFirstContribution) ? b8 : out[8] + b8;
}

// The same into single-precision values: the sum formed in double, rounded once per write.
inline void write_block(float *values, int s, __m256d lo, __m256d hi, double b8)
{
  float        *out  = values + 9 * static_cast<std::size_t>(s & kSlotIndexMask);
  const __m256d keep = _mm256_castsi256_pd(_mm256_set1_epi64x((s & kFirstContribution) ? 0 : -1));
  _mm_storeu_ps(out,
                _mm256_cvtpd_ps(_mm256_add_pd(lo, _mm256_and_pd(keep, _mm256_cvtps_pd(_mm_loadu_ps(out))))));
  _mm_storeu_ps(
    out + 4, _mm256_cvtpd_ps(_mm256_add_pd(hi, _mm256_and_pd(keep, _mm256_cvtps_pd(_mm_loadu_ps(out + 4))))));
  out[8] = static_cast<float>((s & kFirstContribution) ? b8 : static_cast<double>(out[8]) + b8);
}

} // namespace avx2
} // namespace batch
} // namespace BINBCSR_ELEMENT_SET
} // namespace kernels
} // namespace physics
