/*
   Kernels of the BIN-(B)CSR format over ONE lane of a bin (one block row), written as plain inline
   functions: no STL, no PETSc, no allocation, so that a CUDA backend can call the same bodies with
   one thread per lane (BINBCSR_HD expands to __host__ __device__ there).

   Conventions (see src/mat_binbcsr/seq/binbcsr.h for the layout):
     - BS is the block size as a template constant (1, 3) or 0 for "runtime block size bs_rt";
     - V is the value type of the storage (double or float); products accumulate in double;
     - I is the column index type (32-bit in this build);
     - a "tile lane pointer" points at entry 0 of one slot's block for one lane: entry e of the block
       (row-major, e = i*bs + j) is at tile[e * bw].

   CPU drivers (binbcsr_mult.cpp) run slot_mult for k = 0..len-1 in the outer loop and over the lanes of
   a bin in the inner `omp simd` loop, so the lanes map onto SIMD lanes and every load of values and
   column indices is contiguous; a GPU runs lane_mult with one thread per lane, which reads the same
   addresses coalesced across the threads of a warp.
*/
#ifndef BINBCSR_KERNELS_H
#define BINBCSR_KERNELS_H

#if defined(__CUDACC__)
  #define BINBCSR_HD __host__ __device__ __forceinline__
#else
  #define BINBCSR_HD inline
#endif

namespace binbcsr
{

/* acc[i] += sum_j block(i,j) * xc[j]: one slot of one lane (xc = x at the slot's block column). */
template <int BS, typename V>
BINBCSR_HD void slot_mult(const V *tile, int bw, int bs_rt, const double *xc, double *acc)
{
  const int bs = BS ? BS : bs_rt;
  for (int i = 0; i < bs; i++) {
    double s = acc[i];
    for (int j = 0; j < bs; j++) s += (double)tile[(i * bs + j) * bw] * xc[j];
    acc[i] = s;
  }
}

/* yc[j] += sum_i block(i,j) * xr[i]: the transpose product of one slot (yc = y at the slot's block
   column, xr = x at the lane's row). */
template <int BS, typename V>
BINBCSR_HD void slot_mult_transpose(const V *tile, int bw, int bs_rt, const double *xr, double *yc)
{
  const int bs = BS ? BS : bs_rt;
  for (int j = 0; j < bs; j++) {
    double s = 0.0;
    for (int i = 0; i < bs; i++) s += (double)tile[(i * bs + j) * bw] * xr[i];
    yc[j] += s;
  }
}

/* acc = acc + (row of the bin at `lane`) * x over the bin's len slot columns (padding included: it
   holds zeros and a valid column). bin_val / bin_col point at the bin's first tile / slot. */
template <int BS, typename V, typename I>
BINBCSR_HD void lane_mult(const V *bin_val, const I *bin_col, int len, int bw, int bs_rt, int lane, const double *x, double *acc)
{
  const int bs  = BS ? BS : bs_rt;
  const int bs2 = bs * bs;
  for (int k = 0; k < len; k++) {
    const long s = (long)k * bw + lane;
    slot_mult<BS, V>(bin_val + (long)k * bw * bs2 + lane, bw, bs, x + (long)bin_col[s] * bs, acc);
  }
}

/* y(cols) += (row at `lane`)^T * xr over the lane's nz real slots (padding skipped: its column may
   be shared with a real entry, and a phantom row has no x). On a GPU the scatter needs atomics. */
template <int BS, typename V, typename I>
BINBCSR_HD void lane_mult_transpose(const V *bin_val, const I *bin_col, int nz, int bw, int bs_rt, int lane, const double *xr, double *y)
{
  const int bs  = BS ? BS : bs_rt;
  const int bs2 = bs * bs;
  for (int k = 0; k < nz; k++) {
    const long s = (long)k * bw + lane;
    slot_mult_transpose<BS, V>(bin_val + (long)k * bw * bs2 + lane, bw, bs, xr, y + (long)bin_col[s] * bs);
  }
}

/* COO refill of one value: the sum of the coo entries perm[jmap[v] .. jmap[v+1]-1] of coo_v. */
template <typename I>
BINBCSR_HD double coo_gather(const double *coo_v, const I *jmap, const I *perm, long v)
{
  double s = 0.0;
  for (I j = jmap[v]; j < jmap[v + 1]; j++) s += coo_v[perm[j]];
  return s;
}

} // namespace binbcsr

#endif
