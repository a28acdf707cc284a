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

   CPU drivers (binbcsr_bin_drivers.h) run slot_mult for k = 0..len-1 in the outer loop and over the lanes of
   a bin in the inner `omp simd` loop, so the lanes map onto SIMD lanes and every load of values and
   column indices is contiguous; a GPU runs lane_mult with one thread per lane, which reads the same
   addresses coalesced across the threads of a warp.
*/
#ifndef BINBCSR_KERNELS_H
#define BINBCSR_KERNELS_H

#include "../../binbcsr_hd.h"

/* Every body set (kernels/portable, avx2, avx512) compiles these templates with its own target flags in
   its own translation unit: the inline namespace gives each set its own symbols, so the linker never
   merges an AVX-512 instance into the portable code (the one-definition rule across TUs). */
#if !defined(BINBCSR_BODY_SET)
  #define BINBCSR_BODY_SET baseline
#endif

namespace binbcsr {
inline namespace BINBCSR_BODY_SET {

/* Software prefetch of the value stream, CPU only: the nbytes of a slot group, `ahead` bytes ahead of
   it (0: none). One core streaming one array out of cache is limited by how many cache lines it has
   in flight, not by the memory: on a Sapphire Rapids core the hardware prefetcher alone left the
   product at 73-79% of the triad bandwidth (27-point stencil, 48^3 nodes, double), 1 KB ahead gained
   nothing for double and about 10 points for single, 4 KB ahead brought both to 85-94%; on a Zen 5 VM
   in some minutes 4 KB ahead made the same product 1.7x slower than none (docs/tuning.md). So the
   distance is a run-time value of the matrix that the tuner chooses (MatBinBCSRSetPrefetch), not a
   constant: the branch on it is taken the same way for a whole product. */
template <typename V> BINBCSR_HD void prefetch_values(const V *tile, int nbytes, int ahead)
{
#if !defined(__CUDACC__) && defined(__GNUC__)
  if (ahead > 0)
    for (int q = 0; q < nbytes; q += 64) __builtin_prefetch((const char *)tile + ahead + q, 0, 3);
#else
  (void)tile;
  (void)nbytes;
  (void)ahead;
#endif
}

/* The slot groups of K bins swept together (len[q]: the groups of bin q): group(q, k) for group k of
   bin q, one group of each bin in turn while every bin has one left, then the rest of each bin. The
   products sweep several bins at once because the bins are then several streams for the hardware
   prefetcher (bins_sweep in binbcsr_bin_drivers.h says why). Forced inline on the host, so that a
   hand-written body whose group is an always_inline lambda keeps its accumulators in registers (out
   of line, GCC 12 passed them through memory, a call per slot group). */
#if !defined(__CUDACC__) && !defined(__HIPCC__) && defined(__GNUC__)
  #define BINBCSR_SWEEP_INLINE __attribute__((always_inline))
#else
  #define BINBCSR_SWEEP_INLINE
#endif
template <int K, class G> BINBCSR_HD BINBCSR_SWEEP_INLINE void interleave_groups(const int *len, G &&group)
{
  int common = len[0];
  for (int q = 1; q < K; q++) common = len[q] < common ? len[q] : common;
  for (int k = 0; k < common; k++)
    for (int q = 0; q < K; q++) group(q, k);
  for (int q = 0; q < K; q++)
    for (int k = common; k < len[q]; k++) group(q, k);
}

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

/* acc = acc + (row of the bin at `lane`) * x over the lane's first nz slots, its real blocks: padding
   is never read (its zero times a NaN or Inf of x would be a NaN the row does not have). A caller that
   has no row lengths (the CUDA benchmark) passes the bin's len and reads the padding (zeros, valid
   columns). bin_val / bin_col point at the bin's first tile / slot. */
template <int BS, typename V, typename I>
BINBCSR_HD void lane_mult(const V *bin_val, const I *bin_col, int nz, int bw, int bs_rt, int lane,
                          const double *x, double *acc)
{
  const int bs  = BS ? BS : bs_rt;
  const int bs2 = bs * bs;
#if defined(__CUDACC__)
  #pragma unroll 4 /* a thread's slots are chains of dependent loads (column, then x): unrolled, the
                      column loads of 4 slots can be in flight together (on the H100 the gain was
                      within the spread between runs, docs/gpu.md) */
#endif
  for (int k = 0; k < nz; k++) {
    const long s = (long)k * bw + lane;
    slot_mult<BS, V>(bin_val + (long)k * bw * bs2 + lane, bw, bs, x + (long)bin_col[s] * bs, acc);
  }
}

/* Point row i (0 <= i < bs) of the lane's block row times x over the bin's len slots: what lane_mult
   computes for acc[i] alone. A GPU runs bs threads per lane with it (a warp per bin and point row,
   still coalesced), which triples the threads of small matrices that would otherwise not fill it. */
template <int BS, typename V, typename I>
BINBCSR_HD double lane_row_mult(const V *bin_val, const I *bin_col, int len, int bw, int bs_rt, int lane,
                                int i, const double *x, int k0 = 0, int kstep = 1)
{
  const int bs  = BS ? BS : bs_rt;
  const int bs2 = bs * bs;
  double    s   = 0.0;
#if defined(__CUDACC__)
  #pragma unroll 4
#endif
  for (int k = k0; k < len; k += kstep) { /* k0, kstep: a share of the slots, for threads that split a bin */
    const V   *t  = bin_val + (long)k * bw * bs2 + (long)i * bs * bw + lane;
    const long c0 = (long)bin_col[(long)k * bw + lane] * bs;
    for (int j = 0; j < bs; j++) s += (double)t[j * bw] * x[c0 + j];
  }
  return s;
}

/* y(cols) += (row at `lane`)^T * xr over the lane's nz real slots (padding skipped: its column may
   be shared with a real entry, and a phantom row has no x). On a GPU the scatter needs atomics. */
template <int BS, typename V, typename I>
BINBCSR_HD void lane_mult_transpose(const V *bin_val, const I *bin_col, int nz, int bw, int bs_rt, int lane,
                                    const double *xr, double *y)
{
  const int bs  = BS ? BS : bs_rt;
  const int bs2 = bs * bs;
  for (int k = 0; k < nz; k++) {
    const long s = (long)k * bw + lane;
    slot_mult_transpose<BS, V>(bin_val + (long)k * bw * bs2 + lane, bw, bs, xr, y + (long)bin_col[s] * bs);
  }
}

/* Symmetric storage (upper triangle; see binbcsr.h): one lane of a bin, len slots, all of them (real
   and padding). For every slot of block column c: acc += block x_c, and when c != own (an
   off-diagonal block (r, c), c > r): y_c += block^T xr, the product with the lower block that is not
   stored. Padding slots hold zeros and own as their column, the diagonal block (slot group kd, -1:
   none) has c == own: neither scatters, and padding adds nothing to acc (it is not read: zero times a
   NaN or Inf of x_own would be a NaN the row does not have). The caller zeroes y first and adds acc to y_r after the lane. Lanes of one bin may run
   in any order or in lock step per slot (SIMD lanes, a warp): the layout build colours the slots so
   that no two lanes of one slot group scatter to the same column, so no atomics are needed (a GPU
   must keep the lanes of a bin in step per slot, e.g. one warp per bin with __syncwarp per k). */
template <int BS, typename V, typename I>
BINBCSR_HD void sym_lane_mult(const V *bin_val, const I *bin_col, int len, int bw, int bs_rt, int lane, I own,
                              int kd, const double *x, const double *xr, double *y, double *acc)
{
  const int bs  = BS ? BS : bs_rt;
  const int bs2 = bs * bs;
  for (int k = 0; k < len; k++) {
    const long s = (long)k * bw + lane;
    const I    c = bin_col[s];
    const V   *t = bin_val + (long)k * bw * bs2 + lane;
    if (c != own) {
      slot_mult<BS, V>(t, bw, bs, x + (long)c * bs, acc);
      slot_mult_transpose<BS, V>(t, bw, bs, xr, y + (long)c * bs);
    } else if (k == kd) slot_mult<BS, V>(t, bw, bs, x + (long)c * bs, acc);
  }
}

/* True when the BW lanes of a slot group read the consecutive block columns c[0], c[0] + 1, ...: a
   structured grid numbered along its rows (cloth, stencils), away from the grid's edges. */
template <typename I> BINBCSR_HD bool unit_stride(const I *c, int bw)
{
  if (c[bw - 1] != c[0] + bw - 1)
    return false; /* one compare rejects almost every group of an unstructured mesh */
  bool unit = true;
  for (int l = 1; l < bw; l++) unit &= c[l] == c[0] + l;
  return unit;
}
template <int BW, typename I> BINBCSR_HD bool unit_stride(const I *c) { return unit_stride(c, BW); }

/* One slot group of sym_bins_mult whose lanes read the consecutive block columns xs, xs + BS, ...:
   acc += block x_c and, with SCATTER, y_c += block^T x_r, by unit-stride loads and stores. The
   branch is a template argument: a run-time test inside the lane loop stops GCC from vectorising it. */
template <int BS, int BW, typename V, bool SCATTER>
BINBCSR_HD void sym_unit_group_mult(const V *t, const double *xs, const double (*xr)[BW], double *ys,
                                    double (*acc)[BW], int k, const int *kd)
{
  constexpr int BS2 = BS * BS;
#pragma omp simd
  for (int l = 0; l < BW; l++) {
    double     v[BS2], xc[BS];
    const bool real = SCATTER || k == kd[l]; /* without scatters: the diagonal block or padding */
    for (int e = 0; e < BS2; e++) v[e] = (double)t[e * BW + l];
    for (int j = 0; j < BS; j++) xc[j] = real ? xs[l * BS + j] : 0.0;
    for (int i = 0; i < BS; i++) {
      double s = acc[i][l];
      for (int j = 0; j < BS; j++) s += v[i * BS + j] * xc[j];
      acc[i][l] = s;
    }
    if constexpr (SCATTER)
      for (int j = 0; j < BS; j++) {
        double s = 0.0;
        for (int i = 0; i < BS; i++) s += v[i * BS + j] * xr[i][l];
        ys[l * BS + j] += s;
      }
  }
}

/* One slot group (number k) of sym_bins_mult (BW lanes in lock step, the lane loop is the SIMD loop):
   acc += block x_c for the real slots (x_c of a padding slot reads as zero: kd[l] is the group of lane
   l's diagonal block), and a masked scatter-add of block^T x_r into y_c (conflict-free by the
   colouring). */
template <int BS, int BW, typename V, typename I>
BINBCSR_HD void sym_group_mult(const V *t, const I *c, I r0, const I *own, const double (*xr)[BW],
                               const double *x, double *y, double (*acc)[BW], int k, const int *kd, int pf)
{
  constexpr int BS2 = BS * BS;
  prefetch_values(t, BW * BS2 * (int)sizeof(V), pf);
  if (unit_stride<BW>(
        c)) { /* contiguous x_c and y_c: plain loads and stores instead of gathers and scatters */
    const I c0 = c[0];
    /* c0 == r0: the diagonal blocks or padding of every lane, nothing to scatter */
    if (c0 == r0) sym_unit_group_mult<BS, BW, V, false>(t, x + (long)c0 * BS, xr, nullptr, acc, k, kd);
    else sym_unit_group_mult<BS, BW, V, true>(t, x + (long)c0 * BS, xr, y + (long)c0 * BS, acc, k, kd);
    return;
  }
#pragma omp simd
  for (int l = 0; l < BW; l++) {
    const I    cl   = c[l];
    const int  ci   = (int)cl * BS; /* 32-bit offsets: vgatherdpd, fewer index instructions */
    const bool real = cl != own[l] || k == kd[l];
    double     xc[BS], v[BS2];
    for (int j = 0; j < BS; j++) xc[j] = real ? x[ci + j] : 0.0;
    for (int e = 0; e < BS2; e++) v[e] = (double)t[e * BW + l];
    for (int i = 0; i < BS; i++) {
      double s = acc[i][l];
      for (int j = 0; j < BS; j++) s += v[i * BS + j] * xc[j];
      acc[i][l] = s;
    }
    if (cl != own[l]) {
      for (int j = 0; j < BS; j++) {
        double s = 0.0;
        for (int i = 0; i < BS; i++) s += v[i * BS + j] * xr[i][l];
        y[ci + j] += s;
      }
    }
  }
}

/* The symmetric product of K whole bins of BW lanes (BW, BS compile-time), swept together: the slot
   groups of the K bins in turn (several streams for the prefetcher, as the whole-storage bins_sweep),
   each group through sym_group_mult. Lanes whose row is >= mbs are phantom: their slots are padding
   (zeros, column own = mbs - 1, masked out) and their acc is dropped. kd[q][l]: the slot group of
   the diagonal block of lane l of bin q (-1: none), which tells padding from the diagonal block. On exit y_r += acc for the real
   lanes of every bin. Scatters of one bin may land in the rows of another bin of the sweep: all are
   additions into y, and a bin's own rows are added only at its end. pf: the prefetch distance in bytes
   (prefetch_values). */
template <int K, int BS, int BW, typename V, typename I>
BINBCSR_HD void sym_bins_mult(const V *const *bin_val, const I *const *bin_col, const int *len, const I *r0,
                              I mbs, const int (*kd)[BW], const double *x, double *y, int pf)
{
  constexpr int BS2 = BS * BS;
  double        acc[K][BS][BW], xr[K][BS][BW];
  I             own[K][BW];
  for (int q = 0; q < K; q++) {
    for (int l = 0; l < BW; l++) {
      const bool real = r0[q] + l < mbs;
      own[q][l]       = real ? r0[q] + l : mbs - 1;
      for (int i = 0; i < BS; i++) {
        acc[q][i][l] = 0.0;
        xr[q][i][l]  = real ? x[(long)(r0[q] + l) * BS + i] : 0.0;
      }
    }
  }
  interleave_groups<K>(len, [&](int q, int k) {
    sym_group_mult<BS, BW, V, I>(bin_val[q] + (long)k * BW * BS2, bin_col[q] + (long)k * BW, r0[q], own[q],
                                 xr[q], x, y, acc[q], k, kd[q], pf);
  });
  for (int q = 0; q < K; q++)
    for (int l = 0; l < BW; l++)
      if (r0[q] + l < mbs)
        for (int i = 0; i < BS; i++) y[(long)(r0[q] + l) * BS + i] += acc[q][i][l];
}

/* COO refill of one value: the sum of the entries perm[jmap[v] .. jmap[v+1]-1], where an index p < n
   reads coo_v[p] (double or float) and p >= n reads recv[p - n] (the MPI refill: the caller's values and the values
   received from other ranks, without first copying both into one array). One source: n past every
   index, recv unused. */
template <typename I, typename T>
BINBCSR_HD double coo_gather(const T *coo_v, long n, const double *recv, const I *jmap, const I *perm, long v)
{
  double s = 0.0;
  for (I j = jmap[v]; j < jmap[v + 1]; j++) {
    const long p = perm[j];
    s += p < n ? (double)coo_v[p] : recv[p - n];
  }
  return s;
}

} // namespace BINBCSR_BODY_SET
} // namespace binbcsr

#endif
