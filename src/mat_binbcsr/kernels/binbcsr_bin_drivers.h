/*
   The CPU drivers of the products: loops over the bins of a BinMatrix that call the per-lane bodies of
   binbcsr_kernels.h, and the table of one body set (bodies<>) that binbcsr_dispatch.cpp picks from.
   Every body set's translation unit includes this header once, after defining BINBCSR_BODY_SET (its
   name, an inline namespace: each set gets its own symbols) and, for the AVX-512 set,
   BINBCSR_HAND_AVX512 (the hand-written 3x3, width 8 group bodies of avx512/binbcsr_avx512.h) or, for
   the AVX2 set, BINBCSR_HAND_AVX2 (3x3 at widths 4, 8 and 16, avx2/binbcsr_avx2.h).
*/
#ifndef BINBCSR_BIN_DRIVERS_H
#define BINBCSR_BIN_DRIVERS_H

#include "binbcsr_dispatch.h"
#include "binbcsr_kernels.h"
#include "binbcsr_layout.h"
#if defined(BINBCSR_HAND_AVX512)
  #include "avx512/binbcsr_avx512.h"
#endif
#if defined(BINBCSR_HAND_AVX2)
  #include "avx2/binbcsr_avx2.h"
#endif
#include <cstddef>
#include <type_traits>

/* The loop over the lanes of a bin is the SIMD loop. GCC 12 does not vectorise it under `omp simd`
   once the lane kernel is inlined (its private arrays stay in memory), but does with ivdep: lanes are
   independent by construction (each writes only its own accumulators). */
#if defined(__clang__)
  #define BINBCSR_LANE_LOOP _Pragma("clang loop vectorize(enable) interleave(enable)")
#elif defined(__GNUC__)
  #define BINBCSR_LANE_LOOP _Pragma("GCC ivdep")
#else
  #define BINBCSR_LANE_LOOP _Pragma("omp simd")
#endif

namespace binbcsr {
inline namespace BINBCSR_BODY_SET {
namespace drivers {

template <typename V> inline const V *values(const BinMatrix &m)
{
  if constexpr (std::is_same<V, float>::value) return m.valf;
  else return m.val;
}

/* The slices of K bins: values, columns and slot groups (len) of bins[q]. */
template <int K, typename V> struct BinSlices {
  const V   *t[K];
  const int *c[K];
  int        len[K];
};

/* nz[q][l]: the real blocks of lane l of bins[q] (0 for a phantom lane), whole storage. */
template <int K, int BW> inline void lane_lengths(const BinMatrix &m, const int *bins, int (*nz)[BW])
{
  for (int q = 0; q < K; q++)
    for (int l = 0; l < BW; l++) nz[q][l] = bins[q] * BW + l < m.mbs ? m.row_nz[bins[q] * BW + l] : 0;
}

/* kd[q][l]: the slot group of the diagonal block of lane l of bins[q] (-1: none), symmetric storage. */
template <int K, int BW> inline void diagonal_groups(const BinMatrix &m, const int *bins, int (*kd)[BW])
{
  for (int q = 0; q < K; q++)
    for (int l = 0; l < BW; l++) {
      const int r = bins[q] * BW + l;
      kd[q][l]    = r < m.mbs && m.diag_slot[r] >= 0 ? (m.diag_slot[r] - m.bin_start[bins[q]]) / BW : -1;
    }
}

template <int K, int BS, int BW, typename V>
inline BinSlices<K, V> bin_slices(const BinMatrix &m, const int *bins)
{
  const V        *val = values<V>(m);
  BinSlices<K, V> s;
  for (int q = 0; q < K; q++) {
    const int s0 = m.bin_start[bins[q]];
    s.t[q]       = val + (size_t)s0 * BS * BS;
    s.c[q]       = m.col + s0;
    s.len[q]     = (m.bin_start[bins[q] + 1] - s0) / BW;
  }
  return s;
}

/* The order of the products' sweeps: the nbins bins cut into K runs of consecutive bins, f(K, bins)
   for bin j of every run together, then f(1, &b) for each of the nbins % K bins left over. K and the
   count passed to f are compile-time constants (std::integral_constant). */
template <int K, class F> inline void for_each_sweep(int nbins, F &&f)
{
  const int run = nbins / K;
  int       bins[K];
  for (int j = 0; j < run; j++) {
    for (int q = 0; q < K; q++) bins[q] = q * run + j;
    f(std::integral_constant<int, K>{}, bins);
  }
  for (int b = K * run; b < nbins; b++) f(std::integral_constant<int, 1>{}, &b);
}

/* acc[i][l] += block row i of lane l times x_c over slot group k (c: the group's BW columns, t: its
   tiles; nz: the lanes' real blocks). BW is the bin width as a constant: the lanes' accumulators stay
   in registers and the loop over the lanes becomes SIMD (column indices and values are unit-stride
   across lanes). x_c of a padding slot reads as zero (a select, no branch): its zero value times a
   NaN or Inf of x would put a NaN into a row that does not have one. */
template <int BS, int BW, typename V>
inline void group_mult(const V *t, const int *c, const double *x, double (*acc)[BW], int k, const int *nz,
                       int pf)
{
  prefetch_values(t, BW * BS * BS * (int)sizeof(V), pf);
  if (unit_stride<BW>(c)) { /* consecutive columns: x_c by plain loads, no gathers */
    const double *xs = x + (size_t)c[0] * BS;
    BINBCSR_LANE_LOOP
    for (int l = 0; l < BW; l++) {
      double yl[BS], xc[BS];
      for (int j = 0; j < BS; j++) xc[j] = k < nz[l] ? xs[l * BS + j] : 0.0;
      for (int i = 0; i < BS; i++) yl[i] = acc[i][l];
      slot_mult<BS, V>(t + l, BW, BS, xc, yl);
      for (int i = 0; i < BS; i++) acc[i][l] = yl[i];
    }
    return;
  }
  BINBCSR_LANE_LOOP
  for (int l = 0; l < BW; l++) {
    const int ci = c[l] * BS; /* 32-bit offsets: vgatherdpd */
    double    xc[BS], yl[BS];
    for (int j = 0; j < BS; j++) xc[j] = k < nz[l] ? x[ci + j] : 0.0;
    for (int i = 0; i < BS; i++) yl[i] = acc[i][l];
    slot_mult<BS, V>(t + l, BW, BS, xc, yl);
    for (int i = 0; i < BS; i++) acc[i][l] = yl[i];
  }
}

/* K bins swept together: the slot groups of bins[0..K-1] in turn, then y of their rows = z + acc, and
   d += x.y over them when want_dot. Why several bins at once: one core streaming one array out of
   memory is limited by the cache lines it has in flight, and the hardware prefetcher keeps more of them
   in flight for several streams than for one (on a Sapphire Rapids core one array read at 9.9-10.5
   GB/s, two at 11.9-12.4 and four at 13.0-14.1 GB/s; docs/mat_binbcsr.md). */
template <int K, int BS, int BW, typename V>
inline void bins_sweep(const BinMatrix &m, const int *bins, const double *x, const double *z, double *y,
                       double &d, bool want_dot)
{
  constexpr int         BS2            = BS * BS;
  double                acc[K][BS][BW] = {};
  const BinSlices<K, V> s              = bin_slices<K, BS, BW, V>(m, bins);
  int                   nz[K][BW];
  lane_lengths<K, BW>(m, bins, nz);
#if defined(BINBCSR_HAND_AVX512)
  if constexpr (BS == 3 && BW == 8) {
    double(*accq[K])[8];
    for (int q = 0; q < K; q++) accq[q] = acc[q];
    unsigned char xload[K];
    for (int q = 0; q < K; q++) xload[q] = m.bin_xload ? m.bin_xload[bins[q]] : XC_NEAR_UNIT;
    avx512::bins_mult_3x8<K>(s.t, s.c, s.len, nz, x, m.nbs, accq, m.prefetch, xload);
  } else
#endif
#if defined(BINBCSR_HAND_AVX2)
    if constexpr (BS == 3 && (BW == 4 || BW == 8 || BW == 16))
    hand4::bins_mult_3x4<K, BW>(s.t, s.c, s.len, nz, x, m.nbs, acc, m.prefetch);
  else
#endif
    interleave_groups<K>(s.len, [&](int q, int k) {
      group_mult<BS, BW, V>(s.t[q] + (size_t)k * BW * BS2, s.c[q] + (size_t)k * BW, x, acc[q], k, nz[q],
                            m.prefetch);
    });
  for (int q = 0; q < K; q++) {
    /* y += A x in place: an empty bin changes nothing (the off-diagonal part of an MPI matrix is
       mostly empty bins; writing their rows back cost a tenth of the diagonal part's product) */
    if (!s.len[q] && z == y && !want_dot) continue;
    const int r0 = bins[q] * BW, nl = m.mbs - r0 < BW ? m.mbs - r0 : BW;
    /* x.y of the bin in registers: summed straight into d, which y might alias for all the compiler
       knows, it was a chain of stores and loads, a third of the fused product's time */
    double dl[BS] = {};
    for (int l = 0; l < nl; l++) {
      for (int i = 0; i < BS; i++) {
        const size_t p  = (size_t)(r0 + l) * BS + i;
        const double yv = (z ? z[p] : 0.0) + acc[q][i][l];
        y[p]            = yv;
        if (want_dot) dl[i] += x[p] * yv; /* not otherwise: x of an off-diagonal part is its ghosts */
      }
    }
    if (want_dot)
      for (int i = 0; i < BS; i++) d += dl[i];
  }
}

/* y[rows of the bins] = z + A x, and *dot = x.y when dot is non-null; the bins in for_each_sweep's
   order (K runs side by side). */
template <int K, int BS, int BW, typename V>
void mult_fixed(const BinMatrix &m, const double *x, const double *z, double *y, double *dot, double *)
{
  double d = 0.0;
  for_each_sweep<K>(m.nbins, [&](auto KC, const int *bins) {
    bins_sweep<decltype(KC)::value, BS, BW, V>(m, bins, x, z, y, d, dot != nullptr);
  });
  if (dot) *dot = d;
}

/* Any bin width and block size: one lane at a time through the lane kernel. */
template <int BS, typename V>
void mult_any(const BinMatrix &m, const double *x, const double *z, double *y, double *dot, double *acc)
{
  const int bs = BS ? BS : m.bs, bs2 = bs * bs, bw = m.bw;
  const V  *val = values<V>(m);
  double    d   = 0.0;
  for (int b = 0; b < m.nbins; b++) {
    const int s0 = m.bin_start[b];
    for (int l = 0; l < bw && b * bw + l < m.mbs; l++) {
      const int r = b * bw + l;
      for (int i = 0; i < bs; i++) acc[i] = z ? z[(size_t)r * bs + i] : 0.0;
      lane_mult<BS, V, int>(val + (size_t)s0 * bs2, m.col + s0, m.row_nz[r], bw, bs, l, x, acc);
      for (int i = 0; i < bs; i++) {
        y[(size_t)r * bs + i] = acc[i];
        if (dot) d += x[(size_t)r * bs + i] * acc[i];
      }
    }
  }
  if (dot) *dot = d;
}

/* x.y over [p0, p1) in four partial sums: one sum is a chain of dependent adds (and through a
   captured reference, of stores and loads), which cost the fused product a third of its time. */
inline double dot_range(const double *x, const double *y, size_t p0, size_t p1)
{
  double s[4] = {};
  size_t p    = p0;
  for (; p + 4 <= p1; p += 4)
    for (int j = 0; j < 4; j++) s[j] += x[p + j] * y[p + j];
  for (; p < p1; p++) s[0] += x[p] * y[p];
  return (s[0] + s[1]) + (s[2] + s[3]);
}

/* Symmetric storage: y += A x with the upper triangle (y holds z or zero on entry), the bins in
   for_each_sweep's order (K runs side by side). *dot = x.y over the rows: with one run, bin by bin
   once its rows are final (no later bin scatters into rows of earlier bins); with several, a bin's rows
   may still receive scatters from the bins of earlier runs, so the dot is a pass of its own at the end
   (x and y, a small fraction of the bytes of the matrix). */
template <int K, int BS, int BW, typename V>
void sym_mult_fixed(const BinMatrix &m, const double *x, const double *, double *y, double *dot, double *)
{
  double d = 0.0;
  for_each_sweep<K>(m.nbins, [&](auto KC, const int *bins) {
    constexpr int          Kc = decltype(KC)::value;
    const BinSlices<Kc, V> s  = bin_slices<Kc, BS, BW, V>(m, bins);
    int                    r0[Kc], kd[Kc][BW];
    for (int q = 0; q < Kc; q++) r0[q] = bins[q] * BW;
    diagonal_groups<Kc, BW>(m, bins, kd);
#if defined(BINBCSR_HAND_AVX512)
    if constexpr (BS == 3 && BW == 8)
      avx512::sym_bins_mult_3x8<Kc>(s.t, s.c, s.len, r0, m.mbs, kd, x, y, m.prefetch);
    else
#endif
#if defined(BINBCSR_HAND_AVX2)
      if constexpr (BS == 3 && (BW == 4 || BW == 8 || BW == 16))
      hand4::sym_bins_mult_3x4<Kc, BW>(s.t, s.c, s.len, r0, m.mbs, kd, x, y, m.prefetch);
    else
#endif
      sym_bins_mult<Kc, BS, BW, V, int>(s.t, s.c, s.len, r0, m.mbs, kd, x, y, m.prefetch);
    if (dot && K == 1)
      d += dot_range(x, y, (size_t)r0[0] * BS, (size_t)(m.mbs < r0[0] + BW ? m.mbs : r0[0] + BW) * BS);
  });
  if (dot && K > 1) d += dot_range(x, y, 0, (size_t)m.mbs * BS);
  if (dot) *dot = d;
}

/* Any bin width or block size: the lanes of a bin one after the other (no conflicts at all). */
template <int BS, typename V>
void sym_mult_any(const BinMatrix &m, const double *x, const double *, double *y, double *dot, double *acc)
{
  const int bs = BS ? BS : m.bs, bs2 = bs * bs, bw = m.bw;
  const V  *val = values<V>(m);
  double    d   = 0.0;
  for (int b = 0; b < m.nbins; b++) {
    const int s0 = m.bin_start[b], len = (m.bin_start[b + 1] - s0) / bw, r0 = b * bw,
              r1 = m.mbs < r0 + bw ? m.mbs : r0 + bw;
    for (int r = r0; r < r1; r++) {
      for (int i = 0; i < bs; i++) acc[i] = 0.0;
      const int kd = m.diag_slot[r] >= 0 ? (m.diag_slot[r] - s0) / bw : -1;
      sym_lane_mult<BS, V, int>(val + (size_t)s0 * bs2, m.col + s0, len, bw, bs, r - r0, r, kd, x,
                                x + (size_t)r * bs, y, acc);
      for (int i = 0; i < bs; i++) y[(size_t)r * bs + i] += acc[i];
    }
    if (dot) d += dot_range(x, y, (size_t)r0 * bs, (size_t)r1 * bs);
  }
  if (dot) *dot = d;
}

/* y += A^T x (y holds z or zero on entry). Scatter: rows are visited lane by lane. */
template <int BS, typename V> void mult_transpose_any(const BinMatrix &m, const double *x, double *y)
{
  const int bs = BS ? BS : m.bs, bs2 = bs * bs, bw = m.bw;
  const V  *val = values<V>(m);
  for (int b = 0; b < m.nbins; b++) {
    const int s0 = m.bin_start[b];
    for (int l = 0; l < bw && b * bw + l < m.mbs; l++) {
      const int r = b * bw + l;
      lane_mult_transpose<BS, V, int>(val + (size_t)s0 * bs2, m.col + s0, m.row_nz[r], bw, bs, l,
                                      x + (size_t)r * bs, y);
    }
  }
}

/* Calls f(block size, bin width) with each as a compile-time constant where a specialised sweep exists
   (bs 1 and 3; bin widths 4, 8, 16, 32) and 0 where the generic sweep must take it from the matrix. */
template <class F> inline void with_constant_shape(int bs, int bw, F &&f)
{
  using std::integral_constant;
  const auto width = [&](auto BS) {
    switch (bw) {
    case 4:
      f(BS, integral_constant<int, 4>{});
      break;
    case 8:
      f(BS, integral_constant<int, 8>{});
      break;
    case 16:
      f(BS, integral_constant<int, 16>{});
      break;
    case 32:
      f(BS, integral_constant<int, 32>{});
      break;
    default:
      f(BS, integral_constant<int, 0>{});
    }
  };
  if (bs == 3) width(integral_constant<int, 3>{});
  else if (bs == 1) width(integral_constant<int, 1>{});
  else f(integral_constant<int, 0>{}, integral_constant<int, 0>{});
}

/* Calls f(K) with the run count K (1, 2, 4 or 8) as a compile-time constant. */
template <class F> inline void with_streams(int streams, F &&f)
{
  using std::integral_constant;
  switch (streams) {
  case 8:
    f(integral_constant<int, 8>{});
    break;
  case 4:
    f(integral_constant<int, 4>{});
    break;
  case 2:
    f(integral_constant<int, 2>{});
    break;
  default:
    f(integral_constant<int, 1>{});
  }
}

template <typename V> inline bool bodies_of(const Shape &s, Body &b, bool fixed_only)
{
  bool found = false;
  with_constant_shape(s.bs, s.bw, [&](auto BS, auto BW) {
    constexpr int bs_c = decltype(BS)::value, bw_c = decltype(BW)::value;
    b.mult_transpose = &mult_transpose_any<bs_c, V>;
    if constexpr (bs_c > 0 && bw_c > 0) {
      with_streams(s.streams, [&](auto K) {
        constexpr int k_c = decltype(K)::value;
        b.mult            = s.sym ? &sym_mult_fixed<k_c, bs_c, bw_c, V> : &mult_fixed<k_c, bs_c, bw_c, V>;
      });
      found = true;
    } else if (!fixed_only) {
      b.mult = s.sym ? &sym_mult_any<bs_c, V> : &mult_any<bs_c, V>;
      found  = true;
    }
  });
  return found;
}

/* The table of this body set: the fixed shapes always, the generic ones (any bs, any bin width) when
   !fixed_only (the portable set; the others fall back to it there). */
inline bool bodies(const Shape &s, Body &b, bool fixed_only)
{
  return s.single ? bodies_of<float>(s, b, fixed_only) : bodies_of<double>(s, b, fixed_only);
}

/* The table function of a SIMD body set: its fixed shapes, or none when the compiler could not target
   it (`targeted` false: the translation unit is a stub and the dispatch never offers the set). */
inline bool simd_bodies(const Shape &s, Body &b, BodySet set, bool targeted)
{
  b.set = set;
  return targeted && bodies(s, b, true);
}

} // namespace drivers
} // namespace BINBCSR_BODY_SET
} // namespace binbcsr

#endif
