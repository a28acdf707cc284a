// The BIN-(B)CSR lane kernels compiled as CUDA device code, one thread per lane: the check that
// src/mat_binbcsr/binbcsr_kernels.h stays a header a CUDA backend can call (no STL, no PETSc, no host-only
// calls). Compiled by the CTest case cuda_kernels_compile when nvcc is found; CI has no GPU, so this is a
// compile check (the same bodies are tested on the CPU; the whole-storage kernels of binbcsr_cuda.cuh
// were run and checked on an H100 by examples/gpu/, docs/gpu.md; the symmetric product below was not).
#include "mat_binbcsr/binbcsr_kernels.h"
#include "mat_binbcsr/cuda/binbcsr_cuda.cuh" /* the whole-storage product and the merged CG, run by examples/gpu/ */

namespace binbcsr_device_check
{

// Symmetric storage: one warp per bin (bw <= 32). A backend that runs this must also keep the lanes in
// step per slot (__syncwarp between slot groups, see the header): the colouring makes the scatters of
// one slot group conflict-free, not those of different groups.
template <int BS, typename V>
__global__ void sym_bin_mult(const V *val, const int *col, const int *bin_start, int nbins, int mbs, int bw, const double *x, double *y)
{
  const int b = blockIdx.x, lane = threadIdx.x, r = b * bw + lane;
  if (b >= nbins || lane >= bw) return;
  const int own = r < mbs ? r : mbs - 1, s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  double    acc[BS], xr[BS];
  for (int i = 0; i < BS; i++) {
    acc[i] = 0.0;
    xr[i]  = r < mbs ? x[(long)r * BS + i] : 0.0;
  }
  binbcsr::sym_lane_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, own, x, xr, y, acc);
  if (r < mbs)
    for (int i = 0; i < BS; i++) atomicAdd(&y[(long)r * BS + i], acc[i]);
}

// The COO refill: one thread per stored value.
__global__ void coo_refill(const double *coo_v, long n, const double *recv, const int *jmap, const int *perm, long nv, double *val)
{
  const long v = (long)blockIdx.x * blockDim.x + threadIdx.x;
  if (v < nv) val[v] = binbcsr::coo_gather<int>(coo_v, n, recv, jmap, perm, v);
}

// Instantiations: block sizes 1 and 3, double and single storage.
template __global__ void sym_bin_mult<3, double>(const double *, const int *, const int *, int, int, int, const double *, double *);
template __global__ void sym_bin_mult<3, float>(const float *, const int *, const int *, int, int, int, const double *, double *);
} // namespace binbcsr_device_check

// The kernels of binbcsr_cuda.cuh for block sizes 1 and 3 in both precisions (the GPU benchmark
// instantiates the ones it runs; these are the rest a backend would need).
template __global__ void binbcsr::cuda::bin_mult<1, double>(const double *, const int *, const int *, int, int, const double *, double *);
template __global__ void binbcsr::cuda::bin_mult_rows<1, float>(const float *, const int *, const int *, int, int, const double *, double *);
template __global__ void binbcsr::cuda::bin_mult_split8<1, double>(const double *, const int *, const int *, int, const double *, double *);
