// Helpers of binbcsr_gpu_bench.cu: error checks, transfers, timing, the host reference product,
// the table rows and the cuSPARSE baseline rows. Included by that one program only.
#ifndef BINBCSR_GPU_BENCH_UTIL_CUH
#define BINBCSR_GPU_BENCH_UTIL_CUH

#include "bench_matrices.h"

#include <cublas_v2.h>
#include <cuda_runtime.h>
#include <cusparse.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {
using namespace gpu_bench;

void fail(const char *what, const char *file, int line)
{
  std::fprintf(stderr, "%s:%d: %s\n", file, line, what);
  std::exit(2);
}
#define CK(call)                                                             \
  do {                                                                       \
    cudaError_t e_ = (call);                                                 \
    if (e_ != cudaSuccess) fail(cudaGetErrorString(e_), __FILE__, __LINE__); \
  } while (0)
#define CKS(call)                                                                            \
  do {                                                                                       \
    cusparseStatus_t e_ = (call);                                                            \
    if (e_ != CUSPARSE_STATUS_SUCCESS) fail(cusparseGetErrorString(e_), __FILE__, __LINE__); \
  } while (0)
#define CKB(call)                                                         \
  do {                                                                    \
    if ((call) != CUBLAS_STATUS_SUCCESS) fail(#call, __FILE__, __LINE__); \
  } while (0)
#define CKL() CK(cudaGetLastError())

int  failures   = 0;
bool check_only = false; /* -check_only: every kernel once and checked, nothing timed (sanitizers) */

template <typename T> T *to_device(const std::vector<T> &h)
{
  T *d = nullptr;
  CK(cudaMalloc(&d, std::max<size_t>(h.size(), 1) * sizeof(T)));
  if (!h.empty()) CK(cudaMemcpy(d, h.data(), h.size() * sizeof(T), cudaMemcpyHostToDevice));
  return d;
}
template <typename T> std::vector<T> to_host(const T *d, size_t n)
{
  std::vector<T> h(n);
  CK(cudaMemcpy(h.data(), d, n * sizeof(T), cudaMemcpyDeviceToHost));
  return h;
}

// Seconds per call of f: the median over 7 batches of events around `per_batch` calls, after a warm-up.
template <class F> double time_per_call(F &&f, int per_batch)
{
  if (check_only) return NAN;
  cudaEvent_t a, b;
  CK(cudaEventCreate(&a));
  CK(cudaEventCreate(&b));
  for (int i = 0; i < 3; i++) f();
  CK(cudaDeviceSynchronize());
  std::vector<double> t;
  for (int rep = 0; rep < 7; rep++) {
    CK(cudaEventRecord(a));
    for (int i = 0; i < per_batch; i++) f();
    CK(cudaEventRecord(b));
    CK(cudaEventSynchronize(b));
    float ms = 0;
    CK(cudaEventElapsedTime(&ms, a, b));
    t.push_back(ms * 1e-3 / per_batch);
  }
  CK(cudaEventDestroy(a));
  CK(cudaEventDestroy(b));
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Calls per batch so that a batch takes about 20 ms (one timed call first).
template <class F> int batch_size(F &&f)
{
  const double one = time_per_call(f, 1);
  return (int)std::min(2000.0, std::max(5.0, 0.02 / std::max(one, 1e-7)));
}

__global__ void triad(long n, const double *__restrict__ a, const double *__restrict__ b,
                      double *__restrict__ c)
{
  for (long i = blockIdx.x * (long)blockDim.x + threadIdx.x; i < n; i += (long)gridDim.x * blockDim.x)
    c[i] = a[i] + 1.5 * b[i];
}

// STREAM triad over 3 arrays of 2^26 doubles (1.6 GB, far beyond L2): bytes read + written per second.
double triad_bandwidth()
{
  const long n = 1L << 26;
  double    *a, *b, *c;
  CK(cudaMalloc(&a, n * 8));
  CK(cudaMalloc(&b, n * 8));
  CK(cudaMalloc(&c, n * 8));
  CK(cudaMemset(a, 0, n * 8));
  CK(cudaMemset(b, 0, n * 8));
  const double t = time_per_call([&] { triad<<<132 * 16, 256>>>(n, a, b, c); }, 20);
  CKL();
  CK(cudaFree(a));
  CK(cudaFree(b));
  CK(cudaFree(c));
  return 3.0 * n * 8 / t;
}

// Host reference y = A x in double, and per row the scale sum_j |a_ij x_j| the errors are measured against.
void host_product(const ScalarCSR &S, const std::vector<double> &x, std::vector<double> &y,
                  std::vector<double> &scale)
{
  const size_t n = S.ptr.size() - 1;
  y.assign(n, 0.0);
  scale.assign(n, 0.0);
  for (size_t i = 0; i < n; i++)
    for (int p = S.ptr[i]; p < S.ptr[i + 1]; p++) {
      y[i] += S.val[p] * x[S.col[p]];
      scale[i] += std::fabs(S.val[p] * x[S.col[p]]);
    }
}

struct Row {
  std::string format;
  double      seconds, bytes, flops, error, bound;
};

// Checks y against the reference: max_i |y_i - ref_i| / scale_i <= bound (NaN fails: y was poisoned).
template <typename T>
double product_error(const T *dy, const std::vector<double> &ref, const std::vector<double> &scale)
{
  const std::vector<T> y = to_host(dy, ref.size());
  double               e = 0.0;
  for (size_t i = 0; i < ref.size(); i++) {
    const double d = std::fabs((double)y[i] - ref[i]) / std::max(scale[i], 1e-300);
    if (!(d <= e)) e = std::isnan(d) ? INFINITY : std::max(e, d);
  }
  return e;
}

void print_rows(const std::vector<Row> &rows, double bw_triad)
{
  const double csr = rows[0].seconds;
  std::printf("%-26s %9s %9s %8s %7s %7s %9s %9s %s\n", "format", "us", "GFlop/s", "GB/s", "%triad", "x csr",
              "error", "bound", "check");
  for (const Row &r : rows) {
    const bool ok = r.error <= r.bound;
    failures += !ok;
    std::printf("%-26s %9.2f %9.1f %8.1f %7.1f %7.2f %9.1e %9.1e %s\n", r.format.c_str(), r.seconds * 1e6,
                r.flops / r.seconds * 1e-9, r.bytes / r.seconds * 1e-9,
                100.0 * r.bytes / r.seconds / bw_triad, csr / r.seconds, r.error, r.bound,
                ok ? "ok" : "FAIL");
  }
}

// One product row of the table: y poisoned with NaN (an entry the product does not write fails the
// check), one checked run, then the timing.
template <typename T, class F>
Row measure_product(const char *name, F &&run, T *dy, long n, double bytes, double flops,
                    const std::vector<double> &ref, const std::vector<double> &scale, double bound)
{
  CK(cudaMemset(dy, 0xFF, n * sizeof(T)));
  run();
  CKL();
  CK(cudaDeviceSynchronize());
  const double error = product_error(dy, ref, scale);
  return Row{name, time_per_call(run, batch_size(run)), bytes, flops, error, bound};
}

// cuSPARSE SpMV through the generic API, in T (x, y and values all T).
template <typename T>
Row cusparse_row(cusparseHandle_t h, cusparseSpMatDescr_t mat, const char *name, double matrix_bytes,
                 double flops, long n, const std::vector<double> &x, const std::vector<double> &ref,
                 const std::vector<double> &scale, double bound, cusparseSpMVAlg_t alg)
{
  const cudaDataType dt = sizeof(T) == 8 ? CUDA_R_64F : CUDA_R_32F;
  std::vector<T>     xt(x.begin(), x.end());
  T                 *dx = to_device(xt), *dy;
  CK(cudaMalloc(&dy, n * sizeof(T)));
  cusparseDnVecDescr_t vx, vy;
  CKS(cusparseCreateDnVec(&vx, n, dx, dt));
  CKS(cusparseCreateDnVec(&vy, n, dy, dt));
  const T one = 1, zero = 0;
  size_t  buf_size = 0;
  void   *buf      = nullptr;
  CKS(cusparseSpMV_bufferSize(h, CUSPARSE_OPERATION_NON_TRANSPOSE, &one, mat, vx, &zero, vy, dt, alg,
                              &buf_size));
  CK(cudaMalloc(&buf, std::max<size_t>(buf_size, 8)));
  auto run = [&] {
    CKS(cusparseSpMV(h, CUSPARSE_OPERATION_NON_TRANSPOSE, &one, mat, vx, &zero, vy, dt, alg, buf));
  };
  Row r = measure_product(name, run, dy, n, matrix_bytes + 2.0 * n * sizeof(T), flops, ref, scale, bound);
  CKS(cusparseDestroyDnVec(vx));
  CKS(cusparseDestroyDnVec(vy));
  CK(cudaFree(buf));
  CK(cudaFree(dx));
  CK(cudaFree(dy));
  return r;
}

} // namespace

#endif
