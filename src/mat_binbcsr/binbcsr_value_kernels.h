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

namespace binbcsr
{

BINBCSR_HD long value_offset(int k, int e, int bw, int bs2, int lane)
{
  return ((long)k * bw) * bs2 + (long)e * bw + lane;
}

/* v *= a over the lane's real slots. */
template <typename V>
BINBCSR_HD void lane_scale(V *bin_val, int nz, int bw, int bs2, int lane, double a)
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
template <typename V>
BINBCSR_HD void lane_zero_row(V *bin_val, int nz, int bw, int bs, int lane, int i)
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
BINBCSR_HD void lane_zero_columns(V *bin_val, const I *bin_col, int nz, int bw, int bs, int lane, const char *zeroed_col, const char *zeroed_row, const double *x, double *b)
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
template <typename VY, typename VX>
BINBCSR_HD void values_axpy(long n, VY *y, const VX *x, double a)
{
#pragma omp simd
  for (long i = 0; i < n; i++) y[i] = (VY)((double)y[i] + a * (double)x[i]);
}

/* v *= a over n values (a finite). */
template <typename V>
BINBCSR_HD void values_scale(long n, V *v, double a)
{
#pragma omp simd
  for (long i = 0; i < n; i++) v[i] = (V)(a * (double)v[i]);
}

/* Sum of v^2 over n values. */
template <typename V>
BINBCSR_HD double values_sum_squares(long n, const V *v)
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

/* col_sum[c] += |a_ic| over the entries of a bin of len slot groups (a scatter: a GPU needs atomics). */
template <typename V, typename I>
BINBCSR_HD void bin_col_abs_sums(const V *bin_val, const I *bin_col, int len, int bw, int bs, double *col_sum)
{
  const int bs2 = bs * bs;
  for (int k = 0; k < len; k++) {
    const I *cols = bin_col + (long)k * bw;
    for (int i = 0; i < bs; i++)
      for (int j = 0; j < bs; j++) {
        const V *v = bin_val + value_offset(k, i * bs + j, bw, bs2, 0);
        for (int l = 0; l < bw; l++) col_sum[(long)cols[l] * bs + j] += v[l] < 0 ? -(double)v[l] : (double)v[l];
      }
  }
}

} // namespace binbcsr

#endif
