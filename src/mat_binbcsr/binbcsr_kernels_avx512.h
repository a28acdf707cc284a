/*
   AVX-512 body of one slot group of the symmetric product over consecutive block columns, for the
   shape the cloth and the stencils use (3x3 blocks, bin width 8 = one zmm register of doubles). CPU
   only: binbcsr_kernels.h includes it when the compiler targets AVX-512 and calls it from
   sym_unit_group_mult, whose portable loop stays the definition (and the CUDA path).

   Why by hand: x_c of the 8 lanes are 24 consecutive doubles (x, y, z of 8 nodes) and so are the y_c
   updated by the transposed blocks. GCC vectorises the portable loop with 256-bit halves, spills the
   accumulators and (de)interleaves through many shuffles, so the group stayed compute-bound (the
   single-storage product took as long as the double one). Here: 3 loads and 6 two-source permutes
   split x into its components, 9 FMAs for the lanes' rows, 9 for the transposed blocks, 6 permutes
   interleave the result back for 3 loads, adds and stores of y.
*/
#ifndef BINBCSR_KERNELS_AVX512_H
#define BINBCSR_KERNELS_AVX512_H

#include <immintrin.h>

namespace binbcsr
{
namespace avx512
{

inline __m512d load8(const double *p) { return _mm512_loadu_pd(p); }
inline __m512d load8(const float *p) { return _mm512_cvtps_pd(_mm256_loadu_ps(p)); }

/* x, y and z of 8 consecutive nodes (24 interleaved doubles) as one register per component */
inline void split_xyz(const double *xs, __m512d &x0, __m512d &x1, __m512d &x2)
{
  const __m512d a = _mm512_loadu_pd(xs), b = _mm512_loadu_pd(xs + 8), c = _mm512_loadu_pd(xs + 16);
  x0 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), b), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13), c);
  x1 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), b), _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14), c);
  x2 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), b), _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15), c);
}

/* The whole-storage product of one bin (3x3 blocks, 8 lanes): acc[i] (lane l in element l) +=
   sum over the bin's len slot groups of block(i, j) x_c(j), the accumulators in registers for the
   whole bin. Consecutive-column groups load x (split_xyz); the others gather it with 32-bit offsets. */
template <typename V, typename I>
inline void bin_mult_3x8(const V *t, const I *c, int len, const double *x, double (*acc)[8])
{
  static_assert(sizeof(I) == 4, "32-bit column indices");
  __m512d       a0 = _mm512_loadu_pd(acc[0]), a1 = _mm512_loadu_pd(acc[1]), a2 = _mm512_loadu_pd(acc[2]);
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (int k = 0; k < len; k++, c += 8, t += 72) {
    prefetch_values(t, 72 * (int)sizeof(V));
    const __m256i ci = _mm256_loadu_si256((const __m256i *)c);
    __m512d       x0, x1, x2;
    /* unit_stride<8>(c) as one vector compare: the indices are in a register already */
    if (_mm256_cmpeq_epi32_mask(ci, _mm256_add_epi32(_mm256_set1_epi32((int)c[0]), iota)) == 0xFF) split_xyz(x + (long)c[0] * 3, x0, x1, x2);
    else {
      const __m256i off = _mm256_add_epi32(ci, _mm256_add_epi32(ci, ci)); /* 3 c */
      x0                = _mm512_i32gather_pd(off, x, 8);
      x1                = _mm512_i32gather_pd(off, x + 1, 8);
      x2                = _mm512_i32gather_pd(off, x + 2, 8);
    }
    a0 = _mm512_fmadd_pd(load8(t + 16), x2, _mm512_fmadd_pd(load8(t + 8), x1, _mm512_fmadd_pd(load8(t), x0, a0)));
    a1 = _mm512_fmadd_pd(load8(t + 40), x2, _mm512_fmadd_pd(load8(t + 32), x1, _mm512_fmadd_pd(load8(t + 24), x0, a1)));
    a2 = _mm512_fmadd_pd(load8(t + 64), x2, _mm512_fmadd_pd(load8(t + 56), x1, _mm512_fmadd_pd(load8(t + 48), x0, a2)));
  }
  _mm512_storeu_pd(acc[0], a0);
  _mm512_storeu_pd(acc[1], a1);
  _mm512_storeu_pd(acc[2], a2);
}

/* acc[i][l] += sum_j block_l(i,j) x[(c0 + l) * 3 + j]; with SCATTER also
   y[(c0 + l) * 3 + j] += sum_i block_l(i,j) xr[i][l]. t: the group's tile (entry e of lane l at t[e * 8 + l]). */
template <bool SCATTER, typename V>
inline void sym_unit_group_3x8(const V *t, const double *xs, const double (*xr)[8], double *ys, double (*acc)[8])
{
  __m512d x0, x1, x2;
  split_xyz(xs, x0, x1, x2);
  __m512d v[9];
  for (int e = 0; e < 9; e++) v[e] = load8(t + e * 8);
  for (int i = 0; i < 3; i++) {
    __m512d s = _mm512_loadu_pd(acc[i]);
    s         = _mm512_fmadd_pd(v[3 * i + 0], x0, s);
    s         = _mm512_fmadd_pd(v[3 * i + 1], x1, s);
    s         = _mm512_fmadd_pd(v[3 * i + 2], x2, s);
    _mm512_storeu_pd(acc[i], s);
  }
  if (!SCATTER) return;
  const __m512d r0 = _mm512_loadu_pd(xr[0]), r1 = _mm512_loadu_pd(xr[1]), r2 = _mm512_loadu_pd(xr[2]);
  __m512d       s[3];
  for (int j = 0; j < 3; j++) s[j] = _mm512_fmadd_pd(v[6 + j], r2, _mm512_fmadd_pd(v[3 + j], r1, _mm512_mul_pd(v[j], r0)));
  /* back to 24 interleaved doubles: (s0[l], s1[l], s2[l]) at 3l .. 3l + 2 */
  const __m512d lo = _mm512_permutex2var_pd(_mm512_permutex2var_pd(s[0], _mm512_setr_epi64(0, 8, 0, 1, 9, 0, 2, 10), s[1]), _mm512_setr_epi64(0, 1, 8, 3, 4, 9, 6, 7), s[2]);
  const __m512d mi = _mm512_permutex2var_pd(_mm512_permutex2var_pd(s[0], _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5), s[1]), _mm512_setr_epi64(10, 1, 2, 11, 4, 5, 12, 7), s[2]);
  const __m512d hi = _mm512_permutex2var_pd(_mm512_permutex2var_pd(s[0], _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0), s[1]), _mm512_setr_epi64(0, 13, 2, 3, 14, 5, 6, 15), s[2]);
  _mm512_storeu_pd(ys, _mm512_add_pd(_mm512_loadu_pd(ys), lo));
  _mm512_storeu_pd(ys + 8, _mm512_add_pd(_mm512_loadu_pd(ys + 8), mi));
  _mm512_storeu_pd(ys + 16, _mm512_add_pd(_mm512_loadu_pd(ys + 16), hi));
}

} // namespace avx512
} // namespace binbcsr

#endif
