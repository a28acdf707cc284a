/*
   AVX-512 bodies of the two products of 3x3 blocks at bin width 8 (one zmm register of doubles per
   block entry), the shape of the cloth, the stencils and the FE scenes: whole bins of the whole-storage
   product (bins_mult_3x8) and of the symmetric one (sym_bins_mult_3x8). CPU only: the AVX-512 body set
   (binbcsr_avx512.cpp, compiled with AVX-512 flags) plugs them into the bin drivers; the portable
   per-lane kernels stay the definition (and the CUDA path), and the unit tests compare both.

   Why by hand: where the 8 lanes read consecutive block columns, x_c is 24 consecutive doubles (x, y, z
   of 8 nodes), and so is the y_c that the transposed blocks update. GCC vectorises the portable loop with
   256-bit halves, spills the accumulators and (de)interleaves through many shuffles. Here 3 loads and
   6 two-source permutes split x into its components (split_xyz), 9 FMAs serve the lanes' rows and 9 the
   transposed blocks, and 6 permutes interleave the result back (add_xyz). The accumulators stay in
   registers for the whole bin.
*/
#ifndef BINBCSR_AVX512_H
#define BINBCSR_AVX512_H

#include <immintrin.h>

/* Every helper below is forced inline: GCC 12 kept the group bodies out of line (a call per slot
   group, the bin's accumulators and x_r passed through memory), which is what these bodies are
   written to avoid. */
#define BINBCSR_AVX512_INLINE inline __attribute__((always_inline))

namespace binbcsr {
namespace avx512 {

BINBCSR_AVX512_INLINE __m512d load8(const double *p) { return _mm512_loadu_pd(p); }
BINBCSR_AVX512_INLINE __m512d load8(const float *p) { return _mm512_cvtps_pd(_mm256_loadu_ps(p)); }

/* x, y and z of 8 consecutive nodes (24 interleaved doubles) as one register per component */
BINBCSR_AVX512_INLINE void split_xyz(const double *xs, __m512d &x0, __m512d &x1, __m512d &x2)
{
  const __m512d a = _mm512_loadu_pd(xs), b = _mm512_loadu_pd(xs + 8), c = _mm512_loadu_pd(xs + 16);
  x0 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), b),
                              _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13), c);
  x1 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), b),
                              _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14), c);
  x2 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), b),
                              _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15), c);
}

/* ys[3l + j] += s_j[l]: one register per component back to 24 interleaved doubles (split_xyz inverted) */
BINBCSR_AVX512_INLINE void add_xyz(double *ys, __m512d s0, __m512d s1, __m512d s2)
{
  const __m512d lo =
    _mm512_permutex2var_pd(_mm512_permutex2var_pd(s0, _mm512_setr_epi64(0, 8, 0, 1, 9, 0, 2, 10), s1),
                           _mm512_setr_epi64(0, 1, 8, 3, 4, 9, 6, 7), s2);
  const __m512d mi =
    _mm512_permutex2var_pd(_mm512_permutex2var_pd(s0, _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5), s1),
                           _mm512_setr_epi64(10, 1, 2, 11, 4, 5, 12, 7), s2);
  const __m512d hi =
    _mm512_permutex2var_pd(_mm512_permutex2var_pd(s0, _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0), s1),
                           _mm512_setr_epi64(0, 13, 2, 3, 14, 5, 6, 15), s2);
  _mm512_storeu_pd(ys, _mm512_add_pd(_mm512_loadu_pd(ys), lo));
  _mm512_storeu_pd(ys + 8, _mm512_add_pd(_mm512_loadu_pd(ys + 8), mi));
  _mm512_storeu_pd(ys + 16, _mm512_add_pd(_mm512_loadu_pd(ys + 16), hi));
}

/* Where the real lanes of a slot group read consecutive block columns but for at most two: the
   first or last row of a grid line lacks the neighbour on that side, so in a bin that holds it the
   row's k-th block is another column than its neighbours' in every group. Those groups would go lane
   by lane (a third of the 48^3 stencil's groups at width 8; a Zen 4 core ran them, gathered then, at
   half the speed of the loaded ones). Instead: base, the column of lane 0 were the group unit-stride
   (from the first real lane, or the last where the first is the odd one), and off, the real lanes
   that do not follow it. Returns false where more lanes are off or the 8 columns from base leave
   [0, ncols). */
template <typename I>
BINBCSR_AVX512_INLINE bool near_unit_3x8(const I *c, __m256i ci, __mmask8 real, int ncols, int &base,
                                         __mmask8 &off)
{
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  /* the common case first, one compare: 8 real lanes on consecutive columns (the lane counts and
     branches below cost the cloth's in-cache product a quarter of its time) */
  if (real == 0xFF) {
    base = (int)c[0];
    off  = (__mmask8)~_mm256_cmpeq_epi32_mask(ci, _mm256_add_epi32(_mm256_set1_epi32(base), iota));
    if (!off && base + 8 <= ncols) return true;
  }
  if (!real) return false;
  const int lo = __builtin_ctz(real), hi = 31 - __builtin_clz(real);
  base = (int)c[lo] - lo;
  off  = real & ~_mm256_cmpeq_epi32_mask(ci, _mm256_add_epi32(_mm256_set1_epi32(base), iota));
  if (__builtin_popcount(off) > 2) {
    base = (int)c[hi] - hi;
    off  = real & ~_mm256_cmpeq_epi32_mask(ci, _mm256_add_epi32(_mm256_set1_epi32(base), iota));
    if (__builtin_popcount(off) > 2) return false;
  }
  return base >= 0 && base + 8 <= ncols;
}

/* x_c of the lanes in off, one broadcast per component: the near-unit groups' odd lanes. */
template <typename I>
BINBCSR_AVX512_INLINE void patch_xyz(const I *c, const double *x, __mmask8 off, __m512d &x0, __m512d &x1,
                                     __m512d &x2)
{
  for (unsigned m = off; m; m &= m - 1) {
    const int      l = __builtin_ctz(m);
    const __mmask8 b = (__mmask8)(1u << l);
    const double  *p = x + (long)c[l] * 3;
    x0               = _mm512_mask_broadcastsd_pd(x0, b, _mm_load_sd(p));
    x1               = _mm512_mask_broadcastsd_pd(x1, b, _mm_load_sd(p + 1));
    x2               = _mm512_mask_broadcastsd_pd(x2, b, _mm_load_sd(p + 2));
  }
}

/* The two-source permutes of the 8x4 transpose (lanes_xyz_3x8) and of its inverse (lanes_add_xyz_3x8):
   the 128-bit pairs 0 and 2 of each 256-bit half of a and b, or pairs 1 and 3. */
BINBCSR_AVX512_INLINE __m512i pairs_even() { return _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13); }
BINBCSR_AVX512_INLINE __m512i pairs_odd() { return _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15); }

/* x, y and z of lane l (not the fourth element) where lane l is in m, nothing elsewhere */
BINBCSR_AVX512_INLINE __mmask8 xyz_mask(__mmask8 m, int l) { return (__mmask8)(-(int)(m >> l & 1u) & 7); }

/* x_c of a slot group's real lanes, lane by lane: one masked load of x, y and z per lane (the fourth
   element masked off, so the last column never reads past x; a lane outside real loads nothing and
   reads as zero), then an 8x4 transpose (4 inserts, 4 unpacks, 3 two-source permutes) into one
   register per component. Why not a gather: a zmm gather of 8 doubles runs slowly on Zen 4 and Zen 5;
   with single-precision values in cache (an FE operator's size, random columns) three gathers took 1.8x
   the time of these loads and the transpose (docs/mat_binbcsr.md, lane by lane). */
template <typename I>
BINBCSR_AVX512_INLINE void lanes_xyz_3x8(const I *c, __mmask8 real, const double *x, __m512d &x0, __m512d &x1,
                                         __m512d &x2)
{
  const auto lane = [&](int l) __attribute__((always_inline))
  {
    return _mm256_maskz_loadu_pd(xyz_mask(real, l), x + (long)c[l] * 3);
  };
  const auto pair = [&](int l) __attribute__((always_inline))
  {
    return _mm512_insertf64x4(_mm512_castpd256_pd512(lane(l)), lane(l + 4), 1);
  };
  const __m512d a04 = pair(0), a15 = pair(1), a26 = pair(2), a37 = pair(3);
  /* [x0 x1 z0 z1 | x4 x5 z4 z5], [y0 y1 - - | y4 y5 - -] and the same for lanes 2, 3, 6, 7 */
  const __m512d lo01 = _mm512_unpacklo_pd(a04, a15), hi01 = _mm512_unpackhi_pd(a04, a15);
  const __m512d lo23 = _mm512_unpacklo_pd(a26, a37), hi23 = _mm512_unpackhi_pd(a26, a37);
  x0 = _mm512_permutex2var_pd(lo01, pairs_even(), lo23);
  x1 = _mm512_permutex2var_pd(hi01, pairs_even(), hi23);
  x2 = _mm512_permutex2var_pd(lo01, pairs_odd(), lo23);
}

/* y_c[lane l] += (s0, s1, s2)[l] for the lanes in m (lanes_xyz_3x8 inverted; the lanes' columns differ,
   so the read-add-writes do not overlap): the symmetric product's transposed blocks where a slot
   group's columns are not consecutive. A lane outside m reads and writes nothing. */
template <typename I>
BINBCSR_AVX512_INLINE void lanes_add_xyz_3x8(const I *c, __mmask8 m, double *y, __m512d s0, __m512d s1,
                                             __m512d s2)
{
  const __m512d lo01 = _mm512_permutex2var_pd(s0, pairs_even(), s2);
  const __m512d lo23 = _mm512_permutex2var_pd(s0, pairs_odd(), s2);
  const __m512d hi23 = _mm512_permutex_pd(s1, 0xEE);
  /* lane l's (s0, s1, s2, -) in the low half of a[l % 4] for l < 4, the high half for l >= 4 */
  const __m512d a[4] = {_mm512_unpacklo_pd(lo01, s1), _mm512_unpackhi_pd(lo01, s1),
                        _mm512_unpacklo_pd(lo23, hi23), _mm512_unpackhi_pd(lo23, hi23)};
  for (int l = 0; l < 8; l++) {
    const __mmask8 k = xyz_mask(m, l);
    double        *p = y + (long)c[l] * 3;
    const __m256d  v = l < 4 ? _mm512_castpd512_pd256(a[l]) : _mm512_extractf64x4_pd(a[l - 4], 1);
    _mm256_mask_storeu_pd(p, k, _mm256_add_pd(_mm256_maskz_loadu_pd(k, p), v));
  }
}

/* x_c of a slot group's lanes as one register per component, zero in the lanes outside real (zero, not
   x: a padding slot's zero value times a NaN or Inf of x would be a NaN the row does not have); mode:
   the bin's XC_* (binbcsr_layout.h). A masked gather reads nothing for the lanes outside real. */
template <typename I>
BINBCSR_AVX512_INLINE void load_xc_3x8(const I *c, __m256i ci, __mmask8 real, const double *x, int ncols,
                                       __m512d &x0, __m512d &x1, __m512d &x2, unsigned char mode)
{
  int      base;
  __mmask8 off;
  if (mode == XC_NEAR_UNIT && near_unit_3x8(c, ci, real, ncols, base, off)) {
    split_xyz(x + (long)base * 3, x0, x1, x2);
    if (off) patch_xyz(c, x, off, x0, x1, x2);
    x0 = _mm512_maskz_mov_pd(real, x0);
    x1 = _mm512_maskz_mov_pd(real, x1);
    x2 = _mm512_maskz_mov_pd(real, x2);
  } else if (mode != XC_GATHER) lanes_xyz_3x8(c, real, x, x0, x1, x2);
  else {
    const __m256i o = _mm256_add_epi32(ci, _mm256_add_epi32(ci, ci)); /* 3 c */
    x0              = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, o, x, 8);
    x1              = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, o, x + 1, 8);
    x2              = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, o, x + 2, 8);
  }
}

/* One slot group of the whole-storage product (3x3 blocks, 8 lanes): a[i] (lane l in element l) +=
   block(i, j) x_c(j), x_c by load_xc_3x8. real: the lanes whose slot is a real block. ncols: block
   columns of x. */
template <typename V, typename I>
BINBCSR_AVX512_INLINE void group_mult_3x8(const V *t, const I *c, const double *x, int ncols, __m512d *a,
                                          __mmask8 real, int pf, unsigned char mode)
{
  static_assert(sizeof(I) == 4, "32-bit column indices");
  prefetch_values(t, 72 * (int)sizeof(V), pf);
  const __m256i ci = _mm256_loadu_si256((const __m256i *)c);
  __m512d       x0, x1, x2;
  load_xc_3x8(c, ci, real, x, ncols, x0, x1, x2, mode);
  a[0] = _mm512_fmadd_pd(load8(t + 16), x2,
                         _mm512_fmadd_pd(load8(t + 8), x1, _mm512_fmadd_pd(load8(t), x0, a[0])));
  a[1] = _mm512_fmadd_pd(load8(t + 40), x2,
                         _mm512_fmadd_pd(load8(t + 32), x1, _mm512_fmadd_pd(load8(t + 24), x0, a[1])));
  a[2] = _mm512_fmadd_pd(load8(t + 64), x2,
                         _mm512_fmadd_pd(load8(t + 56), x1, _mm512_fmadd_pd(load8(t + 48), x0, a[2])));
}

/* The whole-storage product of K bins swept together (3x3 blocks, 8 lanes): acc[q][i] (lane l in
   element l) += block row i of bin q times x over its len[q] slot groups, the groups of the K bins taken
   in turn; the accumulators stay in registers for the whole sweep. K bins far apart in memory are K
   streams for the hardware prefetcher (bins_sweep in binbcsr_bin_drivers.h says why). */
template <int K, typename V, typename I>
BINBCSR_AVX512_INLINE void bins_mult_3x8(const V *const *bin_val, const I *const *bin_col, const int *len,
                                         const int (*nz)[8], const double *x, int ncols,
                                         double (*const *acc)[8], int pf, const unsigned char *xload)
{
  __m512d a[K][3];
  __m256i n[K]; /* the lanes' real blocks: slot group k of lane l is real when k < n[l] */
  for (int q = 0; q < K; q++) {
    n[q] = _mm256_loadu_si256((const __m256i *)nz[q]);
    for (int i = 0; i < 3; i++) a[q][i] = _mm512_loadu_pd(acc[q][i]);
  }
  /* interleave_groups' order written out: GCC 12 kept its lambda out of line here, a call per slot
     group with the accumulators in memory */
  int common = len[0];
  for (int q = 1; q < K; q++) common = len[q] < common ? len[q] : common;
  const auto group = [&](int q, int k) __attribute__((always_inline))
  {
    group_mult_3x8(bin_val[q] + (long)k * 72, bin_col[q] + (long)k * 8, x, ncols, a[q],
                   _mm256_cmpgt_epi32_mask(n[q], _mm256_set1_epi32(k)), pf, xload[q]);
  };
  for (int k = 0; k < common; k++)
    for (int q = 0; q < K; q++) group(q, k);
  for (int q = 0; q < K; q++)
    for (int k = common; k < len[q]; k++) group(q, k);
  for (int q = 0; q < K; q++)
    for (int i = 0; i < 3; i++) _mm512_storeu_pd(acc[q][i], a[q][i]);
}

/* sym_bins_mult (binbcsr_kernels.h) for 3x3 blocks and 8 lanes, each bin in registers: the lanes'
   accumulators and x_r stay in zmm registers from the first slot group to the last (a per-group body
   kept them in memory, a store and a reload per group on the critical path: the cloth's product took
   1.02 ms instead of 0.84, docs/mat_binbcsr.md). Consecutive-column groups load x and update y
   contiguously; the others read x and add into y lane by lane (lanes_xyz_3x8, lanes_add_xyz_3x8) for
   the lanes whose column is not their own row (conflict-free within a group: the colouring). Same
   semantics as the portable sym_bins_mult: on exit y_r += acc for the real lanes of every bin. */
template <typename V, typename I> struct SymBin3x8 {
  const V *t;
  const I *c;
  I        r0;
  int      nreal, k; /* k: the next slot group */
  __m256i  own, kd;  /* kd: the slot group of each lane's diagonal block (-1: none) */
  __m512d  r[3], a[3];
};

template <typename V, typename I>
BINBCSR_AVX512_INLINE void sym_bin_begin_3x8(SymBin3x8<V, I> &b, const V *bin_val, const I *bin_col, I r0,
                                             I mbs, const int *kd, const double *x)
{
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  b.t                = bin_val;
  b.c                = bin_col;
  b.r0               = r0;
  b.k                = 0;
  b.kd               = _mm256_loadu_si256((const __m256i *)kd);
  b.nreal            = mbs - r0 < 8 ? (int)(mbs - r0) : 8;
  b.own = _mm256_mask_blend_epi32((__mmask8)((1u << b.nreal) - 1), _mm256_set1_epi32((int)mbs - 1),
                                  _mm256_add_epi32(_mm256_set1_epi32((int)r0), iota));
  for (int i = 0; i < 3; i++) b.a[i] = _mm512_setzero_pd();
  if (b.nreal == 8) split_xyz(x + (long)r0 * 3, b.r[0], b.r[1], b.r[2]);
  else {
    alignas(64) double xr[3][8] = {};
    for (int l = 0; l < b.nreal; l++)
      for (int i = 0; i < 3; i++) xr[i][l] = x[(long)(r0 + l) * 3 + i];
    for (int i = 0; i < 3; i++) b.r[i] = _mm512_load_pd(xr[i]);
  }
}

template <typename V, typename I>
BINBCSR_AVX512_INLINE void sym_bin_group_3x8(SymBin3x8<V, I> &b, const double *x, I mbs, double *y, int pf)
{
  static_assert(sizeof(I) == 4, "32-bit column indices");
  const V *t = b.t;
  const I *c = b.c;
  b.t += 72;
  b.c += 8;
  prefetch_values(t, 72 * (int)sizeof(V), pf);
  const __m256i ci = _mm256_loadu_si256((const __m256i *)c);
  __m512d       v[9], xc[3], s[3];
  for (int e = 0; e < 9; e++) v[e] = load8(t + e * 8);
  const __mmask8 scatter = _mm256_cmpneq_epi32_mask(ci, b.own); /* not the diagonal block, not padding */
  /* real blocks: the off-diagonal ones and the diagonal block; padding's x_c reads as zero (zero times a
     NaN or Inf of x_own would be a NaN the row does not have) */
  const __mmask8 real = scatter | _mm256_cmpeq_epi32_mask(b.kd, _mm256_set1_epi32(b.k++));
  int            base;
  __mmask8       off;
  const bool     near = near_unit_3x8(c, ci, real, (int)mbs, base, off);
  if (near) {
    split_xyz(x + (long)base * 3, xc[0], xc[1], xc[2]);
    if (off) patch_xyz(c, x, off, xc[0], xc[1], xc[2]);
    for (int j = 0; j < 3; j++) xc[j] = _mm512_maskz_mov_pd(real, xc[j]);
  } else lanes_xyz_3x8(c, real, x, xc[0], xc[1], xc[2]);
  for (int i = 0; i < 3; i++)
    b.a[i] = _mm512_fmadd_pd(v[3 * i + 2], xc[2],
                             _mm512_fmadd_pd(v[3 * i + 1], xc[1], _mm512_fmadd_pd(v[3 * i], xc[0], b.a[i])));
  if (!scatter) return;
  for (int j = 0; j < 3; j++)
    s[j] = _mm512_fmadd_pd(v[6 + j], b.r[2], _mm512_fmadd_pd(v[3 + j], b.r[1], _mm512_mul_pd(v[j], b.r[0])));
  if (near) {
    /* the lanes that follow base add into 24 consecutive y (a zero where a lane does not scatter),
       the odd ones one by one after it: a column of both gets both, in turn */
    const __mmask8 odd = off & scatter, keep = scatter & ~off;
    if (odd) {
      alignas(64) double sl[3][8];
      for (int j = 0; j < 3; j++) _mm512_store_pd(sl[j], s[j]);
      add_xyz(y + (long)base * 3, _mm512_maskz_mov_pd(keep, s[0]), _mm512_maskz_mov_pd(keep, s[1]),
              _mm512_maskz_mov_pd(keep, s[2]));
      for (unsigned m = odd; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        for (int j = 0; j < 3; j++) y[(long)c[l] * 3 + j] += sl[j][l];
      }
    } else if (keep == 0xFF) add_xyz(y + (long)base * 3, s[0], s[1], s[2]);
    else
      add_xyz(y + (long)base * 3, _mm512_maskz_mov_pd(keep, s[0]), _mm512_maskz_mov_pd(keep, s[1]),
              _mm512_maskz_mov_pd(keep, s[2]));
  } else lanes_add_xyz_3x8(c, scatter, y, s[0], s[1], s[2]);
}

template <typename V, typename I>
BINBCSR_AVX512_INLINE void sym_bin_end_3x8(const SymBin3x8<V, I> &b, double *y)
{
  if (b.nreal == 8) add_xyz(y + (long)b.r0 * 3, b.a[0], b.a[1], b.a[2]);
  else {
    alignas(64) double acc[3][8];
    for (int i = 0; i < 3; i++) _mm512_store_pd(acc[i], b.a[i]);
    for (int l = 0; l < b.nreal; l++)
      for (int i = 0; i < 3; i++) y[(long)(b.r0 + l) * 3 + i] += acc[i][l];
  }
}

template <int K, typename V, typename I>
BINBCSR_AVX512_INLINE void sym_bins_mult_3x8(const V *const *bin_val, const I *const *bin_col, const int *len,
                                             const I *r0, I mbs, const int (*kd)[8], const double *x,
                                             double *y, int pf)
{
  /* interleave_groups' order written out: through its lambda this body ran slower (upper double at
     48^3, three alternations: 7.0-7.6 ms against 6.5-6.9) */
  SymBin3x8<V, I> b[K];
  int             common = len[0];
  for (int q = 0; q < K; q++) {
    sym_bin_begin_3x8(b[q], bin_val[q], bin_col[q], r0[q], mbs, kd[q], x);
    common = len[q] < common ? len[q] : common;
  }
  for (int k = 0; k < common; k++)
    for (int q = 0; q < K; q++) sym_bin_group_3x8(b[q], x, mbs, y, pf);
  for (int q = 0; q < K; q++)
    for (int k = common; k < len[q]; k++) sym_bin_group_3x8(b[q], x, mbs, y, pf);
  for (int q = 0; q < K; q++) sym_bin_end_3x8(b[q], y);
}

} // namespace avx512
} // namespace binbcsr

#undef BINBCSR_AVX512_INLINE

#endif
