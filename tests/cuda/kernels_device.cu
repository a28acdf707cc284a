// The BIN-(B)CSR lane kernels compiled as CUDA device code, one thread per lane: the check that
// src/mat_binbcsr/kernels/binbcsr_kernels.h stays a header a CUDA backend can call (no STL, no PETSc, no host-only
// calls). Compiled by the CTest case cuda_kernels_compile when nvcc is found; CI has no GPU, so this is a
// compile check (the same bodies are tested on the CPU; the whole-storage kernels of binbcsr_cuda.cuh
// were run and checked on an H100 by examples/gpu/, docs/gpu.md; its symmetric product was not).
#include "mat_binbcsr/kernels/binbcsr_kernels.h"
#include "mat_binbcsr/kernels/cuda/binbcsr_cuda.cuh" /* the CUDA body set, run by examples/gpu/ */
#include "ksp_mcg/mcg_device.cuh"                    /* the merged CG on the device */

namespace binbcsr_device_check {

// The COO refill: one thread per stored value.
__global__ void coo_refill(const double *coo_v, long n, const double *recv, const int *jmap, const int *perm,
                           long nv, double *val)
{
  const long v = (long)blockIdx.x * blockDim.x + threadIdx.x;
  if (v < nv) val[v] = binbcsr::coo_gather<int>(coo_v, n, recv, jmap, perm, v);
}

// Instantiations: block sizes 1 and 3, double and single storage.
} // namespace binbcsr_device_check

template __global__ void binbcsr::cuda::sym_bin_mult<3, double>(const double *, const int *, const int *,
                                                                const int *, int, int, int, const double *,
                                                                double *);
template __global__ void binbcsr::cuda::sym_bin_mult<3, float>(const float *, const int *, const int *,
                                                               const int *, int, int, int, const double *,
                                                               double *);

// The kernels of binbcsr_cuda.cuh for block sizes 1 and 3 in both precisions (the GPU benchmark
// instantiates the ones it runs; these are the rest a backend would need).
template __global__ void binbcsr::cuda::bin_mult<1, double>(const double *, const int *, const int *, int,
                                                            int, const double *, double *);
template __global__ void binbcsr::cuda::bin_mult_rows<1, float>(const float *, const int *, const int *, int,
                                                                int, const double *, double *);
template __global__ void binbcsr::cuda::bin_mult_split8<1, double>(const double *, const int *, const int *,
                                                                   int, const double *, double *);
