/* The one host/device function marker of the project: kernels that a CPU loop and a CUDA (or HIP)
   kernel both call are written once and declared BINBCSR_HD (an inline function on the host, an
   inlined __host__ __device__ function under nvcc). */
#ifndef BINBCSR_HD_H
#define BINBCSR_HD_H

#if defined(__CUDACC__) || defined(__HIPCC__)
  #define BINBCSR_HD __host__ __device__ __forceinline__
#else
  #define BINBCSR_HD inline
#endif

#endif
