// BIN-(B)CSR and the merged CG on a GPU, against cuSPARSE and a stock CG (cuSPARSE + cuBLAS): the
// seed's Fig. 2.42 (SpMV GFlop/s per format and matrix) and Fig. 2.43 (CG speed-up over matrix size)
// with this project's matrices. Standalone (no PETSc: Debian's PETSc has no CUDA): it builds the bins
// with src/mat_binbcsr/kernels/binbcsr_layout.h and runs the lane kernels of binbcsr_kernels.h through
// src/mat_binbcsr/kernels/cuda/binbcsr_cuda.cuh. Every product is checked against a double-precision product
// on the host, every CG against the stock CG's residual history; a failed check exits non-zero.
//
//   binbcsr_gpu_bench [-stencil 16,32,64] [-f A.bin [-f B.bin ...]] [-bs 3] [-cg_its 1000] [-no_cg] [-no_triad] [-check_only]
//
// -check_only runs every kernel once with its checks and times nothing (for compute-sanitizer).
// -f reads a PETSc binary matrix (what the drivers write with -dump_matrix), grouped into bs x bs
// blocks. Stencil matrices are 27-point block stencils on n^3 nodes, symmetric and diagonally dominant.
// Build: scripts/gpu_bench (nvcc; links cuSPARSE and cuBLAS).
#include "bench_matrices.h"
#include "ksp_mcg/mcg_device.cuh" /* the merged CG; includes the matrix kernels, mat_binbcsr/kernels/cuda/binbcsr_cuda.cuh */

#include <cublas_v2.h>
#include <cuda_runtime.h>
#include <cusparse.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "gpu_bench_util.cuh"

namespace {
using namespace gpu_bench;

// Our product: bins in V, x and y in double.
template <int BS, typename V>
Row bin_row(const Bins<V> &B, bool per_row, const char *name, double flops, const std::vector<double> &x,
            const std::vector<double> &ref, const std::vector<double> &scale, double bound)
{
  const long n  = (long)B.mbs * BS;
  V         *dv = to_device(B.val);
  int       *dc = to_device(B.col), *ds = to_device(B.start);
  double    *dx = to_device(x), *dy;
  CK(cudaMalloc(&dy, n * 8));
  const int bt = binbcsr::cuda::block_threads, lanes_blocks = (B.mbs + bt - 1) / bt,
            rows_blocks  = (int)((binbcsr::cuda::rows_threads(B.mbs, B.bw, BS) + bt - 1) / bt);
  const int split_blocks = (int)((binbcsr::cuda::split_threads(B.mbs, BS) + bt - 1) / bt);
  auto      run          = [&] {
    if (per_row && B.bw == 8)
      binbcsr::cuda::bin_mult_split8<BS, V><<<split_blocks, bt>>>(dv, dc, ds, B.mbs, dx, dy);
    else if (per_row)
      binbcsr::cuda::bin_mult_rows<BS, V><<<rows_blocks, bt>>>(dv, dc, ds, B.mbs, B.bw, dx, dy);
    else binbcsr::cuda::bin_mult<BS, V><<<lanes_blocks, bt>>>(dv, dc, ds, B.mbs, B.bw, dx, dy);
  };
  const double bytes = (double)B.val.size() * sizeof(V) + 4.0 * (B.col.size() + B.start.size()) + 16.0 * n;
  Row          r     = measure_product(name, run, dy, n, bytes, flops, ref, scale, bound);
  CK(cudaFree(dv));
  CK(cudaFree(dc));
  CK(cudaFree(ds));
  CK(cudaFree(dx));
  CK(cudaFree(dy));
  return r;
}

void spmv_table(const BlockMatrix &A, const ScalarCSR &S, cusparseHandle_t h, double bw_triad)
{
  const long   n = A.n(), nnz = (long)S.col.size();
  const double flops = 2.0 * nnz, eps32 = std::ldexp(1.0, -24);
  int          maxrow = 0, minrow = 1 << 30;
  for (int r = 0; r < A.mbs; r++) {
    maxrow = std::max(maxrow, A.ptr[r + 1] - A.ptr[r]);
    minrow = std::min(minrow, A.ptr[r + 1] - A.ptr[r]);
  }
  std::vector<double> x(n), ref, scale;
  for (long i = 0; i < n; i++) x[i] = unit_random(0xABCDEFULL + i);
  host_product(S, x, ref, scale);
  const double b64 = 1e-12, b32 = (double)(maxrow * A.bs + 2) * eps32, bstore32 = 2 * eps32;

  std::vector<Row> rows;
  // cuSPARSE CSR
  int                 *dptr = to_device(S.ptr), *dcol = to_device(S.col);
  double              *dval = to_device(S.val);
  std::vector<float>   sval32(S.val.begin(), S.val.end());
  float               *dval32 = to_device(sval32);
  cusparseSpMatDescr_t m;
  const double         csr_bytes64 = 12.0 * nnz + 4.0 * (n + 1), csr_bytes32 = 8.0 * nnz + 4.0 * (n + 1);
  CKS(cusparseCreateCsr(&m, n, n, nnz, dptr, dcol, dval, CUSPARSE_INDEX_32I, CUSPARSE_INDEX_32I,
                        CUSPARSE_INDEX_BASE_ZERO, CUDA_R_64F));
  rows.push_back(cusparse_row<double>(h, m, "cusparse csr double", csr_bytes64, flops, n, x, ref, scale, b64,
                                      CUSPARSE_SPMV_CSR_ALG1));
  CKS(cusparseDestroySpMat(m));
  CKS(cusparseCreateCsr(&m, n, n, nnz, dptr, dcol, dval32, CUSPARSE_INDEX_32I, CUSPARSE_INDEX_32I,
                        CUSPARSE_INDEX_BASE_ZERO, CUDA_R_32F));
  rows.push_back(cusparse_row<float>(h, m, "cusparse csr single", csr_bytes32, flops, n, x, ref, scale, b32,
                                     CUSPARSE_SPMV_CSR_ALG1));
  CKS(cusparseDestroySpMat(m));
  CK(cudaFree(dval));
  CK(cudaFree(dval32));
  CK(cudaFree(dptr));
  CK(cudaFree(dcol));
  // cuSPARSE BSR (block rows as A, row-major blocks)
  if (A.bs > 1) {
    int               *bptr = to_device(A.ptr), *bcol = to_device(A.col);
    double            *bval = to_device(A.val);
    std::vector<float> bv32(A.val.begin(), A.val.end());
    float             *bval32      = to_device(bv32);
    const double       bsr_bytes64 = 8.0 * A.val.size() + 4.0 * (A.col.size() + A.ptr.size()),
                 bsr_bytes32       = 4.0 * A.val.size() + 4.0 * (A.col.size() + A.ptr.size());
    CKS(cusparseCreateBsr(&m, A.mbs, A.mbs, A.nblocks(), A.bs, A.bs, bptr, bcol, bval, CUSPARSE_INDEX_32I,
                          CUSPARSE_INDEX_32I, CUSPARSE_INDEX_BASE_ZERO, CUDA_R_64F, CUSPARSE_ORDER_ROW));
    rows.push_back(cusparse_row<double>(h, m, "cusparse bsr double", bsr_bytes64, flops, n, x, ref, scale,
                                        b64, CUSPARSE_SPMV_BSR_ALG1));
    CKS(cusparseDestroySpMat(m));
    CKS(cusparseCreateBsr(&m, A.mbs, A.mbs, A.nblocks(), A.bs, A.bs, bptr, bcol, bval32, CUSPARSE_INDEX_32I,
                          CUSPARSE_INDEX_32I, CUSPARSE_INDEX_BASE_ZERO, CUDA_R_32F, CUSPARSE_ORDER_ROW));
    rows.push_back(cusparse_row<float>(h, m, "cusparse bsr single", bsr_bytes32, flops, n, x, ref, scale, b32,
                                       CUSPARSE_SPMV_BSR_ALG1));
    CKS(cusparseDestroySpMat(m));
    CK(cudaFree(bptr));
    CK(cudaFree(bcol));
    CK(cudaFree(bval));
    CK(cudaFree(bval32));
  }
  // cuSPARSE sliced ELL, slice 32 (padding column -1): the nearest cuSPARSE format to BIN-CSR
  {
    const int           slice = 32, nslices = (int)((n + slice - 1) / slice);
    std::vector<int>    off(nslices + 1, 0), scol;
    std::vector<double> sval;
    for (int sl = 0; sl < nslices; sl++) {
      int len = 0;
      for (long r = (long)sl * slice; r < std::min(n, (long)(sl + 1) * slice); r++)
        len = std::max(len, S.ptr[r + 1] - S.ptr[r]);
      off[sl + 1] = off[sl] + len * slice;
    }
    scol.assign(off[nslices], -1);
    sval.assign(off[nslices], 0.0);
    for (long r = 0; r < n; r++)
      for (int k = 0; k < S.ptr[r + 1] - S.ptr[r]; k++) {
        const long at = off[r / slice] + (long)k * slice + r % slice;
        scol[at]      = S.col[S.ptr[r] + k];
        sval[at]      = S.val[S.ptr[r] + k];
      }
    std::vector<float> sv32(sval.begin(), sval.end());
    int               *doff = to_device(off), *dsc = to_device(scol);
    double            *dsv          = to_device(sval);
    float             *dsv32        = to_device(sv32);
    const double       sell_bytes64 = 12.0 * scol.size() + 4.0 * off.size(),
                 sell_bytes32       = 8.0 * scol.size() + 4.0 * off.size();
    CKS(cusparseCreateSlicedEll(&m, n, n, nnz, (int64_t)scol.size(), slice, doff, dsc, dsv,
                                CUSPARSE_INDEX_32I, CUSPARSE_INDEX_32I, CUSPARSE_INDEX_BASE_ZERO,
                                CUDA_R_64F));
    rows.push_back(cusparse_row<double>(h, m, "cusparse sell32 double", sell_bytes64, flops, n, x, ref, scale,
                                        b64, CUSPARSE_SPMV_SELL_ALG1));
    CKS(cusparseDestroySpMat(m));
    CKS(cusparseCreateSlicedEll(&m, n, n, nnz, (int64_t)scol.size(), slice, doff, dsc, dsv32,
                                CUSPARSE_INDEX_32I, CUSPARSE_INDEX_32I, CUSPARSE_INDEX_BASE_ZERO,
                                CUDA_R_32F));
    rows.push_back(cusparse_row<float>(h, m, "cusparse sell32 single", sell_bytes32, flops, n, x, ref, scale,
                                       b32, CUSPARSE_SPMV_SELL_ALG1));
    CKS(cusparseDestroySpMat(m));
    CK(cudaFree(doff));
    CK(cudaFree(dsc));
    CK(cudaFree(dsv));
    CK(cudaFree(dsv32));
  }
  // Ours: BIN-CSR (scalars, bin width 32) and BIN-BCSR (3x3 blocks, bin widths 32, 16, 8)
  double pad_csr = 0, pad_bcsr32 = 0;
  {
    const auto B = make_bins<double>(S.ptr, S.col, S.val, 1, (int)n, 32);
    pad_csr      = 100.0 * ((double)B.nslots() / nnz - 1.0);
    rows.push_back(bin_row<1, double>(B, false, "bin-csr double (bw 32)", flops, x, ref, scale, b64));
    const auto F = make_bins<float>(S.ptr, S.col, S.val, 1, (int)n, 32);
    rows.push_back(bin_row<1, float>(F, false, "bin-csr single (bw 32)", flops, x, ref, scale, bstore32));
  }
  if (A.bs == 3)
    for (int bw : {32, 16, 8}) {
      const auto        B    = make_bins<double>(A.ptr, A.col, A.val, 3, A.mbs, bw);
      const auto        F    = make_bins<float>(A.ptr, A.col, A.val, 3, A.mbs, bw);
      const std::string tail = bw == 8 ? ", split 4)" : ")",
                        d    = "bin-bcsr double (bw " + std::to_string(bw) + tail,
                        s    = "bin-bcsr single (bw " + std::to_string(bw) + tail;
      if (bw == 32) pad_bcsr32 = 100.0 * ((double)B.nslots() / A.nblocks() - 1.0);
      rows.push_back(bin_row<3, double>(B, true, d.c_str(), flops, x, ref, scale, b64));
      rows.push_back(bin_row<3, float>(F, true, s.c_str(), flops, x, ref, scale, bstore32));
      if (bw == 32) { /* one thread per lane for all 3 point rows: a third of the threads */
        rows.push_back(
          bin_row<3, double>(B, false, "bin-bcsr double, lane/thread", flops, x, ref, scale, b64));
        rows.push_back(
          bin_row<3, float>(F, false, "bin-bcsr single, lane/thread", flops, x, ref, scale, bstore32));
      }
    }
  std::printf(
    "\n== %s: %ld rows, %ld nonzeros (%ld blocks of %dx%d), block row length %d..%d (avg %.1f), padding bin-csr %.1f%%, bin-bcsr (bw 32) %.1f%%\n",
    A.name.c_str(), n, nnz, A.nblocks(), A.bs, A.bs, minrow, maxrow, (double)A.nblocks() / A.mbs, pad_csr,
    pad_bcsr32);
  print_rows(rows, bw_triad);
}

// ---------------------------------------------------------------------------------------------------
// CG, Jacobi-preconditioned, from x = 0, a fixed number of iterations.

__global__ void pointwise_mult(int n, const double *__restrict__ a, const double *__restrict__ b,
                               double *__restrict__ c)
{
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) c[i] = a[i] * b[i];
}

struct CGResult {
  double              seconds_per_it;
  std::vector<double> rz; /* r.z after each iteration (index 0: the start) */
};

// Stock CG as a PETSc user gets it on a GPU (KSPCG + PCJACOBI on aijcusparse): cuSPARSE CSR SpMV (or
// the BIN-BCSR kernel with bins != nullptr), cuBLAS dots that return to the host, axpys, a Jacobi
// kernel: 8 launches and 2 host synchronisations per iteration.
template <typename V>
CGResult stock_cg(cusparseHandle_t sh, cublasHandle_t bh, const ScalarCSR &S, const Bins<V> *bins,
                  const std::vector<double> &dinv_h, const std::vector<double> &b_h, int its)
{
  const int n    = (int)dinv_h.size();
  double   *dinv = to_device(dinv_h), *b = to_device(b_h), *x, *r, *z, *p, *q;
  for (double **v : {&x, &r, &z, &p, &q}) CK(cudaMalloc(v, n * 8));
  int                 *dptr = nullptr, *dcol = nullptr, *bc = nullptr, *bst = nullptr;
  double              *dval = nullptr;
  V                   *bv   = nullptr;
  cusparseSpMatDescr_t m    = nullptr;
  cusparseDnVecDescr_t vp = nullptr, vq = nullptr;
  void                *buf = nullptr;
  const double         one = 1.0, zero = 0.0;
  if (!bins) {
    dptr = to_device(S.ptr);
    dcol = to_device(S.col);
    dval = to_device(S.val);
    CKS(cusparseCreateCsr(&m, n, n, (int64_t)S.col.size(), dptr, dcol, dval, CUSPARSE_INDEX_32I,
                          CUSPARSE_INDEX_32I, CUSPARSE_INDEX_BASE_ZERO, CUDA_R_64F));
    CKS(cusparseCreateDnVec(&vp, n, p, CUDA_R_64F));
    CKS(cusparseCreateDnVec(&vq, n, q, CUDA_R_64F));
    size_t sz = 0;
    CKS(cusparseSpMV_bufferSize(sh, CUSPARSE_OPERATION_NON_TRANSPOSE, &one, m, vp, &zero, vq, CUDA_R_64F,
                                CUSPARSE_SPMV_CSR_ALG1, &sz));
    CK(cudaMalloc(&buf, std::max<size_t>(sz, 8)));
  } else {
    bv  = to_device(bins->val);
    bc  = to_device(bins->col);
    bst = to_device(bins->start);
  }
  const int vb   = std::min((n + 255) / 256, 132 * 8);
  auto      spmv = [&] {
    if (!bins)
      CKS(cusparseSpMV(sh, CUSPARSE_OPERATION_NON_TRANSPOSE, &one, m, vp, &zero, vq, CUDA_R_64F,
                            CUSPARSE_SPMV_CSR_ALG1, buf));
    else
      binbcsr::cuda::bin_mult_rows<3, V>
        <<<(int)((binbcsr::cuda::rows_threads(bins->mbs, bins->bw, 3) + 255) / 256), 256>>>(
          bv, bc, bst, bins->mbs, bins->bw, p, q);
  };
  CGResult res;
  auto     solve = [&](bool record) {
    double rz, pq;
    CK(cudaMemcpy(r, b, n * 8, cudaMemcpyDeviceToDevice));
    CK(cudaMemset(x, 0, n * 8));
    pointwise_mult<<<vb, 256>>>(n, dinv, r, z);
    CK(cudaMemcpy(p, z, n * 8, cudaMemcpyDeviceToDevice));
    CKB(cublasDdot(bh, n, r, 1, z, 1, &rz));
    if (record) res.rz.assign(1, rz);
    for (int it = 0; it < its; it++) {
      spmv();
      CKB(cublasDdot(bh, n, p, 1, q, 1, &pq));
      const double a  = pq > 0.0 ? rz / pq : 0.0,
                   ma = -a; /* the merged CG's guards: p = 0 once converged exactly */
      CKB(cublasDaxpy(bh, n, &a, p, 1, x, 1));
      CKB(cublasDaxpy(bh, n, &ma, q, 1, r, 1));
      pointwise_mult<<<vb, 256>>>(n, dinv, r, z);
      double rz_new;
      CKB(cublasDdot(bh, n, r, 1, z, 1, &rz_new));
      const double beta = rz > 0.0 ? rz_new / rz : 0.0;
      CKB(cublasDscal(bh, n, &beta, p, 1));
      CKB(cublasDaxpy(bh, n, &one, z, 1, p, 1));
      rz = rz_new;
      if (record) res.rz.push_back(rz);
    }
  };
  solve(true);
  CKL();
  res.seconds_per_it = time_per_call([&] { solve(false); }, 3) / its;
  if (m) {
    CKS(cusparseDestroySpMat(m));
    CKS(cusparseDestroyDnVec(vp));
    CKS(cusparseDestroyDnVec(vq));
  }
  for (void *v : {(void *)dinv, (void *)b, (void *)x, (void *)r, (void *)z, (void *)p, (void *)q,
                  (void *)dptr, (void *)dcol, (void *)dval, (void *)bv, (void *)bc, (void *)bst, buf})
    CK(cudaFree(v));
  return res;
}

// The merged CG with BIN-BCSR: 3 launches per iteration, no host synchronisation until the end; with
// graph, the whole fixed-iteration solve is captured once and replayed as one launch.
template <typename V>
CGResult merged_cg(const Bins<V> &B, const std::vector<double> &dinv_h, const std::vector<double> &b_h,
                   int its, bool graph)
{
  namespace bc   = binbcsr::cuda;
  const int n    = (int)dinv_h.size();
  double   *dinv = to_device(dinv_h), *b = to_device(b_h), *x, *r, *z, *p, *q, *partials, *hist;
  for (double **v : {&x, &r, &z, &p, &q}) CK(cudaMalloc(v, n * 8));
  V        *dv = to_device(B.val);
  int      *dc = to_device(B.col), *ds = to_device(B.start);
  const int sb = (int)(((B.bw == 8 ? bc::split_threads(B.mbs, 3) : bc::rows_threads(B.mbs, B.bw, 3)) +
                        bc::block_threads - 1) /
                       bc::block_threads),
            vb = std::min((n + bc::block_threads - 1) / bc::block_threads, 132 * 8);
  CK(cudaMalloc(&partials, std::max(sb, vb) * 8));
  CK(cudaMalloc(&hist, (its + 1) * 8));
  bc::MCGScalars *s;
  CK(cudaMalloc(&s, sizeof(bc::MCGScalars)));
  CK(cudaMemset(s, 0, sizeof(bc::MCGScalars)));
  cudaStream_t st;
  CK(cudaStreamCreate(&st));
  auto enqueue = [&] {
    bc::mcg_start<<<vb, bc::block_threads, 0, st>>>(n, dinv, b, x, r, z, p, partials, s, hist);
    for (int it = 0; it < its; it++) {
      const int cur = it % 2;
      if (B.bw == 8)
        bc::bin_mult_dot_split8<3, V>
          <<<sb, bc::block_threads, 0, st>>>(dv, dc, ds, B.mbs, p, q, partials, &s->ticket, &s->pq);
      else
        bc::bin_mult_dot<3, V>
          <<<sb, bc::block_threads, 0, st>>>(dv, dc, ds, B.mbs, B.bw, p, q, partials, &s->ticket, &s->pq);
      bc::mcg_update<<<vb, bc::block_threads, 0, st>>>(n, cur, dinv, p, q, x, r, z, partials, s,
                                                       hist + it + 1);
      bc::mcg_direction<<<vb, bc::block_threads, 0, st>>>(n, cur, z, p, s);
    }
  };
  cudaGraphExec_t exec = nullptr;
  if (graph) {
    cudaGraph_t g;
    CK(cudaStreamBeginCapture(st, cudaStreamCaptureModeGlobal));
    enqueue();
    CK(cudaStreamEndCapture(st, &g));
    CK(cudaGraphInstantiate(&exec, g, 0));
    CK(cudaGraphDestroy(g));
  }
  auto solve = [&] {
    if (graph) CK(cudaGraphLaunch(exec, st));
    else enqueue();
  };
  CK(cudaMemset(hist, 0xFF, (its + 1) * 8));
  solve();
  CK(cudaStreamSynchronize(st));
  CKL();
  CGResult res;
  res.rz = to_host(hist, its + 1);
  // time_per_call records on the default stream, which waits for st (legacy default stream semantics)
  res.seconds_per_it = time_per_call(solve, 3) / its;
  if (exec) CK(cudaGraphExecDestroy(exec));
  CK(cudaStreamDestroy(st));
  for (void *v : {(void *)dinv, (void *)b, (void *)x, (void *)r, (void *)z, (void *)p, (void *)q,
                  (void *)partials, (void *)hist, (void *)s, (void *)dv, (void *)dc, (void *)ds})
    CK(cudaFree(v));
  return res;
}

// Largest relative difference of sqrt(r.z) between two histories over the first `upto` iterations.
double history_difference(const std::vector<double> &a, const std::vector<double> &b, size_t upto)
{
  double d = 0.0;
  for (size_t i = 0; i < std::min({a.size(), b.size(), upto + 1}); i++) {
    const double e =
      std::fabs(std::sqrt(std::fabs(a[i])) - std::sqrt(std::fabs(b[i]))) / std::sqrt(std::fabs(b[i]));
    if (!(e <= d)) d = std::isnan(e) ? INFINITY : e;
  }
  return d;
}

void cg_table(const BlockMatrix &A, const ScalarCSR &S, cusparseHandle_t sh, cublasHandle_t bh, int its)
{
  const int           n = A.n();
  std::vector<double> dinv(n), b(n);
  for (int br = 0; br < A.mbs; br++)
    for (int p = A.ptr[br]; p < A.ptr[br + 1]; p++)
      if (A.col[p] == br)
        for (int i = 0; i < A.bs; i++)
          dinv[br * A.bs + i] = 1.0 / A.val[(size_t)p * A.bs * A.bs + i * A.bs + i];
  for (int i = 0; i < n; i++) b[i] = unit_random(0x5EEDULL + i);
  const auto     B32         = make_bins<double>(A.ptr, A.col, A.val, 3, A.mbs, 32);
  const auto     F32         = make_bins<float>(A.ptr, A.col, A.val, 3, A.mbs, 32);
  const auto     B8          = make_bins<double>(A.ptr, A.col, A.val, 3, A.mbs, 8);
  const auto     F8          = make_bins<float>(A.ptr, A.col, A.val, 3, A.mbs, 8);
  const CGResult stock       = stock_cg<double>(sh, bh, S, nullptr, dinv, b, its);
  const CGResult stock_bins  = stock_cg<double>(sh, bh, S, &B32, dinv, b, its);
  const CGResult mcg         = merged_cg<double>(B32, dinv, b, its, false);
  const CGResult mcg_graph   = merged_cg<double>(B32, dinv, b, its, true);
  const CGResult mcg_single  = merged_cg<float>(F32, dinv, b, its, true);
  const CGResult mcg8        = merged_cg<double>(B8, dinv, b, its, true);
  const CGResult mcg8_single = merged_cg<float>(F8, dinv, b, its, true);

  const size_t upto =
    30; /* residual histories of different summation orders drift apart slowly; compare the simulation's 30 */
  struct Line {
    const char     *name;
    const CGResult *r;
    double          bound;
  } lines[] = {{"stock cg, cusparse csr", &stock, 0},
               {"stock cg, bin-bcsr spmv", &stock_bins, 1e-8},
               {"merged cg, bin-bcsr", &mcg, 1e-8},
               {"merged cg, bin-bcsr, graph", &mcg_graph, 1e-8},
               {"merged cg, single, graph", &mcg_single, 1e-3},
               {"merged cg, bw 8 split, graph", &mcg8, 1e-8},
               {"merged cg, bw 8 split, single", &mcg8_single, 1e-3}};
  std::printf("\n-- CG (Jacobi, from zero, %d iterations) on %s: sqrt(r.z) %.3e -> %.3e\n", its,
              A.name.c_str(), std::sqrt(stock.rz.front()), std::sqrt(std::fabs(stock.rz.back())));
  std::printf("%-30s %12s %10s %22s %s\n", "solver", "us/iteration", "speed-up", "history diff (30 its)",
              "check");
  for (const Line &l : lines) {
    const double d  = history_difference(l.r->rz, stock.rz, upto);
    const bool   ok = l.r == &stock || d <= l.bound;
    failures += !ok;
    std::printf("%-30s %12.2f %10.2f %22.1e %s\n", l.name, l.r->seconds_per_it * 1e6,
                stock.seconds_per_it / l.r->seconds_per_it, d, ok ? "ok" : "FAIL");
  }
}

} // namespace

int main(int argc, char **argv)
{
  std::vector<int>         sizes;
  std::vector<std::string> files;
  int                      bs = 3, its = 1000;
  bool                     cg = true, triad_run = true;
  for (int i = 1; i < argc; i++) {
    const std::string a    = argv[i];
    auto              next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-stencil") {
      std::string v = next();
      for (size_t p = 0; p < v.size();) {
        size_t q = v.find(',', p);
        sizes.push_back(std::atoi(v.substr(p, q - p).c_str()));
        p = q == std::string::npos ? v.size() : q + 1;
      }
    } else if (a == "-f") files.push_back(next());
    else if (a == "-bs") bs = std::atoi(next().c_str());
    else if (a == "-cg_its") its = std::atoi(next().c_str());
    else if (a == "-no_cg") cg = false;
    else if (a == "-no_triad")
      triad_run = false; /* e.g. under compute-sanitizer, where 1.5 GB of triad takes minutes */
    else if (a == "-check_only") check_only = true, triad_run = false;
    else {
      std::fprintf(
        stderr,
        "unknown option %s\nusage: %s [-stencil 16,32] [-f A.bin]... [-bs 3] [-cg_its 1000] [-no_cg] [-no_triad] [-check_only]\n",
        a.c_str(), argv[0]);
      return 2;
    }
  }
  if (sizes.empty() && files.empty()) sizes = {16, 32, 64};
  cudaDeviceProp prop;
  CK(cudaGetDeviceProperties(&prop, 0));
  const double bw_triad = triad_run ? triad_bandwidth() : NAN;
  std::printf("device: %s, %d SMs, L2 %.0f MB; STREAM triad %.0f GB/s (3 x 512 MB arrays)\n", prop.name,
              prop.multiProcessorCount, prop.l2CacheSize / 1e6, bw_triad * 1e-9);
  std::printf(
    "bytes model: values + column indices + row/bin offsets + x read once + y written once; GFlop/s = 2 nnz / t\n");
  cusparseHandle_t sh;
  cublasHandle_t   bh;
  CKS(cusparseCreate(&sh));
  CKB(cublasCreate(&bh));
  std::vector<BlockMatrix> mats;
  for (int s : sizes) mats.push_back(stencil_matrix(s));
  for (const std::string &f : files) mats.push_back(read_matrix(f, bs));
  for (const BlockMatrix &A : mats) {
    const ScalarCSR S = scalar_csr(A);
    spmv_table(A, S, sh, bw_triad);
    if (cg && A.bs == 3) cg_table(A, S, sh, bh, its);
    std::fflush(stdout);
  }
  CKS(cusparseDestroy(sh));
  CKB(cublasDestroy(bh));
  std::printf("\n%s: %d check(s) failed\n", failures ? "FAIL" : "ok", failures);
  return failures ? 1 : 0;
}
