/* The cuda executor: the device library's bins, refill, products and merged CG as CUDA kernels that
   call the same bodies as the reference executor (binbcsr_kernels.h per lane or point row,
   mcg_kernels.h per index, device_bodies.h for the refill and the CG's scalar step), one thread per
   lane / row / index. Block sizes 1 and 3.

   Reductions: every pass writes one partial sum per block; one small kernel (one block) sums them in
   block order and runs the CG's scalar step, so every run gives the same bits and no host thread is
   involved. An iteration is 3 launches (update pass, product with u.w, finish); k iterations are one
   CUDA graph, replayed (a fixed-iteration solve: one graph of all its iterations, one copy at the end). */
#include "mcg_driver.h"
#include "reference.h"
#include "mat_binbcsr/kernels/cuda/binbcsr_cuda.cuh"

#include <cuda_runtime.h>
#include <map>
#include <stdexcept>
#include <tuple>

namespace binbcsr {
namespace device {
namespace {

constexpr int T = binbcsr::cuda::block_threads; /* 256 */

void ck(cudaError_t e, const char *what)
{
  if (e != cudaSuccess)
    throw std::runtime_error(std::string("cuda executor: ") + what + ": " + cudaGetErrorString(e));
}
#define CK(x) ck((x), #x)

template <typename X> struct DevBuf {
  X   *p   = nullptr;
  long n   = 0;
  DevBuf() = default;
  explicit DevBuf(long n_) { resize(n_); }
  DevBuf(const DevBuf &)            = delete;
  DevBuf &operator=(const DevBuf &) = delete;
  ~DevBuf() { cudaFree(p); }
  void resize(long n_)
  {
    if (n_ == n) return;
    cudaFree(p);
    p = nullptr;
    n = n_;
    if (n > 0) CK(cudaMalloc(&p, sizeof(X) * n));
  }
  void put(const X *h, long cnt) { CK(cudaMemcpy(p, h, sizeof(X) * cnt, cudaMemcpyHostToDevice)); }
  void get(X *h, long cnt) const { CK(cudaMemcpy(h, p, sizeof(X) * cnt, cudaMemcpyDeviceToHost)); }
};

class CudaVector : public Vector {
public:
  explicit CudaVector(long n) : d(n) { CK(cudaMemset(d.p, 0, sizeof(double) * n)); }
  long           size() const override { return d.n; }
  void           upload(const double *h) override { d.put(h, d.n); }
  void           download(double *h) const override { d.get(h, d.n); }
  DevBuf<double> d;
};
const double *dp(const Vector &x) { return static_cast<const CudaVector &>(x).d.p; }
double       *dp(Vector &x) { return static_cast<CudaVector &>(x).d.p; }

long blocks(long threads) { return (threads + T - 1) / T; }

/* ---- kernels ---------------------------------------------------------------------------------- */

template <typename V, bool ADD>
__global__ void __launch_bounds__(T) k_refill(V *val, const int *bin_start, int nbins, int bw, int bs2,
                                              const int *jmap, const int *perm, const double *coo, long ncoo)
{
  const long t = (long)blockIdx.x * blockDim.x + threadIdx.x;
  if (t < (long)nbins * bw)
    lane_refill<V, ADD>(val, bin_start, (int)(t / bw), (int)(t % bw), bw, bs2, jmap, perm, coo, ncoo);
}

/* Whole storage, y = A x and the block partials of x.y (partials may be null): bw 8 by the split8
   mapping (a warp per bin and point row), other widths one thread per point row of a lane. */
template <int BS, typename V, bool SPLIT>
__device__ __forceinline__ void
whole_body(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs,
           int bw, const double *__restrict__ x, double *__restrict__ y, double *partials)
{
  double d = 0.0;
  if (SPLIT) {
    int          row;
    const double s = binbcsr::cuda::bin_row_split8<BS, V>(val, col, bin_start, mbs, x, &row);
    if (row >= 0) {
      y[row] = s;
      d      = s * x[row];
    }
  } else {
    const long t = (long)blockIdx.x * blockDim.x + threadIdx.x;
    const int  b = (int)(t / (BS * bw)), i = (int)(t / bw % BS), lane = (int)(t % bw), r = b * bw + lane;
    if (r < mbs) {
      const int    s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
      const double s = lane_row_mult<BS, V, int>(val + (long)s0 * BS * BS, col + s0, len, bw, BS, lane, i, x);
      y[(long)r * BS + i] = s;
      d                   = s * x[(long)r * BS + i];
    }
  }
  if (partials) {
    const double bsum = binbcsr::cuda::block_sum(d);
    if (threadIdx.x == 0) partials[blockIdx.x] = bsum;
  }
}
template <int BS, typename V, bool SPLIT>
__global__ void __launch_bounds__(T)
  k_whole(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int mbs,
          int bw, const double *__restrict__ x, double *__restrict__ y, double *partials)
{
  whole_body<BS, V, SPLIT>(val, col, bin_start, mbs, bw, x, y, partials);
}

/* Symmetric storage: one warp per bin (bw <= 32), the per-slot bodies of sym_lane_mult; the scatters
   y_c += block^T x_r (into rows of other bins too) and the lane's own row are atomic adds into a
   zeroed y. */
template <int BS, typename V>
__global__ void __launch_bounds__(T)
  k_sym(const V *__restrict__ val, const int *__restrict__ col, const int *__restrict__ bin_start, int nbins,
        int mbs, int bw, const double *__restrict__ x, double *y)
{
  const int b = (int)(((long)blockIdx.x * blockDim.x + threadIdx.x) / 32), lane = threadIdx.x % 32;
  if (b >= nbins || lane >= bw) return;
  const int r = b * bw + lane, own = r < mbs ? r : mbs - 1, s0 = bin_start[b],
            len = (bin_start[b + 1] - s0) / bw;
  double acc[BS], xr[BS];
  for (int i = 0; i < BS; i++) {
    acc[i] = 0.0;
    xr[i]  = r < mbs ? x[(long)r * BS + i] : 0.0;
  }
  for (int k = 0; k < len; k++) {
    const long s = (long)s0 + (long)k * bw + lane;
    const int  c = col[s];
    const V   *t = val + ((long)s0 + (long)k * bw) * BS * BS + lane;
    slot_mult<BS, V>(t, bw, BS, x + (long)c * BS, acc);
    if (c != own) {
      double yc[BS];
      for (int j = 0; j < BS; j++) yc[j] = 0.0;
      slot_mult_transpose<BS, V>(t, bw, BS, xr, yc);
      for (int j = 0; j < BS; j++) atomicAdd(&y[(long)c * BS + j], yc[j]);
    }
  }
  if (r < mbs)
    for (int i = 0; i < BS; i++) atomicAdd(&y[(long)r * BS + i], acc[i]);
}

__global__ void __launch_bounds__(T) k_dot(long n, const double *x, const double *y, double *partials)
{
  double d = 0.0;
  for (long i = (long)blockIdx.x * blockDim.x + threadIdx.x; i < n; i += (long)gridDim.x * blockDim.x)
    d += x[i] * y[i];
  const double s = binbcsr::cuda::block_sum(d);
  if (threadIdx.x == 0) partials[blockIdx.x] = s;
}

/* out[c] = sum over b of partials[b * stride + c], c < count, in block order (one block). */
__device__ void sum_partials(const double *partials, int nparts, int stride, int count, double *out)
{
  for (int c = 0; c < count; c++) {
    double s = 0.0;
    for (int b = threadIdx.x; b < nparts; b += blockDim.x) s += partials[(long)b * stride + c];
    s = binbcsr::cuda::block_sum(s);
    if (threadIdx.x == 0) out[c] = s;
    __syncthreads();
  }
}
__global__ void __launch_bounds__(T) k_finish_dot(const double *partials, int nparts, double *out)
{
  sum_partials(partials, nparts, 1, 1, out);
}

/* r = b - r (after r = A x), or r = b and x = 0; p = s = 0. */
__global__ void __launch_bounds__(T)
  k_residual(long n, int zero, const double *b, double *x, double *r, double *p, double *s)
{
  for (long i = (long)blockIdx.x * blockDim.x + threadIdx.x; i < n; i += (long)gridDim.x * blockDim.x) {
    if (zero) {
      x[i] = 0.0;
      r[i] = b[i];
    } else r[i] = b[i] - r[i];
    p[i] = 0.0;
    s[i] = 0.0;
  }
}

/* The block's sums of r.u, r.r, u.u, x.x as its partials (stride 4, the order gather_dots reads). */
__device__ void store_block_sums(double ru, double rr, double uu, double xx, double *partials)
{
  const double v[4] = {ru, rr, uu, xx};
  for (int c = 0; c < 4; c++) {
    const double t = binbcsr::cuda::block_sum(v[c]);
    if (threadIdx.x == 0) partials[blockIdx.x * 4 + c] = t;
    __syncthreads(); /* block_sum's shared words are reused */
  }
}

/* u = M^-1 r and the partials of r.u, r.r, u.u (x.x: 0). */
template <bool J>
__global__ void __launch_bounds__(T)
  k_precondition(long n, const double *r, const double *dinv, double *u, double *partials)
{
  double ru = 0, rr = 0, uu = 0;
  for (long i = (long)blockIdx.x * blockDim.x + threadIdx.x; i < n; i += (long)gridDim.x * blockDim.x)
    mcg_precondition_index<J, double>(i, r, dinv, u, ru, rr, uu);
  store_block_sums(ru, rr, uu, 0.0, partials);
}

/* The iteration's vector pass (mcg_update_index), partials of r.u, r.r, u.u, x.x (stride 4). */
template <bool J>
__global__ void __launch_bounds__(T)
  k_update(long n, const MCGState *st, double *u, const double *w, double *p, double *s, double *x, double *r,
           const double *dinv, double *partials)
{
  if (st->done || st->want_verify) return;
  const double alpha = st->alpha, beta = st->beta;
  double       ru = 0, rr = 0, uu = 0, xx = 0;
  for (long i = (long)blockIdx.x * blockDim.x + threadIdx.x; i < n; i += (long)gridDim.x * blockDim.x)
    mcg_update_index<J, double>(i, alpha, beta, u, w, p, s, x, r, dinv, ru, rr, uu, xx);
  store_block_sums(ru, rr, uu, xx, partials);
}

/* Gathers the dots of a pass (vector partials: ru, rr, uu, xx; product partials: u.w) into MCG order. */
__device__ void gather_dots(const double *vp, int nvp, const double *pp, int npp, double *dots)
{
  __shared__ double v[4], w[1];
  sum_partials(vp, nvp, 4, 4, v);
  if (pp) sum_partials(pp, npp, 1, 1, w);
  else if (threadIdx.x == 0) w[0] = 0.0;
  __syncthreads();
  if (threadIdx.x == 0) {
    dots[MCG_DOT_RU] = v[0];
    dots[MCG_DOT_RR] = v[1];
    dots[MCG_DOT_UU] = v[2];
    dots[MCG_DOT_XX] = v[3];
    dots[MCG_DOT_UW] = w[0];
  }
}
/* kind 0: the start (mcg_start_step, and mcg_start_test when test); 1: an iteration (mcg_step);
   2: the true-residual check (mcg_verify_step); 3: the restart's u.w (mcg_restart_step). */
__global__ void __launch_bounds__(T) k_finish(int kind, int test, const double *vp, int nvp, const double *pp,
                                              int npp, MCGState *st, double *dots, double *hist)
{
  if (kind == 1 && (st->done || st->want_verify)) return;
  if (kind == 3) {
    __shared__ double w[1];
    sum_partials(pp, npp, 1, 1, w);
    if (threadIdx.x == 0 && st->fresh && !st->done) mcg_restart_step(*st, w[0], dots[MCG_DOT_UU]);
    return;
  }
  double d[MCG_NDOTS];
  gather_dots(vp, nvp, kind == 2 ? nullptr : pp, npp, dots);
  if (threadIdx.x != 0) return;
  for (int c = 0; c < MCG_NDOTS; c++) d[c] = dots[c];
  if (kind == 0) {
    mcg_start_step(*st, d, hist);
    if (test) mcg_start_test(*st);
  } else if (kind == 1) mcg_step(*st, d, hist);
  else mcg_verify_step(*st, d);
}

/* The product of a CG pass: w = A u with partials of u.w, skipped (u.w = 0) after the last iteration. */
template <int BS, typename V, bool SPLIT>
__global__ void __launch_bounds__(T)
  k_cg_product(const MCGState *st, const V *__restrict__ val, const int *__restrict__ col,
               const int *__restrict__ bin_start, int mbs, int bw, const double *__restrict__ u,
               double *__restrict__ w, double *partials)
{
  if (st->done || st->want_verify) return;
  if (st->its + 1 >= st->max_its) {
    if (threadIdx.x == 0) partials[blockIdx.x] = 0.0;
    return;
  }
  whole_body<BS, V, SPLIT>(val, col, bin_start, mbs, bw, u, w, partials);
}

/* ---- matrix ----------------------------------------------------------------------------------- */

template <typename V> class CudaMatrix : public Matrix {
public:
  CudaMatrix(const Layout &L, Precision p) : prec(p)
  {
    if (L.bs != 1 && L.bs != 3) throw std::invalid_argument("cuda executor: block sizes 1 and 3 only");
    if (L.bw < 1 || L.bw > 32 || L.mbs < 1)
      throw std::invalid_argument("cuda executor: needs 1 <= bw <= 32 and mbs >= 1");
    lay = L;
    h_bin_start.assign(L.bin_start, L.bin_start + L.nbins() + 1);
    d_bin_start.resize(h_bin_start.size());
    d_bin_start.put(h_bin_start.data(), h_bin_start.size());
    d_col.resize(L.nslots());
    d_col.put(L.col, L.nslots());
    lay.bin_start = h_bin_start.data();
    lay.col       = nullptr; /* on the device only */
    d_val.resize(L.nvalues());
    CK(cudaMemset(d_val.p, 0, sizeof(V) * L.nvalues()));
    CK(cudaStreamCreate(&stream));
    const long nprod = prod_blocks();
    d_pp.resize(nprod > 1 ? nprod : 1);
  }
  ~CudaMatrix() override
  {
    drop_graphs();
    cudaStreamDestroy(stream);
  }
  void drop_graphs()
  {
    for (auto &g : graphs) cudaGraphExecDestroy(g.second);
    graphs.clear();
  }
  const Layout &layout() const override { return lay; }
  Precision     precision() const override { return prec; }
  void          set_values(const double *v) override
  {
    std::vector<V> h(v, v + lay.nvalues());
    d_val.put(h.data(), lay.nvalues());
  }
  void get_values(double *v) const override
  {
    std::vector<V> h(lay.nvalues());
    d_val.get(h.data(), lay.nvalues());
    for (long i = 0; i < lay.nvalues(); i++) v[i] = (double)h[i];
  }
  void set_gather_map(const GatherMap &m) override
  {
    std::vector<int> jm(m.jmap, m.jmap + lay.nvalues() + 1);
    d_jmap.resize(jm.size());
    d_jmap.put(jm.data(), jm.size());
    d_perm.resize(jm.back() > 0 ? jm.back() : 1);
    if (jm.back() > 0) d_perm.put(m.perm, jm.back());
    d_coo.resize(m.ncoo > 0 ? m.ncoo : 1);
    ncoo = m.ncoo;
  }
  void refill(const double *coo, bool add) override
  {
    if (!d_jmap.p) throw std::logic_error("cuda executor: refill before set_gather_map");
    if (ncoo > 0) CK(cudaMemcpyAsync(d_coo.p, coo, sizeof(double) * ncoo, cudaMemcpyHostToDevice, stream));
    refill_device(d_coo.p, add);
    CK(cudaStreamSynchronize(stream));
  }
  /* the refill from COO values already on the device (the benchmark) */
  void refill_device(const double *coo, bool add)
  {
    const long th = (long)lay.nbins() * lay.bw;
    if (add)
      k_refill<V, true><<<blocks(th), T, 0, stream>>>(d_val.p, d_bin_start.p, lay.nbins(), lay.bw,
                                                      lay.bs * lay.bs, d_jmap.p, d_perm.p, coo, ncoo);
    else
      k_refill<V, false><<<blocks(th), T, 0, stream>>>(d_val.p, d_bin_start.p, lay.nbins(), lay.bw,
                                                       lay.bs * lay.bs, d_jmap.p, d_perm.p, coo, ncoo);
    CK(cudaGetLastError());
  }
  long prod_blocks() const
  {
    if (lay.symmetric) return blocks((long)lay.nbins() * 32);
    if (lay.bw == 8) return blocks(binbcsr::cuda::split_threads(lay.mbs, lay.bs));
    return blocks(binbcsr::cuda::rows_threads(lay.mbs, lay.bw, lay.bs));
  }
  /* y = A u on the stream, with the product partials of u.y in d_pp when dot */
  void launch_mult(const double *x, double *y, bool dot)
  {
    double *pp = dot ? d_pp.p : nullptr;
    if (lay.symmetric) {
      CK(cudaMemsetAsync(y, 0, sizeof(double) * lay.n(), stream));
      if (lay.bs == 3)
        k_sym<3, V><<<prod_blocks(), T, 0, stream>>>(d_val.p, d_col.p, d_bin_start.p, lay.nbins(), lay.mbs,
                                                     lay.bw, x, y);
      else
        k_sym<1, V><<<prod_blocks(), T, 0, stream>>>(d_val.p, d_col.p, d_bin_start.p, lay.nbins(), lay.mbs,
                                                     lay.bw, x, y);
      if (dot) k_dot<<<vec_blocks(), T, 0, stream>>>(lay.n(), x, y, pp);
    } else {
      const long nb = prod_blocks();
      if (lay.bs == 3 && lay.bw == 8)
        k_whole<3, V, true><<<nb, T, 0, stream>>>(d_val.p, d_col.p, d_bin_start.p, lay.mbs, 8, x, y, pp);
      else if (lay.bs == 3)
        k_whole<3, V, false>
          <<<nb, T, 0, stream>>>(d_val.p, d_col.p, d_bin_start.p, lay.mbs, lay.bw, x, y, pp);
      else if (lay.bw == 8)
        k_whole<1, V, true><<<nb, T, 0, stream>>>(d_val.p, d_col.p, d_bin_start.p, lay.mbs, 8, x, y, pp);
      else
        k_whole<1, V, false>
          <<<nb, T, 0, stream>>>(d_val.p, d_col.p, d_bin_start.p, lay.mbs, lay.bw, x, y, pp);
    }
    CK(cudaGetLastError());
  }
  int  dot_parts() const { return lay.symmetric ? vec_blocks() : (int)prod_blocks(); }
  int  vec_blocks() const { return (int)std::min<long>(blocks(lay.n()), 1024); }
  void mult(const Vector &x, Vector &y) override
  {
    launch_mult(dp(x), dp(y), false); /* asynchronous: a download or synchronize() waits for it */
  }
  double mult_dot(const Vector &x, Vector &y) override
  {
    DevBuf<double> out(1);
    launch_mult(dp(x), dp(y), true);
    k_finish_dot<<<1, T, 0, stream>>>(d_pp.p, dot_parts(), out.p);
    CK(cudaGetLastError());
    double d;
    CK(cudaStreamSynchronize(stream));
    out.get(&d, 1);
    return d;
  }
  /* the CG's product pass (w = A u, partials of u.w, skipped after the last iteration) */
  void launch_cg_product(const MCGState *st, const double *u, double *w)
  {
    if (lay.symmetric) { /* the state test is in the finish; the product of a finished solve is harmless */
      launch_mult(u, w, true);
      return;
    }
    const long nb = prod_blocks();
    if (lay.bs == 3 && lay.bw == 8)
      k_cg_product<3, V, true>
        <<<nb, T, 0, stream>>>(st, d_val.p, d_col.p, d_bin_start.p, lay.mbs, 8, u, w, d_pp.p);
    else if (lay.bs == 3)
      k_cg_product<3, V, false>
        <<<nb, T, 0, stream>>>(st, d_val.p, d_col.p, d_bin_start.p, lay.mbs, lay.bw, u, w, d_pp.p);
    else if (lay.bw == 8)
      k_cg_product<1, V, true>
        <<<nb, T, 0, stream>>>(st, d_val.p, d_col.p, d_bin_start.p, lay.mbs, 8, u, w, d_pp.p);
    else
      k_cg_product<1, V, false>
        <<<nb, T, 0, stream>>>(st, d_val.p, d_col.p, d_bin_start.p, lay.mbs, lay.bw, u, w, d_pp.p);
    CK(cudaGetLastError());
  }
  SolveResult solve(const Vector &dinv, const Vector &b, Vector &x, const SolveSettings &st) override;

  Layout           lay;
  Precision        prec;
  std::vector<int> h_bin_start;
  DevBuf<int>      d_bin_start, d_col, d_jmap, d_perm;
  DevBuf<V>        d_val;
  DevBuf<double>   d_coo, d_pp;
  long             ncoo = 0;
  cudaStream_t     stream{};
  /* the CG's workspace, kept between solves so that captured graphs stay valid */
  DevBuf<double>   r, u, w, p, s, vp, hist, dots;
  DevBuf<MCGState> state;
  std::map<std::tuple<int, const double *, const double *, double *, bool>, cudaGraphExec_t> graphs;
};

template <typename V> struct CudaOps {
  CudaMatrix<V> &A;
  const double  *dinv, *b;
  double        *x;
  bool           jacobi;
  long           n;
  int            nvb;

  void precondition()
  {
    if (jacobi) k_precondition<true><<<nvb, T, 0, A.stream>>>(n, A.r.p, dinv, A.u.p, A.vp.p);
    else k_precondition<false><<<nvb, T, 0, A.stream>>>(n, A.r.p, dinv, A.u.p, A.vp.p);
  }
  void residual(bool zero)
  {
    if (!zero) A.launch_mult(x, A.r.p, false);
    k_residual<<<nvb, T, 0, A.stream>>>(n, zero, b, x, A.r.p, A.p.p, A.s.p);
  }
  void start(bool guess_zero, bool test_on_device)
  {
    residual(guess_zero);
    precondition();
    A.launch_mult(A.u.p, A.w.p, true);
    k_finish<<<1, T, 0, A.stream>>>(0, test_on_device, A.vp.p, nvb, A.d_pp.p, A.dot_parts(), A.state.p,
                                    A.dots.p, A.hist.p);
    CK(cudaGetLastError());
  }
  void launch_iteration()
  {
    if (jacobi)
      k_update<true>
        <<<nvb, T, 0, A.stream>>>(n, A.state.p, A.u.p, A.w.p, A.p.p, A.s.p, x, A.r.p, dinv, A.vp.p);
    else
      k_update<false>
        <<<nvb, T, 0, A.stream>>>(n, A.state.p, A.u.p, A.w.p, A.p.p, A.s.p, x, A.r.p, dinv, A.vp.p);
    A.launch_cg_product(A.state.p, A.u.p, A.w.p);
    k_finish<<<1, T, 0, A.stream>>>(1, 0, A.vp.p, nvb, A.d_pp.p, A.dot_parts(), A.state.p, A.dots.p,
                                    A.hist.p);
  }
  void iterations(int k)
  {
    const auto key = std::make_tuple(k, dinv, b, x, jacobi);
    auto       it  = A.graphs.find(key);
    if (it == A.graphs.end()) {
      if (A.graphs.size() >= 16) A.drop_graphs(); /* solves with ever new vectors: keep a few */
      cudaGraph_t g;
      CK(cudaStreamBeginCapture(A.stream, cudaStreamCaptureModeThreadLocal));
      for (int t = 0; t < k; t++) launch_iteration();
      CK(cudaStreamEndCapture(A.stream, &g));
      cudaGraphExec_t e;
      CK(cudaGraphInstantiate(&e, g, 0));
      CK(cudaGraphDestroy(g));
      it = A.graphs.emplace(key, e).first;
    }
    CK(cudaGraphLaunch(it->second, A.stream));
  }
  void verify()
  {
    residual(false);
    precondition();
    k_finish<<<1, T, 0, A.stream>>>(2, 0, A.vp.p, nvb, nullptr, 0, A.state.p, A.dots.p, A.hist.p);
    CK(cudaGetLastError());
    MCGState s;
    get_state(s);
    if (!s.fresh || s.done) return; /* the claim stands, or no progress: no restart */
    CK(cudaMemsetAsync(A.p.p, 0, sizeof(double) * n, A.stream));
    CK(cudaMemsetAsync(A.s.p, 0, sizeof(double) * n, A.stream));
    A.launch_mult(A.u.p, A.w.p, true);
    k_finish<<<1, T, 0, A.stream>>>(3, 0, nullptr, 0, A.d_pp.p, A.dot_parts(), A.state.p, A.dots.p, A.hist.p);
    CK(cudaGetLastError());
  }
  void get_state(MCGState &o)
  {
    CK(cudaMemcpyAsync(&o, A.state.p, sizeof(MCGState), cudaMemcpyDeviceToHost, A.stream));
    CK(cudaStreamSynchronize(A.stream));
  }
  void put_state(const MCGState &o)
  {
    CK(cudaMemcpyAsync(A.state.p, &o, sizeof(MCGState), cudaMemcpyHostToDevice, A.stream));
  }
  void history(double *h, int count)
  {
    CK(cudaMemcpyAsync(h, A.hist.p, sizeof(double) * count, cudaMemcpyDeviceToHost, A.stream));
    CK(cudaStreamSynchronize(A.stream));
  }
};

template <typename V>
SolveResult CudaMatrix<V>::solve(const Vector &dinv, const Vector &b, Vector &x, const SolveSettings &st)
{
  const long n = lay.n(), its = (st.fixed_its > 0 ? st.fixed_its : st.max_its) + 1;
  if (r.n != n) {
    for (DevBuf<double> *v : {&r, &u, &w, &p, &s}) v->resize(n);
    vp.resize(4L * vec_blocks());
    dots.resize(MCG_NDOTS);
    state.resize(1);
  }
  if (hist.n < its) { /* the graphs hold the old pointer */
    drop_graphs();
    hist.resize(its);
  }
  CudaOps<V>  ops{*this, dp(dinv), dp(b), dp(x), st.jacobi, n, vec_blocks()};
  SolveResult res = run_mcg(ops, st);
  CK(cudaStreamSynchronize(stream));
  return res;
}

class CudaExecutor : public Executor {
public:
  const char             *name() const override { return "cuda"; }
  std::unique_ptr<Vector> vector(long n) override { return std::make_unique<CudaVector>(n); }
  std::unique_ptr<Matrix> matrix(const Layout &L, Precision p) override
  {
    if (p == Precision::single_values) return std::make_unique<CudaMatrix<float>>(L, p);
    return std::make_unique<CudaMatrix<double>>(L, p);
  }
  void synchronize() override { CK(cudaDeviceSynchronize()); }
};

} // namespace

std::unique_ptr<Executor> make_cuda_executor(std::string *why)
{
  int               count = 0;
  const cudaError_t e     = cudaGetDeviceCount(&count);
  if (e != cudaSuccess) {
    *why = std::string("no usable CUDA device: cudaGetDeviceCount: ") + cudaGetErrorString(e);
    return nullptr;
  }
  if (count == 0) {
    *why = "no CUDA device on this machine";
    return nullptr;
  }
  return std::make_unique<CudaExecutor>();
}

} // namespace device
} // namespace binbcsr
