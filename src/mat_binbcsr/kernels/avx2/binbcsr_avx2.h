/*
   AVX2 + FMA bodies of the two products of 3x3 blocks at bin widths 4, 8 and 16: a bin's lanes in
   chunks of 4, one ymm register of doubles per block entry and chunk. CPU only: the AVX2 body set
   (binbcsr_avx2.cpp, compiled with -mavx2 -mfma) plugs them into the bin drivers; the portable per-lane
   kernels stay the definition, and the unit tests compare both.

   Why by hand: GCC vectorises the portable loop with a 4-wide gather per component in every group that
   is not exactly unit stride, and AVX2 gathers are slow on some cores (a Zen 3 core ran that body at
   1.1x seqbaij in double and single alike, bound by the gathers, not by the bytes). Where the 4 lanes of a chunk read consecutive block columns but for
   at most two (near_unit_3x4), x_c is 12 consecutive doubles: 3 loads, 2 blends, 1 lane swap and 3
   shuffles split it into its components (split_xyz4) and the odd lanes are patched by broadcast. The
   symmetric product updates y_c the same way (add_xyz4, the split inverted). Elsewhere x_c is read lane
   by lane, one masked load each, and transposed (slow gathers avoided), and y_c updated lane by lane
   (AVX2 has no scatter).

   The helpers live in the body set's inline namespace, as everything the set compiles: another set's
   translation unit gets its own copies, never this one's AVX2 instructions.
*/
#ifndef BINBCSR_AVX2_H
#define BINBCSR_AVX2_H

#include <immintrin.h>

/* Forced inline: out of line, a call per slot group would pass the accumulators through memory. */
#define BINBCSR_AVX2_INLINE inline __attribute__((always_inline))

namespace binbcsr {
inline namespace BINBCSR_BODY_SET {
namespace hand4 {

BINBCSR_AVX2_INLINE __m256d load4(const double *p) { return _mm256_loadu_pd(p); }
BINBCSR_AVX2_INLINE __m256d load4(const float *p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }

/* x, y and z of 4 consecutive nodes (12 interleaved doubles) as one register per component */
BINBCSR_AVX2_INLINE void split_xyz4(const double *xs, __m256d &x0, __m256d &x1, __m256d &x2)
{
  const __m256d a = _mm256_loadu_pd(xs), b = _mm256_loadu_pd(xs + 4), c = _mm256_loadu_pd(xs + 8);
  const __m256d m1 = _mm256_blend_pd(a, b, 0xC);         /* x0 y0 x2 y2 */
  const __m256d m2 = _mm256_blend_pd(b, c, 0xC);         /* y1 z1 y3 z3 */
  const __m256d m3 = _mm256_permute2f128_pd(a, c, 0x21); /* z0 x1 z2 x3 */
  x0               = _mm256_shuffle_pd(m1, m3, 0xA);
  x1               = _mm256_shuffle_pd(m1, m2, 0x5);
  x2               = _mm256_shuffle_pd(m3, m2, 0xA);
}

/* ys[3l + j] += s_j[l]: split_xyz4 inverted */
BINBCSR_AVX2_INLINE void add_xyz4(double *ys, __m256d s0, __m256d s1, __m256d s2)
{
  const __m256d m1 = _mm256_shuffle_pd(s0, s1, 0x0); /* x0 y0 x2 y2 */
  const __m256d m2 = _mm256_shuffle_pd(s1, s2, 0xF); /* y1 z1 y3 z3 */
  const __m256d m3 = _mm256_shuffle_pd(s2, s0, 0xA); /* z0 x1 z2 x3 */
  _mm256_storeu_pd(ys, _mm256_add_pd(_mm256_loadu_pd(ys), _mm256_permute2f128_pd(m1, m3, 0x20)));
  _mm256_storeu_pd(ys + 4, _mm256_add_pd(_mm256_loadu_pd(ys + 4), _mm256_blend_pd(m2, m1, 0xC)));
  _mm256_storeu_pd(ys + 8, _mm256_add_pd(_mm256_loadu_pd(ys + 8), _mm256_permute2f128_pd(m3, m2, 0x31)));
}

/* The 64-bit lanes of the 4-bit lane mask m, all ones or zeros (a blend or and mask). */
BINBCSR_AVX2_INLINE __m256d lanes_of(unsigned m)
{
  const __m256i bit = _mm256_setr_epi64x(1, 2, 4, 8);
  return _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(_mm256_set1_epi64x(m), bit), bit));
}

BINBCSR_AVX2_INLINE unsigned mask_of(__m128i v) { return (unsigned)_mm_movemask_ps(_mm_castsi128_ps(v)); }

/* x_c of the 4 lanes of a chunk, zero outside real, without gathers: each lane's 3 doubles by one
   masked load (the fourth element masked off, so the last column never reads past x; a lane outside
   real loads nothing), then a 4x4 transpose (4 unpacks, 3 lane swaps) into one register per
   component. On a Zen 3 core three 4-wide gathers instead made the products of unstructured FE
   matrices 1.1-1.25x slower. */
template <typename I>
BINBCSR_AVX2_INLINE void load_lanes_xyz4(const I *c, unsigned real, const double *x, __m256d *xc)
{
  const __m256i xyz = _mm256_setr_epi64x(-1, -1, -1, 0), none = _mm256_setzero_si256();
  const __m256d r0 = _mm256_maskload_pd(x + (long)c[0] * 3, real & 1 ? xyz : none);
  const __m256d r1 = _mm256_maskload_pd(x + (long)c[1] * 3, real & 2 ? xyz : none);
  const __m256d r2 = _mm256_maskload_pd(x + (long)c[2] * 3, real & 4 ? xyz : none);
  const __m256d r3 = _mm256_maskload_pd(x + (long)c[3] * 3, real & 8 ? xyz : none);
  const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1); /* x0 x1 z0 z1, y0 y1 0 0 */
  const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
  xc[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  xc[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  xc[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
}

/* y_c[l] += (s0[l], s1[l], s2[l]) for the lanes l in m, one after the other (so right even where two
   lanes share a column): the 4x4 transpose of load_lanes_xyz4 inverted, then per lane one 2-wide and one
   scalar read-modify-write (AVX2 has no scatter). */
template <typename I>
BINBCSR_AVX2_INLINE void scatter_add_xyz4(const I *c, unsigned m, const __m256d *s, double *y)
{
  const __m256d t0      = _mm256_unpacklo_pd(s[0], s[1]),
                t1      = _mm256_unpackhi_pd(s[0], s[1]); /* x0 y0 x2 y2, x1 y1 x3 y3 */
  const __m256d t2      = _mm256_unpacklo_pd(s[2], s[2]),
                t3      = _mm256_unpackhi_pd(s[2], s[2]); /* z0 z0 z2 z2, z1 z1 z3 z3 */
  const __m256d lane[4] = {_mm256_permute2f128_pd(t0, t2, 0x20), _mm256_permute2f128_pd(t1, t3, 0x20),
                           _mm256_permute2f128_pd(t0, t2, 0x31), _mm256_permute2f128_pd(t1, t3, 0x31)};
  for (; m; m &= m - 1) {
    const int l = __builtin_ctz(m);
    double   *p = y + (long)c[l] * 3;
    _mm_storeu_pd(p, _mm_add_pd(_mm_loadu_pd(p), _mm256_castpd256_pd128(lane[l])));
    _mm_store_sd(p + 2, _mm_add_sd(_mm_load_sd(p + 2), _mm256_extractf128_pd(lane[l], 1)));
  }
}

/* Where the real lanes of a chunk read consecutive block columns but for at most two: base, the
   column of lane 0 were the chunk unit-stride (from the first real lane, or the last where the first
   is the odd one), and off, the real lanes that do not follow it. The first or last row of a grid line
   lacks the neighbour on that side, so in a chunk that holds it the row's k-th block is another column
   than its neighbours'. Returns false where more lanes are off or the 4 columns from base leave
   [0, ncols). */
template <typename I>
BINBCSR_AVX2_INLINE bool near_unit_3x4(const I *c, __m128i ci, unsigned real, int ncols, int &base,
                                       unsigned &off)
{
  const __m128i iota = _mm_setr_epi32(0, 1, 2, 3);
  if (!real) return false;
  const int lo = __builtin_ctz(real), hi = 31 - __builtin_clz(real);
  base = (int)c[lo] - lo;
  off  = real & ~mask_of(_mm_cmpeq_epi32(ci, _mm_add_epi32(_mm_set1_epi32(base), iota)));
  if (__builtin_popcount(off) > 2) {
    base = (int)c[hi] - hi;
    off  = real & ~mask_of(_mm_cmpeq_epi32(ci, _mm_add_epi32(_mm_set1_epi32(base), iota)));
    if (__builtin_popcount(off) > 2) return false;
  }
  return base >= 0 && base + 4 <= ncols;
}

/* x_c of a chunk's lanes as one register per component, zero in the lanes outside real: loaded where
   the chunk is near-unit (the odd lanes by broadcast), lane by lane elsewhere (load_lanes_xyz4). Zero, not x: a padding slot's zero value times a
   NaN or Inf of x would be a NaN the row does not have. Returns whether the chunk was near-unit. */
template <typename I>
BINBCSR_AVX2_INLINE bool load_xc_3x4(const I *c, __m128i ci, unsigned real, const double *x, int ncols,
                                     __m256d *xc, int &base, unsigned &off)
{
  /* the common case first: 4 real lanes on consecutive columns (one compare, no lane masks) */
  base = (int)c[0];
  if (real == 0xF &&
      mask_of(_mm_cmpeq_epi32(ci, _mm_add_epi32(_mm_set1_epi32(base), _mm_setr_epi32(0, 1, 2, 3)))) == 0xF &&
      base + 4 <= ncols) {
    off = 0;
    split_xyz4(x + (long)base * 3, xc[0], xc[1], xc[2]);
    return true;
  }
  if (near_unit_3x4(c, ci, real, ncols, base, off)) {
    split_xyz4(x + (long)base * 3, xc[0], xc[1], xc[2]);
    for (unsigned m = off; m; m &= m - 1) {
      const int     l  = __builtin_ctz(m);
      const __m256d lm = lanes_of(1u << l);
      const double *p  = x + (long)c[l] * 3;
      for (int j = 0; j < 3; j++) xc[j] = _mm256_blendv_pd(xc[j], _mm256_broadcast_sd(p + j), lm);
    }
    if (real != 0xF) {
      const __m256d rm = lanes_of(real);
      for (int j = 0; j < 3; j++) xc[j] = _mm256_and_pd(xc[j], rm);
    }
    return true;
  }
  load_lanes_xyz4(c, real, x, xc);
  return false;
}

/* a[i] += block(i, j) x_c(j) over one chunk of a slot group: t at entry 0 of the chunk's lane 0
   (entry e at t + e BW), nz the chunk's lanes' real blocks, k the group. */
template <int BW, typename V, typename I>
BINBCSR_AVX2_INLINE void chunk_mult_3x4(const V *t, const I *c, const double *x, int ncols, __m256d *a, int k,
                                        __m128i nz)
{
  const __m128i  ci   = _mm_loadu_si128((const __m128i *)c);
  const unsigned real = mask_of(_mm_cmpgt_epi32(nz, _mm_set1_epi32(k)));
  if (!real) return; /* padding of a bin's longer rows only */
  __m256d  xc[3];
  int      base;
  unsigned off;
  load_xc_3x4(c, ci, real, x, ncols, xc, base, off);
  for (int i = 0; i < 3; i++)
    a[i] = _mm256_fmadd_pd(load4(t + (3 * i + 2) * BW), xc[2],
                           _mm256_fmadd_pd(load4(t + (3 * i + 1) * BW), xc[1],
                                           _mm256_fmadd_pd(load4(t + 3 * i * BW), xc[0], a[i])));
}

/* bins_sweep's slot groups (binbcsr_bin_drivers.h) for 3x3 blocks, BW lanes (4, 8 or 16): the groups
   of K bins in interleave_groups' order, and acc[q][i][l] += the rows' sums. */
template <int K, int BW, typename V, typename I>
BINBCSR_AVX2_INLINE void bins_mult_3x4(const V *const *bin_val, const I *const *bin_col, const int *len,
                                       const int (*nz)[BW], const double *x, int ncols, double (*acc)[3][BW],
                                       int pf)
{
  constexpr int H = BW / 4;
  static_assert(BW % 4 == 0 && sizeof(I) == 4, "chunks of 4 lanes, 32-bit column indices");
  __m256d a[K][H][3];
  __m128i n[K][H];
  for (int q = 0; q < K; q++)
    for (int h = 0; h < H; h++) {
      n[q][h] = _mm_loadu_si128((const __m128i *)(nz[q] + 4 * h));
      for (int i = 0; i < 3; i++) a[q][h][i] = _mm256_loadu_pd(acc[q][i] + 4 * h);
    }
  interleave_groups<K>(
    len, [&](int q, int k) __attribute__((always_inline)) {
      const V *t = bin_val[q] + (long)k * 9 * BW;
      const I *c = bin_col[q] + (long)k * BW;
      prefetch_values(t, 9 * BW * (int)sizeof(V), pf);
      for (int h = 0; h < H; h++) chunk_mult_3x4<BW>(t + 4 * h, c + 4 * h, x, ncols, a[q][h], k, n[q][h]);
    });
  for (int q = 0; q < K; q++)
    for (int h = 0; h < H; h++)
      for (int i = 0; i < 3; i++) _mm256_storeu_pd(acc[q][i] + 4 * h, a[q][h][i]);
}

/* One chunk of 4 lanes of a symmetric bin, in registers from its first slot group to its last: the
   lanes' accumulators a and x_r. own: each lane's row (mbs - 1 for a phantom lane, the padding's
   column); kd: the slot group of each lane's diagonal block (-1: none). */
struct SymChunk3x4 {
  int     r0, nreal;
  __m128i own, kd;
  __m256d r[3], a[3];
};

BINBCSR_AVX2_INLINE void sym_chunk_begin(SymChunk3x4 &b, int r0, int mbs, const int *kd, const double *x)
{
  b.r0    = r0;
  b.nreal = mbs - r0 < 4 ? (mbs - r0 > 0 ? mbs - r0 : 0) : 4;
  alignas(16) int own[4];
  for (int l = 0; l < 4; l++) own[l] = l < b.nreal ? r0 + l : mbs - 1;
  b.own = _mm_load_si128((const __m128i *)own);
  b.kd  = _mm_loadu_si128((const __m128i *)kd);
  for (int i = 0; i < 3; i++) b.a[i] = _mm256_setzero_pd();
  if (b.nreal == 4) split_xyz4(x + (long)r0 * 3, b.r[0], b.r[1], b.r[2]);
  else {
    alignas(32) double xr[3][4] = {};
    for (int l = 0; l < b.nreal; l++)
      for (int i = 0; i < 3; i++) xr[i][l] = x[(long)(r0 + l) * 3 + i];
    for (int i = 0; i < 3; i++) b.r[i] = _mm256_load_pd(xr[i]);
  }
}

/* Slot group k of the chunk: a += block x_c for its real blocks (the off-diagonal ones and the
   diagonal block), y_c += block^T x_r for the off-diagonal ones. t, c as in chunk_mult_3x4. */
template <int BW, typename V, typename I>
BINBCSR_AVX2_INLINE void sym_chunk_group(SymChunk3x4 &b, const V *t, const I *c, int k, const double *x,
                                         int mbs, double *y)
{
  const __m128i  ci      = _mm_loadu_si128((const __m128i *)c);
  const unsigned scatter = 0xF & ~mask_of(_mm_cmpeq_epi32(ci, b.own)); /* not the diagonal, not padding */
  const unsigned real    = scatter | mask_of(_mm_cmpeq_epi32(b.kd, _mm_set1_epi32(k)));
  if (!real) return; /* padding only */
  __m256d v[9], xc[3], s[3];
  for (int e = 0; e < 9; e++) v[e] = load4(t + e * BW);
  int        base;
  unsigned   off;
  const bool near = load_xc_3x4(c, ci, real, x, mbs, xc, base, off);
  for (int i = 0; i < 3; i++)
    b.a[i] = _mm256_fmadd_pd(v[3 * i + 2], xc[2],
                             _mm256_fmadd_pd(v[3 * i + 1], xc[1], _mm256_fmadd_pd(v[3 * i], xc[0], b.a[i])));
  if (!scatter) return;
  for (int j = 0; j < 3; j++)
    s[j] = _mm256_fmadd_pd(v[6 + j], b.r[2], _mm256_fmadd_pd(v[3 + j], b.r[1], _mm256_mul_pd(v[j], b.r[0])));
  const unsigned keep = near ? scatter & ~off : 0, odd = scatter & ~keep;
  /* the lanes that follow base add into 12 consecutive y (a zero where a lane does not scatter), the
     others one by one after it: a column of both gets both, in turn */
  if (keep == 0xF) add_xyz4(y + (long)base * 3, s[0], s[1], s[2]);
  else if (keep) {
    const __m256d km = lanes_of(keep);
    add_xyz4(y + (long)base * 3, _mm256_and_pd(s[0], km), _mm256_and_pd(s[1], km), _mm256_and_pd(s[2], km));
  }
  if (odd) scatter_add_xyz4(c, odd, s, y);
}

BINBCSR_AVX2_INLINE void sym_chunk_end(const SymChunk3x4 &b, double *y)
{
  if (b.nreal == 4) add_xyz4(y + (long)b.r0 * 3, b.a[0], b.a[1], b.a[2]);
  else {
    alignas(32) double acc[3][4];
    for (int i = 0; i < 3; i++) _mm256_store_pd(acc[i], b.a[i]);
    for (int l = 0; l < b.nreal; l++)
      for (int i = 0; i < 3; i++) y[(long)(b.r0 + l) * 3 + i] += acc[i][l];
  }
}

/* sym_bins_mult (binbcsr_kernels.h) for 3x3 blocks and BW lanes (4, 8 or 16): same semantics, on exit
   y_r += acc for the real lanes of every bin. The chunks of a group run one after the other; their
   lanes' columns are distinct (the colouring), and the lane-by-lane updates would be right even if
   they were not. */
template <int K, int BW, typename V, typename I>
BINBCSR_AVX2_INLINE void sym_bins_mult_3x4(const V *const *bin_val, const I *const *bin_col, const int *len,
                                           const I *r0, I mbs, const int (*kd)[BW], const double *x,
                                           double *y, int pf)
{
  constexpr int H = BW / 4;
  static_assert(BW % 4 == 0 && sizeof(I) == 4, "chunks of 4 lanes, 32-bit column indices");
  SymChunk3x4 b[K][H];
  for (int q = 0; q < K; q++)
    for (int h = 0; h < H; h++) sym_chunk_begin(b[q][h], (int)r0[q] + 4 * h, (int)mbs, kd[q] + 4 * h, x);
  interleave_groups<K>(
    len, [&](int q, int k) __attribute__((always_inline)) {
      const V *t = bin_val[q] + (long)k * 9 * BW;
      const I *c = bin_col[q] + (long)k * BW;
      prefetch_values(t, 9 * BW * (int)sizeof(V), pf);
      for (int h = 0; h < H; h++) sym_chunk_group<BW>(b[q][h], t + 4 * h, c + 4 * h, k, x, (int)mbs, y);
    });
  for (int q = 0; q < K; q++)
    for (int h = 0; h < H; h++) sym_chunk_end(b[q][h], y);
}

} // namespace hand4
} // namespace BINBCSR_BODY_SET
} // namespace binbcsr

#undef BINBCSR_AVX2_INLINE

#endif
