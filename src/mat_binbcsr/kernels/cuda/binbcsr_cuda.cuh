/*
   The CUDA body set of BIN-(B)CSR: kernels over device arrays. They call
   the lane bodies of binbcsr_kernels.h with one thread per lane, so the GPU runs the arithmetic the
   CPU kernels are tested with. No PETSc here (Debian's PETSc has no CUDA): examples/gpu/ drives them
   directly, and a MATBINBCSRCUDA type would call the same kernels.

   Thread mapping: global thread t is lane t % bw of bin t / bw; with bw = 32 a warp is a bin, so the
   column indices and each entry plane of the values are read as one coalesced 128/256-byte line.

   The merged CG's vector updates that go with these products are the KSP's: src/ksp_mcg/mcg_device.cuh.

   Reductions (bin_mult_dot) are finished by the last block to arrive (a ticket counter), which sums
   the blocks' partials in block order: the result does not depend on the order the blocks ran in, so
   two runs give the same bits and every block reads the same scalar.
*/
#ifndef BINBCSR_CUDA_CUH
#define BINBCSR_CUDA_CUH

#include "../binbcsr_kernels.h"

namespace binbcsr {
namespace cuda {

constexpr int block_threads = 256;

/* Sum of v over the block (block_threads threads); valid in thread 0. */
__device__ __forceinline__ double block_sum(double v)
{
  __shared__ double warp_sums[block_threads / 32];
  for (int o = 16; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
  if ((threadIdx.x & 31) == 0) warp_sums[threadIdx.x >> 5] = v;
  __syncthreads();
  double s = 0.0;
  if (threadIdx.x == 0)
    for (int w = 0; w < block_threads / 32; w++) s += warp_sums[w];
  return s;
}

/* Stores the block's partial sum; the last block to arrive sums all partials in block order into *out
   (and, if hist is non-null, appends it there). ticket: one counter, zero on entry, zero again on exit. */
__device__ __forceinline__ void finish_sum(double mine, double *partials, unsigned *ticket, double *out,
                                           double *hist)
{
  __shared__ bool last;
  if (threadIdx.x == 0) {
    partials[blockIdx.x] = mine;
    __threadfence();
    last = atomicInc(ticket, gridDim.x - 1) == gridDim.x - 1; /* wraps to 0 for the next launch */
  }
  __syncthreads();
  if (!last) return;
  double s = 0.0;
  for (unsigned b = threadIdx.x; b < gridDim.x; b += blockDim.x) s += ((volatile double *)partials)[b];
  s = block_sum(s);
  if (threadIdx.x == 0) {
    *out = s;
    if (hist) *hist = s;
  }
}

/* y = A x, one thread per lane (block row). */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads)
  bin_mult(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs,
           int bw, const double *__restrict__ x, double *__restrict__ y)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, b = t / bw, lane = t % bw, r = t;
  if (r >= mbs) return;
  const int s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  double    acc[BS];
  for (int i = 0; i < BS; i++) acc[i] = 0.0;
  lane_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, x,
                        acc); /* len: padding read (no row lengths here) */
  for (int i = 0; i < BS; i++) y[(long)r * BS + i] = acc[i];
}

/* y = A x with bs threads per lane, one per point row (lane_row_mult): thread t is point row i of lane
   l of bin b, t = (b * BS + i) * bw + l. */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads)
  bin_mult_rows(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start,
                int mbs, int bw, const double *__restrict__ x, double *__restrict__ y)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, b = t / (BS * bw), i = t / bw % BS, lane = t % bw,
            r = b * bw + lane;
  if (r >= mbs) return;
  const int s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  y[(long)r * BS + i] =
    lane_row_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, i, x);
}

/* Bin width 8 (the CPU's default): a warp is one point row of one bin, its 32 threads 8 lanes x 4 slot
   phases; thread (h, l) takes slots h, h + 4, ... and two shuffles add the 4 partial sums. A warp
   walks a quarter of its bin, which is what bins holding a few very long rows need (a warp's time is
   its longest row's). Launch 32 * BS threads per bin: split_threads(). */
template <int BS, typename V>
__device__ __forceinline__ double bin_row_split8(const V *__restrict__ val, const int *__restrict__ col,
                                                 const int *__restrict__ bin_start, int mbs,
                                                 const double *__restrict__ x, int     *row)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, warp = t / 32, lane = t % 8, h = t % 32 / 8,
            b = warp / BS, i = warp % BS;
  double s = 0.0;
  *row     = -1;
  if (b * 8 < mbs) {
    const int s0 = bin_start[b], len = (bin_start[b + 1] - s0) / 8;
    s = lane_row_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, 8, BS, lane, i, x, h, 4);
    if (h == 0 && b * 8 + lane < mbs) *row = (b * 8 + lane) * BS + i;
  }
  s += __shfl_xor_sync(0xffffffffu, s, 8);
  s += __shfl_xor_sync(0xffffffffu, s, 16);
  return s;
}
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads)
  bin_mult_split8(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start,
                  int mbs, const double *__restrict__ x, double *__restrict__ y)
{
  int          row;
  const double s = bin_row_split8<BS, V>(val, col, bin_start, mbs, x, &row);
  if (row >= 0) y[row] = s;
}
inline long split_threads(int mbs, int bs) { return (long)((mbs + 7) / 8) * 32 * bs; }

/* Threads bin_mult_rows needs for mbs block rows: BS per lane of every bin, phantom lanes included. */
inline long rows_threads(int mbs, int bw, int bs) { return (long)((mbs + bw - 1) / bw) * bw * bs; }

/* q = A p and p.q, finished into *out by the last block (finish_sum; ticket: its counter): the product
   of a merged CG iteration. Launch rows_threads(mbs, bw, BS) threads. */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads)
  bin_mult_dot(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start,
               int mbs, int bw, const double *__restrict__ p, double *__restrict__ q, double *partials,
               unsigned *ticket, double *out)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, b = t / (BS * bw), i = t / bw % BS, lane = t % bw,
            r = b * bw + lane;
  double d    = 0.0;
  if (r < mbs) { /* the thread mapping of bin_mult_rows */
    const int    s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
    const double qi = lane_row_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, i, p);
    q[(long)r * BS + i] = qi;
    d                   = p[(long)r * BS + i] * qi;
  }
  finish_sum(block_sum(d), partials, ticket, out, nullptr);
}

/* bin_mult_dot for bin width 8, the bin_mult_split8 mapping. Launch split_threads(mbs, BS) threads. */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads)
  bin_mult_dot_split8(const V *__restrict__ val, const int *__restrict__ col,
                      const int *__restrict__ bin_start, int mbs, const double *__restrict__ p,
                      double *__restrict__ q, double *partials, unsigned *ticket, double *out)
{
  int          row;
  const double qi = bin_row_split8<BS, V>(val, col, bin_start, mbs, p, &row);
  double       d  = 0.0;
  if (row >= 0) {
    q[row] = qi;
    d      = p[row] * qi;
  }
  finish_sum(block_sum(d), partials, ticket, out, nullptr);
}

/* Symmetric storage: one warp per bin (bw <= 32), y += A x with y zeroed first. A backend that runs
   this must also keep the lanes in step per slot (__syncwarp between slot groups, see sym_lane_mult):
   the colouring makes the scatters of one slot group conflict-free, not those of different groups.
   Compiled (tests/cuda/kernels_device.cu), not yet run on a GPU. */
template <int BS, typename V>
__global__ void sym_bin_mult(const V *val, const int *col, const int *bin_start, const int *diag_slot,
                             int nbins, int mbs, int bw, const double *x, double *y)
{
  const int b = blockIdx.x, lane = threadIdx.x, r = b * bw + lane;
  if (b >= nbins || lane >= bw) return;
  const int own = r < mbs ? r : mbs - 1, s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  double    acc[BS], xr[BS];
  for (int i = 0; i < BS; i++) {
    acc[i] = 0.0;
    xr[i]  = r < mbs ? x[(long)r * BS + i] : 0.0;
  }
  const int kd = r < mbs && diag_slot[r] >= 0 ? (diag_slot[r] - s0) / bw : -1;
  sym_lane_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, own, kd, x, xr, y, acc);
  if (r < mbs)
    for (int i = 0; i < BS; i++) atomicAdd(&y[(long)r * BS + i], acc[i]);
}

} // namespace cuda
} // namespace binbcsr

#endif
