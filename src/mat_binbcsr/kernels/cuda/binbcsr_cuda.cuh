/*
   CUDA kernels of BIN-(B)CSR and of the merged CG (KSPMCG's iteration) over device arrays. They call
   the lane bodies of binbcsr_kernels.h with one thread per lane, so the GPU runs the arithmetic the
   CPU kernels are tested with. No PETSc here (Debian's PETSc has no CUDA): examples/gpu/ drives them
   directly, and a MATBINBCSRCUDA type would call the same kernels.

   Thread mapping: global thread t is lane t % bw of bin t / bw; with bw = 32 a warp is a bin, so the
   column indices and each entry plane of the values are read as one coalesced 128/256-byte line.

   The merged CG (Jacobi preconditioner) takes 3 launches per iteration and no host synchronisation:
     1. q = A p and the partial sums of p.q           (mcg_spmv_dot)
     2. x += a p, r -= a q, z = D^-1 r, partial r.z   (mcg_update; a = rz / pq read on the device)
     3. p = z + b p                                    (mcg_direction; b = rz_new / rz)
   Each reduction is finished by the last block to arrive (a ticket counter), which sums the blocks'
   partials in block order: the result does not depend on the order the blocks ran in, so two runs
   give the same bits and every block reads the same scalar.
*/
#ifndef BINBCSR_CUDA_CUH
#define BINBCSR_CUDA_CUH

#include "../binbcsr_kernels.h"

namespace binbcsr
{
namespace cuda
{

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
__device__ __forceinline__ void finish_sum(double mine, double *partials, unsigned *ticket, double *out, double *hist)
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
__global__ void __launch_bounds__(block_threads) bin_mult(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs, int bw, const double *__restrict__ x, double *__restrict__ y)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, b = t / bw, lane = t % bw, r = t;
  if (r >= mbs) return;
  const int s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  double    acc[BS];
  for (int i = 0; i < BS; i++) acc[i] = 0.0;
  lane_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, x, acc);
  for (int i = 0; i < BS; i++) y[(long)r * BS + i] = acc[i];
}

/* y = A x with bs threads per lane, one per point row (lane_row_mult): thread t is point row i of lane
   l of bin b, t = (b * BS + i) * bw + l. */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads) bin_mult_rows(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs, int bw, const double *__restrict__ x, double *__restrict__ y)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, b = t / (BS * bw), i = t / bw % BS, lane = t % bw, r = b * bw + lane;
  if (r >= mbs) return;
  const int s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  y[(long)r * BS + i] = lane_row_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, i, x);
}

/* Bin width 8 (the CPU's default): a warp is one point row of one bin, its 32 threads 8 lanes x 4 slot
   phases; thread (h, l) takes slots h, h + 4, ... and two shuffles add the 4 partial sums. A warp
   walks a quarter of its bin, which is what bins holding a few very long rows need (a warp's time is
   its longest row's). Launch 32 * BS threads per bin: split_threads(). */
template <int BS, typename V>
__device__ __forceinline__ double bin_row_split8(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs, const double *__restrict__ x, int *row)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, warp = t / 32, lane = t % 8, h = t % 32 / 8, b = warp / BS, i = warp % BS;
  double    s = 0.0;
  *row = -1;
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
__global__ void __launch_bounds__(block_threads) bin_mult_split8(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs, const double *__restrict__ x, double *__restrict__ y)
{
  int          row;
  const double s = bin_row_split8<BS, V>(val, col, bin_start, mbs, x, &row);
  if (row >= 0) y[row] = s;
}
inline long split_threads(int mbs, int bs) { return (long)((mbs + 7) / 8) * 32 * bs; }

/* Threads bin_mult_rows needs for mbs block rows: BS per lane of every bin, phantom lanes included. */
inline long rows_threads(int mbs, int bw, int bs) { return (long)((mbs + bw - 1) / bw) * bw * bs; }

/* Scalars of one merged-CG solve, on the device. */
struct MCGScalars {
  double   rz[2];    /* r.z of the current and the next iteration (parity of the iteration picks) */
  double   pq;       /* p.A p of this iteration */
  unsigned ticket;   /* finish_sum's counter */
};

/* 1. q = A p; p.q into s->pq. Launch rows_threads(mbs, bw, BS) threads. */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads) mcg_spmv_dot(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs, int bw, const double *__restrict__ p, double *__restrict__ q, double *partials, MCGScalars *s)
{
  const int t = blockIdx.x * blockDim.x + threadIdx.x, b = t / (BS * bw), i = t / bw % BS, lane = t % bw, r = b * bw + lane;
  double    d = 0.0;
  if (r < mbs) { /* the thread mapping of bin_mult_rows */
    const int    s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
    const double qi = lane_row_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, i, p);
    q[(long)r * BS + i] = qi;
    d = p[(long)r * BS + i] * qi;
  }
  finish_sum(block_sum(d), partials, &s->ticket, &s->pq, nullptr);
}

/* 1 for bin width 8, the bin_mult_split8 mapping. Launch split_threads(mbs, BS) threads. */
template <int BS, typename V>
__global__ void __launch_bounds__(block_threads) mcg_spmv_dot_split8(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs, const double *__restrict__ p, double *__restrict__ q, double *partials, MCGScalars *s)
{
  int          row;
  const double qi = bin_row_split8<BS, V>(val, col, bin_start, mbs, p, &row);
  double       d  = 0.0;
  if (row >= 0) {
    q[row] = qi;
    d      = p[row] * qi;
  }
  finish_sum(block_sum(d), partials, &s->ticket, &s->pq, nullptr);
}

/* 2. With a = rz / pq: x += a p, r -= a q, z = dinv r; r.z of the new residual into s->rz[1 - cur]
   (and hist). Grid-stride over the n entries. */
__global__ void __launch_bounds__(block_threads) mcg_update(int n, int cur, const double *__restrict__ dinv, const double *__restrict__ p, const double *__restrict__ q, double *__restrict__ x, double *__restrict__ r, double *__restrict__ z, double *partials, MCGScalars *s, double *hist)
{
  const double a = s->pq > 0.0 ? s->rz[cur] / s->pq : 0.0; /* p = 0: converged exactly, stay */
  double       d = 0.0;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    const double ri = r[i] - a * q[i], zi = dinv[i] * ri;
    x[i] += a * p[i];
    r[i] = ri;
    z[i] = zi;
    d += ri * zi;
  }
  finish_sum(block_sum(d), partials, &s->ticket, &s->rz[1 - cur], hist);
}

/* Start from x = 0: r = b, z = dinv b, p = z, r.z into s->rz[0] (and hist). */
__global__ void __launch_bounds__(block_threads) mcg_start(int n, const double *__restrict__ dinv, const double *__restrict__ rhs, double *__restrict__ x, double *__restrict__ r, double *__restrict__ z, double *__restrict__ p, double *partials, MCGScalars *s, double *hist)
{
  double d = 0.0;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    const double zi = dinv[i] * rhs[i];
    x[i] = 0.0;
    r[i] = rhs[i];
    z[i] = zi;
    p[i] = zi;
    d += rhs[i] * zi;
  }
  finish_sum(block_sum(d), partials, &s->ticket, &s->rz[0], hist);
}

/* 3. p = z + b p with b = rz[next] / rz[cur]. */
__global__ void __launch_bounds__(block_threads) mcg_direction(int n, int cur, const double *__restrict__ z, double *__restrict__ p, const MCGScalars *s)
{
  const double beta = s->rz[cur] > 0.0 ? s->rz[1 - cur] / s->rz[cur] : 0.0;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) p[i] = z[i] + beta * p[i];
}

} // namespace cuda
} // namespace binbcsr

#endif
