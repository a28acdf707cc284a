/*
   Value kernels of the BIN-(B)CSR format over ONE lane of a bin (one block row): scaling, AXPY,
   zeroing rows and columns, and the sums that norms need. Same conventions as binbcsr_kernels.h
   (plain inline functions, no STL, no PETSc, no allocation; callable from a CUDA kernel with one
   thread per lane): bin_val / bin_col point at the bin's first tile / slot, `nz` is the lane's count
   of real slots (the lane kernels never touch padding, so it stays zero whatever the factor), entry
   e of slot k of the lane is bin_val[k * bw * bs2 + e * bw + lane]. Operations whose result is the
   same with padding included (finite factors, sums) run over whole arrays or bins instead: the
   contiguous loops vectorise.
*/
#ifndef BINBCSR_VALUE_KERNELS_H
#define BINBCSR_VALUE_KERNELS_H

#include "binbcsr_kernels.h"

namespace binbcsr {

BINBCSR_HD long value_offset(int k, int e, int bw, int bs2, int lane)
{
  return ((long)k * bw) * bs2 + (long)e * bw + lane;
}

/* v *= a over the lane's real slots. */
template <typename V> BINBCSR_HD void lane_scale(V *bin_val, int nz, int bw, int bs2, int lane, double a)
{
  for (int k = 0; k < nz; k++)
    for (int e = 0; e < bs2; e++) {
      V &v = bin_val[value_offset(k, e, bw, bs2, lane)];
      v    = (V)(a * (double)v);
    }
}

/* y += a x over the lane's real slots, for two matrices with the same layout (any precisions). */
template <typename VY, typename VX>
BINBCSR_HD void lane_axpy(VY *y_bin_val, const VX *x_bin_val, int nz, int bw, int bs2, int lane, double a)
{
  for (int k = 0; k < nz; k++)
    for (int e = 0; e < bs2; e++) {
      const long o = value_offset(k, e, bw, bs2, lane);
      y_bin_val[o] = (VY)((double)y_bin_val[o] + a * (double)x_bin_val[o]);
    }
}

/* Row i (0 <= i < bs) of every block of the lane set to zero. */
template <typename V> BINBCSR_HD void lane_zero_row(V *bin_val, int nz, int bw, int bs, int lane, int i)
{
  const int bs2 = bs * bs;
  for (int k = 0; k < nz; k++)
    for (int j = 0; j < bs; j++) bin_val[value_offset(k, i * bs + j, bw, bs2, lane)] = (V)0;
}

/* Zeroes the entries of the lane's rows that lie in zeroed columns (zeroed_col[c] != 0, indexed by
   point column), skipping the rows flagged in zeroed_row[0..bs) (they are zeroed whole afterwards).
   With x and b: b[i] -= a_ic x[c] first, so that the eliminated unknowns' known values move to the
   right-hand side (b, zeroed_row point at the lane's rows; x is the whole vector). */
template <typename V, typename I>
BINBCSR_HD void lane_zero_columns(V *bin_val, const I *bin_col, int nz, int bw, int bs, int lane,
                                  const char *zeroed_col, const char *zeroed_row, const double *x, double *b)
{
  const int bs2 = bs * bs;
  for (int k = 0; k < nz; k++) {
    const long c0 = (long)bin_col[(long)k * bw + lane] * bs;
    for (int j = 0; j < bs; j++) {
      if (!zeroed_col[c0 + j]) continue;
      for (int i = 0; i < bs; i++) {
        if (zeroed_row[i]) continue;
        V &v = bin_val[value_offset(k, i * bs + j, bw, bs2, lane)];
        if (b) b[i] -= (double)v * x[c0 + j];
        v = (V)0;
      }
    }
  }
}

/* Kernels over whole value arrays or whole bins. Padding is included: it holds zeros, which add
   nothing to a sum and stay zero under a finite factor, and the loops run over contiguous memory. */

/* y += a x over n values (a finite). */
template <typename VY, typename VX> BINBCSR_HD void values_axpy(long n, VY *y, const VX *x, double a)
{
#pragma omp simd
  for (long i = 0; i < n; i++) y[i] = (VY)((double)y[i] + a * (double)x[i]);
}

/* v *= a over n values (a finite). */
template <typename V> BINBCSR_HD void values_scale(long n, V *v, double a)
{
#pragma omp simd
  for (long i = 0; i < n; i++) v[i] = (V)(a * (double)v[i]);
}

/* Sum of v^2 over n values. */
template <typename V> BINBCSR_HD double values_sum_squares(long n, const V *v)
{
  double s = 0.0;
#pragma omp simd reduction(+ : s)
  for (long i = 0; i < n; i++) s += (double)v[i] * (double)v[i];
  return s;
}

/* row_sum[i * bw + l] += |a_ij| over row i (0 <= i < bs) of every lane l of a bin of len slot groups
   (row_sum: bs * bw, zeroed by the caller). */
template <typename V>
BINBCSR_HD void bin_row_abs_sums(const V *bin_val, int len, int bw, int bs, double *row_sum)
{
  const int bs2 = bs * bs;
  for (int k = 0; k < len; k++)
    for (int i = 0; i < bs; i++)
      for (int j = 0; j < bs; j++) {
        const V *v = bin_val + value_offset(k, i * bs + j, bw, bs2, 0);
#pragma omp simd
        for (int l = 0; l < bw; l++) row_sum[i * bw + l] += v[l] < 0 ? -(double)v[l] : (double)v[l];
      }
}

/* Column reductions (MatGetColumnNorms/Reductions, the 1-norm): red[c] = op over the entries of
   point column c, for op one of: */
enum reduction_kind {
  reduce_abs_sum    = 0,
  reduce_square_sum = 1,
  reduce_abs_max    = 2,
  reduce_sum        = 3
};
template <int KIND> BINBCSR_HD double reduce(double acc, double v)
{
  const double a = v < 0 ? -v : v;
  if constexpr (KIND == reduce_abs_sum) return acc + a;
  else if constexpr (KIND == reduce_square_sum) return acc + v * v;
  else if constexpr (KIND == reduce_abs_max) return a > acc ? a : acc;
  else return acc + v;
}

/* red[c] = reduce(red[c], a_ic) over the entries of a bin of len slot groups whose lanes are the block
   rows r0, r0 + 1, ... (a scatter: a GPU needs atomics). Padding adds zeros, which change no reduction.
   MIRROR (symmetric storage): a stored off-diagonal block (r, c) also stands for its transpose (c, r),
   whose entries lie in the columns of block row r; phantom lanes (r >= mbs) have none. The kind and
   the mirror are template arguments: tested per value they cost the 1-norm 2.4x. */
template <int KIND, bool MIRROR, typename V, typename I>
BINBCSR_HD void bin_col_reductions(const V *bin_val, const I *bin_col, int len, int bw, int bs, I r0, I mbs,
                                   double *red)
{
  const int bs2 = bs * bs;
  for (int k = 0; k < len; k++) {
    const I *cols = bin_col + (long)k * bw;
    for (int i = 0; i < bs; i++)
      for (int j = 0; j < bs; j++) {
        const V *v = bin_val + value_offset(k, i * bs + j, bw, bs2, 0);
        for (int l = 0; l < bw; l++) {
          const long c = (long)cols[l] * bs + j;
          red[c]       = reduce<KIND>(red[c], (double)v[l]);
          if constexpr (MIRROR) {
            if (r0 + l < mbs && cols[l] != r0 + l) {
              const long r = (long)(r0 + l) * bs + i;
              red[r]       = reduce<KIND>(red[r], (double)v[l]);
            }
          }
        }
      }
  }
}

/* v_ij *= l_i r_j over one block (l: the bs factors of its block row or null, r: of its block column or
   null); tile points at entry 0 of the slot's block for its lane. */
template <typename V>
BINBCSR_HD void slot_diagonal_scale(V *tile, int bw, int bs, const double *l, const double *r)
{
  for (int i = 0; i < bs; i++)
    for (int j = 0; j < bs; j++) {
      V     &v = tile[(i * bs + j) * bw];
      double f = l ? l[i] : 1.0;
      if (r) f *= r[j];
      v = (V)(f * (double)v);
    }
}

/* The same over the lane's nz real slots (padding stays zero whatever the factors): l at the lane's
   rows, r the whole column scaling. */
template <typename V, typename I>
BINBCSR_HD void lane_diagonal_scale(V *bin_val, const I *bin_col, int nz, int bw, int bs, int lane,
                                    const double *l, const double *r)
{
  const int bs2 = bs * bs;
  for (int k = 0; k < nz; k++)
    slot_diagonal_scale(bin_val + value_offset(k, 0, bw, bs2, lane), bw, bs, l,
                        r ? r + (long)bin_col[(long)k * bw + lane] * bs : nullptr);
}

/* Row extremes (MatGetRowMaxAbs, MatGetRowMax, MatGetRowMin) with PETSc's AIJ rules: the value and the
   column where it is reached, for each point row. */
enum row_extreme_kind {
  extreme_max_abs = 0,
  extreme_max     = 1,
  extreme_min     = 2,
  extreme_min_abs = 3
};

/* The state of a row before its stored entries are seen: for max/min/min-abs, a row that does not store
   every column holds implicit zeros, the first at column first_gap; a row that does starts from
   nothing. */
template <typename I>
BINBCSR_HD void row_extreme_start(int kind, bool dense, I first_gap, double *best, I *at)
{
  if (kind == extreme_max_abs || !dense) {
    *best = 0.0;
    *at   = kind == extreme_max_abs ? 0 : first_gap;
  } else {
    *best = kind == extreme_max ? -1.0 / 0.0 : 1.0 / 0.0;
    *at   = -1;
  }
}

/* Whether v beats the row's best so far, and what is kept: |v| for max-abs, v itself otherwise (seqaij
   keeps the signed entry of the smallest magnitude). */
BINBCSR_HD bool row_extreme_beats(int kind, double v, double best)
{
  const double av = v < 0 ? -v : v, ab = best < 0 ? -best : best;
  switch (kind) {
  case extreme_max_abs:
    return av > best;
  case extreme_max:
    return v > best;
  case extreme_min:
    return v < best;
  default:
    return av < ab;
  }
}

/* best[i], at[i] (point row i of the block row) updated by one block of the row, whose columns are
   c0 .. c0 + bs - 1; blocks must come in ascending column order: only a strictly better value moves
   at[i], so ties keep the smallest column. transposed: the block is stored as (c, r) (the lower part of
   symmetric storage), entry (i, j) of the row is its entry (j, i). */
template <typename V, typename I>
BINBCSR_HD void slot_row_extremes(const V *tile, int bw, int bs, bool transposed, I c0, int kind,
                                  double *best, I *at)
{
  for (int i = 0; i < bs; i++)
    for (int j = 0; j < bs; j++) {
      const double v = (double)tile[(transposed ? j * bs + i : i * bs + j) * bw];
      if (row_extreme_beats(kind, v, best[i])) {
        best[i] = kind == extreme_max_abs && v < 0 ? -v : v;
        at[i]   = c0 + j;
      }
    }
}

/* MatGetRowMaxAbs over a whole bin whose lanes are the block rows r0, r0 + 1, ...: best[p], at[p] for
   every point row p of the matrix, started at 0 and 0 by the caller (seqaij's start). Ties go to the
   smaller column whatever the order the slots come in (symmetric storage colours them), which is
   seqaij's first maximum in column order. Padding holds zeros, which never beat a start of 0, so all
   len slot groups run. MIRROR (symmetric storage): a stored off-diagonal block (r, c) also offers its
   entries, transposed, to the rows of block c (a scatter: a GPU needs atomics for it). */
template <typename I> BINBCSR_HD void max_abs_offer(double a, I col, double *best, I *at)
{
  if (a > *best || (a == *best && a > 0 && col < *at)) {
    *best = a;
    *at   = col;
  }
}
template <bool MIRROR, typename V, typename I>
BINBCSR_HD void bin_row_max_abs(const V *bin_val, const I *bin_col, int len, int bw, int bs, I r0, I mbs,
                                double *best, I *at)
{
  const int bs2 = bs * bs, lanes = mbs - r0 < bw ? (int)(mbs - r0) : bw; /* phantom lanes hold padding only */
  for (int k = 0; k < len; k++) {
    const I *cols = bin_col + (long)k * bw;
    for (int i = 0; i < bs; i++)
      for (int j = 0; j < bs; j++) {
        const V *v = bin_val + value_offset(k, i * bs + j, bw, bs2, 0);
        for (int l = 0; l < lanes; l++) {
          const double a = v[l] < 0 ? -(double)v[l] : (double)v[l];
          const I      r = r0 + l, c = cols[l];
          max_abs_offer(a, c * bs + j, best + (long)r * bs + i, at + (long)r * bs + i);
          if constexpr (MIRROR)
            if (c != r) max_abs_offer(a, r * bs + i, best + (long)c * bs + j, at + (long)c * bs + j);
        }
      }
  }
}

} // namespace binbcsr

#endif
