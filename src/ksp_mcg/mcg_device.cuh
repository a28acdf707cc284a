/*
   KSPMCG's merged CG (Jacobi preconditioner) on a GPU: the vector updates of an iteration as CUDA
   kernels that call the per-index updates of mcg_kernels.h, the same code the CPU solver runs
   (mcg_solve.cpp). The products come from the matrix's CUDA body set
   (src/mat_binbcsr/kernels/cuda/binbcsr_cuda.cuh). No PETSc (Debian's PETSc has no CUDA):
   examples/gpu/ drives them directly.

   3 launches per iteration and no host synchronisation:
     1. q = A p and the partial sums of p.q           (binbcsr::cuda::bin_mult_dot, into s->pq)
     2. x += a p, r -= a q, z = D^-1 r, partial r.z   (mcg_update; a = rz / pq read on the device)
     3. p = z + b p                                    (mcg_direction; b = rz_new / rz)
*/
#ifndef BINBCSR_MCG_DEVICE_CUH
#define BINBCSR_MCG_DEVICE_CUH

#include "mcg_kernels.h"
#include "../mat_binbcsr/kernels/cuda/binbcsr_cuda.cuh"

namespace binbcsr {
namespace cuda {

/* Scalars of one merged-CG solve, on the device. */
struct MCGScalars {
  double   rz[2];  /* r.z of the current and the next iteration (parity of the iteration picks) */
  double   pq;     /* p.A p of this iteration */
  unsigned ticket; /* finish_sum's counter */
};

/* 2. With a = rz / pq: x += a p, r -= a q, then z = dinv r and r.z of the new residual
   (mcg_precondition_index) into s->rz[1 - cur] (and hist). Grid-stride over the n entries. */
__global__ void __launch_bounds__(block_threads)
  mcg_update(int n, int cur, const double *__restrict__ dinv, const double *__restrict__ p,
             const double *__restrict__ q, double *__restrict__ x, double *__restrict__ r,
             double *__restrict__ z, double *partials, MCGScalars *s, double *hist)
{
  const double a = s->pq > 0.0 ? s->rz[cur] / s->pq : 0.0; /* p = 0: converged exactly, stay */
  double       d = 0.0, rr = 0.0, zz = 0.0;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    x[i] += a * p[i];
    r[i] -= a * q[i];
    mcg_precondition_index<true, double>(i, r, dinv, z, d, rr, zz);
  }
  finish_sum(block_sum(d), partials, &s->ticket, &s->rz[1 - cur], hist);
}

/* Start from x = 0: r = b, z = dinv b, p = z, r.z into s->rz[0] (and hist). */
__global__ void __launch_bounds__(block_threads)
  mcg_start(int n, const double *__restrict__ dinv, const double *__restrict__ rhs, double *__restrict__ x,
            double *__restrict__ r, double *__restrict__ z, double *__restrict__ p, double *partials,
            MCGScalars *s, double *hist)
{
  double d = 0.0, rr = 0.0, zz = 0.0;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    x[i] = 0.0;
    r[i] = rhs[i];
    mcg_precondition_index<true, double>(i, r, dinv, z, d, rr, zz);
    p[i] = z[i];
  }
  finish_sum(block_sum(d), partials, &s->ticket, &s->rz[0], hist);
}

/* 3. p = z + b p with b = rz[next] / rz[cur]. */
__global__ void __launch_bounds__(block_threads)
  mcg_direction(int n, int cur, const double *__restrict__ z, double *__restrict__ p, const MCGScalars *s)
{
  const double beta = s->rz[cur] > 0.0 ? s->rz[1 - cur] / s->rz[cur] : 0.0;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x)
    p[i] = z[i] + beta * p[i];
}

} // namespace cuda
} // namespace binbcsr

#endif
