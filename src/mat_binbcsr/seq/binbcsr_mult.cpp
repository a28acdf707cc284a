/* MATSEQBINBCSR products: y = A x (+ z), y = A^T x (+ z), the fused y = A x with x.y, the diagonal and
   its block inverse. The CPU drivers here loop over bins; the per-lane arithmetic is
   src/mat_binbcsr/binbcsr_kernels.h. */
#include "binbcsr.h"
#include "../binbcsr_kernels.h"
#include <petsc/private/kernels/blockinvert.h>
#include <type_traits>

/* The loop over the lanes of a bin is the SIMD loop. GCC 12 does not vectorise it under `omp simd`
   once the lane kernel is inlined (its private arrays stay in memory), but does with ivdep: lanes are
   independent by construction (each writes only its own accumulators). */
#if defined(__clang__)
  #define BINBCSR_LANE_LOOP _Pragma("clang loop vectorize(enable) interleave(enable)")
#elif defined(__GNUC__)
  #define BINBCSR_LANE_LOOP _Pragma("GCC ivdep")
#else
  #define BINBCSR_LANE_LOOP _Pragma("omp simd")
#endif

namespace
{

/* Everything a bin sweep reads, as plain pointers. */
template <typename V>
struct BinSweep {
  const PetscInt *bin_start, *col;
  const V        *val;
  PetscInt        nbins, mbs, bs;
};

/* The slices of K bins: values, columns and slot groups (len) of bins[q]. */
template <int K, typename V>
struct BinSlices {
  const V        *t[K];
  const PetscInt *c[K];
  int             len[K];
};

template <int K, int BS, int BW, typename V>
BinSlices<K, V> bin_slices(const PetscInt *bin_start, const PetscInt *col, const V *val, const PetscInt *bins)
{
  BinSlices<K, V> s;
  for (int q = 0; q < K; q++) {
    const PetscInt s0 = bin_start[bins[q]];
    s.t[q]            = val + (size_t)s0 * BS * BS;
    s.c[q]            = col + s0;
    s.len[q]          = (int)((bin_start[bins[q] + 1] - s0) / BW);
  }
  return s;
}

/* The order of the products' sweeps: the nbins bins cut into K runs of consecutive bins, f(K, bins)
   for bin j of every run together, then f(1, &b) for each of the nbins % K bins left over. K and the
   count passed to f are compile-time constants (std::integral_constant). */
template <int K, class F>
void for_each_sweep(PetscInt nbins, F &&f)
{
  const PetscInt run = nbins / K;
  PetscInt       bins[K];
  for (PetscInt j = 0; j < run; j++) {
    for (int q = 0; q < K; q++) bins[q] = q * run + j;
    f(std::integral_constant<int, K>{}, bins);
  }
  for (PetscInt b = K * run; b < nbins; b++) f(std::integral_constant<int, 1>{}, &b);
}

/* acc[i][l] += block row i of lane l times x_c over one slot group (c: the group's BW columns, t: its
   tiles). BW is the bin width as a constant: the lanes' accumulators stay in registers and the loop
   over the lanes becomes SIMD (column indices and values are unit-stride across lanes). */
template <int BS, int BW, typename V>
inline void group_mult(const V *t, const PetscInt *c, const double *x, double (*acc)[BW])
{
  binbcsr::prefetch_values(t, BW * BS * BS * (int)sizeof(V));
  if (binbcsr::unit_stride<BW>(c)) { /* consecutive columns: x_c by plain loads, no gathers */
    const double *xs = x + (size_t)c[0] * BS;
    BINBCSR_LANE_LOOP
    for (int l = 0; l < BW; l++) {
      double yl[BS];
      for (int i = 0; i < BS; i++) yl[i] = acc[i][l];
      binbcsr::slot_mult<BS, V>(t + l, BW, BS, xs + l * BS, yl);
      for (int i = 0; i < BS; i++) acc[i][l] = yl[i];
    }
    return;
  }
  BINBCSR_LANE_LOOP
  for (int l = 0; l < BW; l++) {
    const int ci = (int)c[l] * BS; /* 32-bit offsets (PetscInt is 32-bit here): vgatherdpd */
    double    xc[BS], yl[BS];
    for (int j = 0; j < BS; j++) xc[j] = x[ci + j];
    for (int i = 0; i < BS; i++) yl[i] = acc[i][l];
    binbcsr::slot_mult<BS, V>(t + l, BW, BS, xc, yl);
    for (int i = 0; i < BS; i++) acc[i][l] = yl[i];
  }
}

/* K bins swept together: the slot groups of bins[0..K-1] in turn, then y of their rows = z + acc, and
   *dot += x.y over them when dot is non-null. Why several bins at once: one core streaming one array
   out of memory is limited by the cache lines it has in flight, and the hardware prefetcher keeps more
   of them in flight for several streams than for one. On this project's machine one core read one
   array at 9.9-10.5 GB/s, two at 11.9-12.4 and four at 13.0-14.1 GB/s; the 48^3 stencil's product
   took 16.2-20.0 ms with 4 runs against 20.2-22.9 ms with one (docs/mat_binbcsr.md). */
template <int K, int BS, int BW, typename V>
void bins_sweep(const BinSweep<V> &m, const PetscInt *bins, const double *x, const double *z, double *y, double &d, bool want_dot)
{
  constexpr int         BS2            = BS * BS;
  double                acc[K][BS][BW] = {};
  const BinSlices<K, V> s              = bin_slices<K, BS, BW, V>(m.bin_start, m.col, m.val, bins);
#if defined(BINBCSR_AVX512)
  if constexpr (BS == 3 && BW == 8) {
    double(*accq[K])[8];
    for (int q = 0; q < K; q++) accq[q] = acc[q];
    binbcsr::avx512::bins_mult_3x8<K>(s.t, s.c, s.len, x, accq);
  } else
#endif
  binbcsr::interleave_groups<K>(s.len, [&](int q, int k) { group_mult<BS, BW, V>(s.t[q] + (size_t)k * BW * BS2, s.c[q] + (size_t)k * BW, x, acc[q]); });
  for (int q = 0; q < K; q++) {
    /* y += A x in place: an empty bin changes nothing (the off-diagonal part of an MPI matrix is
       mostly empty bins; writing their rows back cost a tenth of the diagonal part's product) */
    if (!s.len[q] && z == y && !want_dot) continue;
    const PetscInt r0 = bins[q] * BW, nl = PetscMin((PetscInt)BW, m.mbs - r0);
    for (PetscInt l = 0; l < nl; l++) {
      for (int i = 0; i < BS; i++) {
        const size_t p  = (size_t)(r0 + l) * BS + i;
        const double yv = (z ? z[p] : 0.0) + acc[q][i][l];
        y[p]            = yv;
        if (want_dot) d += x[p] * yv;
      }
    }
  }
}

/* y[rows of the bins] = z + A x, and *dot += x.y over the rows when dot is non-null; the bins in
   for_each_sweep's order (K runs side by side). */
template <int K, int BS, int BW, typename V>
void mult_bins_fixed(const BinSweep<V> &m, const double *x, const double *z, double *y, double *dot)
{
  double d = 0.0;
  for_each_sweep<K>(m.nbins, [&](auto KC, const PetscInt *bins) { bins_sweep<decltype(KC)::value, BS, BW, V>(m, bins, x, z, y, d, dot != nullptr); });
  if (dot) *dot += d;
}

/* Any bin width and block size: one lane at a time through the lane kernel. */
template <int BS, typename V>
void mult_bins_any(const BinSweep<V> &m, PetscInt bw, const double *x, const double *z, double *y, double *dot, double *acc)
{
  const PetscInt bs = BS ? BS : m.bs, bs2 = bs * bs;
  double         d  = 0.0;
  for (PetscInt b = 0; b < m.nbins; b++) {
    const PetscInt s0 = m.bin_start[b], len = (m.bin_start[b + 1] - s0) / bw;
    for (PetscInt l = 0; l < bw && b * bw + l < m.mbs; l++) {
      const PetscInt r = b * bw + l;
      for (PetscInt i = 0; i < bs; i++) acc[i] = z ? z[r * bs + i] : 0.0;
      binbcsr::lane_mult<BS, V, PetscInt>(m.val + (size_t)s0 * bs2, m.col + s0, (int)len, (int)bw, (int)bs, (int)l, x, acc);
      for (PetscInt i = 0; i < bs; i++) {
        y[r * bs + i] = acc[i];
        if (dot) d += x[r * bs + i] * acc[i];
      }
    }
  }
  if (dot) *dot += d;
}

/* Calls f(block size, bin width) with each as a compile-time constant where a specialised sweep exists
   (bs 1 and 3; bin widths 4, 8, 16, 32) and 0 where the generic sweep must take it from the matrix. */
template <class F>
void with_constant_shape(PetscInt bs, PetscInt bw, F &&f)
{
  using std::integral_constant;
  const auto width = [&](auto BS) {
    switch (bw) {
    case 4:
      f(BS, integral_constant<int, 4>{});
      break;
    case 8:
      f(BS, integral_constant<int, 8>{});
      break;
    case 16:
      f(BS, integral_constant<int, 16>{});
      break;
    case 32:
      f(BS, integral_constant<int, 32>{});
      break;
    default:
      f(BS, integral_constant<int, 0>{});
    }
  };
  if (bs == 3) width(integral_constant<int, 3>{});
  else if (bs == 1) width(integral_constant<int, 1>{});
  else f(integral_constant<int, 0>{}, integral_constant<int, 0>{});
}

/* Calls f(K) with the run count K (MatBinBCSRSetStreams: 1, 2, 4 or 8) as a compile-time constant. */
template <class F>
void with_streams(PetscInt streams, F &&f)
{
  using std::integral_constant;
  switch (streams) {
  case 8:
    f(integral_constant<int, 8>{});
    break;
  case 4:
    f(integral_constant<int, 4>{});
    break;
  case 2:
    f(integral_constant<int, 2>{});
    break;
  default:
    f(integral_constant<int, 1>{});
  }
}

template <typename V>
void mult_dispatch(const Mat_SeqBinBCSR *a, const V *val, const double *x, const double *z, double *y, double *dot, double *acc)
{
  const BinSweep<V> m = {a->bin_start, a->col, val, a->nbins, a->mbs, a->bs};
  if (dot) *dot = 0.0;
  with_constant_shape(a->bs, a->bw, [&](auto BS, auto BW) {
    if constexpr (BS > 0 && BW > 0) {
      with_streams(a->streams, [&](auto K) { mult_bins_fixed<K, BS, BW, V>(m, x, z, y, dot); });
    } else mult_bins_any<BS, V>(m, a->bw, x, z, y, dot, acc);
  });
}

/* Symmetric storage: y += A x with the upper triangle (y holds z or zero on entry), the bins in
   for_each_sweep's order (K runs side by side). *dot += x.y over the rows: with one run, bin by bin
   once its rows are final (no later bin scatters into rows of earlier bins); with several, a bin's rows
   may still receive scatters from the bins of earlier runs, so the dot is a pass of its own at the end
   (x and y, a small fraction of the bytes of the matrix). */
template <int K, int BS, int BW, typename V>
void sym_mult_bins_fixed(const Mat_SeqBinBCSR *a, const V *val, const double *x, double *y, double *dot)
{
  double d = 0.0;
  for_each_sweep<K>(a->nbins, [&](auto KC, const PetscInt *bins) {
    constexpr int          Kc = decltype(KC)::value;
    const BinSlices<Kc, V> s  = bin_slices<Kc, BS, BW, V>(a->bin_start, a->col, val, bins);
    PetscInt               r0[Kc];
    for (int q = 0; q < Kc; q++) r0[q] = bins[q] * BW;
    binbcsr::sym_bins_mult<Kc, BS, BW, V, PetscInt>(s.t, s.c, s.len, r0, a->mbs, x, y);
    if (dot && K == 1)
      for (PetscInt p = r0[0] * BS; p < PetscMin(a->mbs, r0[0] + BW) * BS; p++) d += x[p] * y[p];
  });
  if (dot && K > 1)
    for (PetscInt p = 0; p < a->mbs * BS; p++) d += x[p] * y[p];
  if (dot) *dot += d;
}

/* Any bin width or block size: the lanes of a bin one after the other (no conflicts at all). */
template <int BS, typename V>
void sym_mult_bins_any(const Mat_SeqBinBCSR *a, const V *val, const double *x, double *y, double *dot, double *acc)
{
  const PetscInt bs = BS ? BS : a->bs, bs2 = bs * bs, bw = a->bw;
  double         d  = 0.0;
  for (PetscInt b = 0; b < a->nbins; b++) {
    const PetscInt s0 = a->bin_start[b], len = (a->bin_start[b + 1] - s0) / bw, r0 = b * bw, r1 = PetscMin(a->mbs, r0 + bw);
    for (PetscInt r = r0; r < r1; r++) {
      for (PetscInt i = 0; i < bs; i++) acc[i] = 0.0;
      binbcsr::sym_lane_mult<BS, V, PetscInt>(val + (size_t)s0 * bs2, a->col + s0, (int)len, (int)bw, (int)bs, (int)(r - r0), r, x, x + (size_t)r * bs, y, acc);
      for (PetscInt i = 0; i < bs; i++) y[r * bs + i] += acc[i];
    }
    if (dot)
      for (PetscInt p = r0 * bs; p < r1 * bs; p++) d += x[p] * y[p];
  }
  if (dot) *dot += d;
}

template <typename V>
void sym_mult_dispatch(const Mat_SeqBinBCSR *a, const V *val, const double *x, double *y, double *dot, double *acc)
{
  if (dot) *dot = 0.0;
  with_constant_shape(a->bs, a->bw, [&](auto BS, auto BW) {
    if constexpr (BS > 0 && BW > 0) {
      with_streams(a->streams, [&](auto K) { sym_mult_bins_fixed<K, BS, BW, V>(a, val, x, y, dot); });
    } else sym_mult_bins_any<BS, V>(a, val, x, y, dot, acc);
  });
}

/* y += A^T x (y holds z or zero on entry). Scatter: rows are visited lane by lane. */
template <int BS, typename V>
void mult_transpose_bins(const Mat_SeqBinBCSR *a, const V *val, const double *x, double *y)
{
  const PetscInt bs = BS ? BS : a->bs, bs2 = bs * bs, bw = a->bw;
  for (PetscInt b = 0; b < a->nbins; b++) {
    const PetscInt s0 = a->bin_start[b];
    for (PetscInt l = 0; l < bw && b * bw + l < a->mbs; l++) {
      const PetscInt r = b * bw + l;
      binbcsr::lane_mult_transpose<BS, V, PetscInt>(val + (size_t)s0 * bs2, a->col + s0, (int)a->row_nz[r], (int)bw, (int)bs, (int)l, x + (size_t)r * bs, y);
    }
  }
}

template <typename V>
void mult_transpose_dispatch(const Mat_SeqBinBCSR *a, const V *val, const double *x, double *y)
{
  if (a->bs == 3) mult_transpose_bins<3, V>(a, val, x, y);
  else if (a->bs == 1) mult_transpose_bins<1, V>(a, val, x, y);
  else mult_transpose_bins<0, V>(a, val, x, y);
}

} // namespace

static PetscInt CountDiagonal(const Mat_SeqBinBCSR *a)
{
  PetscInt n = 0;
  for (PetscInt r = 0; r < a->mbs; r++) n += a->diag_slot[r] >= 0;
  return n;
}

/* y = z + A x (z may be null, may alias y); dot: optional local x.y. */
static PetscErrorCode MatMultKernel_SeqBinBCSR(Mat A, Vec xx, Vec zz, Vec yy, PetscScalar *dot)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscScalar *x, *z = nullptr;
  PetscScalar       *y, *acc = nullptr;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  { /* the lane-by-lane path (other block sizes or bin widths) needs bs accumulators */
    const PetscBool fixed = (PetscBool)((a->bs == 1 || a->bs == 3) && (a->bw == 4 || a->bw == 8 || a->bw == 16 || a->bw == 32));
    if (!fixed) PetscCall(PetscMalloc1(a->bs, &acc));
  }
  PetscCall(VecGetArrayRead(xx, &x));
  if (a->sym) { /* y = z (or 0), then y += A x with scatters */
    if (zz && zz != yy) PetscCall(VecCopy(zz, yy));
    PetscCall(VecGetArray(yy, &y));
    if (!zz) PetscCall(PetscArrayzero(y, A->rmap->n));
    if (a->val) sym_mult_dispatch<double>(a, a->val, x, y, dot, acc);
    else sym_mult_dispatch<float>(a, a->valf, x, y, dot, acc);
    PetscCall(VecRestoreArray(yy, &y));
    PetscCall(VecRestoreArrayRead(xx, &x));
    PetscCall(PetscFree(acc));
    PetscCall(PetscLogFlops(2.0 * (2 * a->nz - CountDiagonal(a)) * a->bs2 - (zz ? 0.0 : (double)A->rmap->n) + (dot ? 2.0 * A->rmap->n : 0.0)));
    PetscFunctionReturn(0);
  }
  if (zz == yy) {
    PetscCall(VecGetArray(yy, &y));
    z = y;
  } else {
    if (zz) PetscCall(VecGetArrayRead(zz, &z));
    PetscCall(VecGetArrayWrite(yy, &y));
  }
  if (a->val) mult_dispatch<double>(a, a->val, x, z, y, dot, acc);
  else mult_dispatch<float>(a, a->valf, x, z, y, dot, acc);
  PetscCall(VecRestoreArrayRead(xx, &x));
  if (zz == yy) PetscCall(VecRestoreArray(yy, &y));
  else {
    if (zz) PetscCall(VecRestoreArrayRead(zz, &z));
    PetscCall(VecRestoreArrayWrite(yy, &y));
  }
  PetscCall(PetscFree(acc));
  PetscCall(PetscLogFlops(2.0 * a->nz * a->bs2 - (zz ? 0.0 : (double)A->rmap->n) + (dot ? 2.0 * A->rmap->n : 0.0)));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMult_SeqBinBCSR(Mat A, Vec x, Vec y)
{
  PetscFunctionBegin;
  PetscCall(MatMultKernel_SeqBinBCSR(A, x, nullptr, y, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMultAdd_SeqBinBCSR(Mat A, Vec x, Vec z, Vec y)
{
  PetscFunctionBegin;
  PetscCall(MatMultKernel_SeqBinBCSR(A, x, z, y, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMultDotLocal_SeqBinBCSR(Mat A, Vec x, Vec y, PetscScalar *xdoty)
{
  PetscInt nx, ny;

  PetscFunctionBegin;
  PetscCheck(A->assembled, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Not for unassembled matrix");
  PetscCheck(x != y, PETSC_COMM_SELF, PETSC_ERR_ARG_IDN, "x and y must be different vectors");
  PetscCall(VecGetLocalSize(x, &nx));
  PetscCall(VecGetLocalSize(y, &ny));
  PetscCheck(nx == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Mat A,Vec x: local dim %" PetscInt_FMT " %" PetscInt_FMT, A->cmap->n, nx);
  PetscCheck(ny == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Mat A,Vec y: local dim %" PetscInt_FMT " %" PetscInt_FMT, A->rmap->n, ny);
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "x.y needs a square matrix");
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_MultDot, A, x, y, 0));
  PetscCall(MatMultKernel_SeqBinBCSR(A, x, nullptr, y, xdoty));
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_MultDot, A, x, y, 0));
  PetscCall(PetscObjectStateIncrease((PetscObject)y));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMultTransposeKernel_SeqBinBCSR(Mat A, Vec xx, Vec zz, Vec yy)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscScalar *x;
  PetscScalar       *y;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  if (A->symmetric == PETSC_BOOL3_TRUE || a->sym) { /* A^T = A: the vectorised product */
    PetscCall(MatMultKernel_SeqBinBCSR(A, xx, zz, yy, nullptr));
    PetscFunctionReturn(0);
  }
  if (zz && zz != yy) PetscCall(VecCopy(zz, yy));
  else if (!zz) PetscCall(VecSet(yy, 0.0));
  PetscCall(VecGetArrayRead(xx, &x));
  PetscCall(VecGetArray(yy, &y));
  if (a->val) mult_transpose_dispatch<double>(a, a->val, x, y);
  else mult_transpose_dispatch<float>(a, a->valf, x, y);
  PetscCall(VecRestoreArrayRead(xx, &x));
  PetscCall(VecRestoreArray(yy, &y));
  PetscCall(PetscLogFlops(2.0 * a->nz * a->bs2));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMultTranspose_SeqBinBCSR(Mat A, Vec x, Vec y)
{
  PetscFunctionBegin;
  PetscCall(MatMultTransposeKernel_SeqBinBCSR(A, x, nullptr, y));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMultTransposeAdd_SeqBinBCSR(Mat A, Vec x, Vec z, Vec y)
{
  PetscFunctionBegin;
  PetscCall(MatMultTransposeKernel_SeqBinBCSR(A, x, z, y));
  PetscFunctionReturn(0);
}

PetscErrorCode MatGetDiagonal_SeqBinBCSR(Mat A, Vec v)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscScalar    *d;
  PetscInt        n;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCall(VecGetLocalSize(v, &n));
  PetscCheck(n == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Nonconforming matrix and vector: %" PetscInt_FMT " rows, vector of %" PetscInt_FMT, A->rmap->n, n);
  PetscCall(VecGetArrayWrite(v, &d));
  for (PetscInt r = 0; r < a->mbs; r++) {
    const PetscInt s = a->diag_slot[r];
    for (PetscInt i = 0; i < a->bs; i++) d[r * a->bs + i] = s < 0 ? 0.0 : BinBCSRGetValue(a, BinBCSRValueIndex(s, i * a->bs + i, a->bw, a->bs2));
  }
  PetscCall(VecRestoreArrayWrite(v, &d));
  PetscFunctionReturn(0);
}

/* In-place inverse of one bs x bs block by Gauss-Jordan with partial pivoting on [m | I] (block sizes
   without a PETSc kernel); aug holds bs * 2bs scalars. Returns false on a zero pivot. */
static PetscBool InvertBlockGeneric(PetscInt bs, MatScalar *m, MatScalar *aug)
{
  const PetscInt w = 2 * bs;
  for (PetscInt i = 0; i < bs; i++)
    for (PetscInt j = 0; j < bs; j++) {
      aug[i * w + j]      = m[i * bs + j];
      aug[i * w + bs + j] = (i == j) ? 1.0 : 0.0;
    }
  for (PetscInt k = 0; k < bs; k++) {
    PetscInt  p   = k;
    PetscReal big = PetscAbsScalar(aug[k * w + k]);
    for (PetscInt i = k + 1; i < bs; i++)
      if (PetscAbsScalar(aug[i * w + k]) > big) {
        big = PetscAbsScalar(aug[i * w + k]);
        p   = i;
      }
    if (big < PETSC_MACHINE_EPSILON) return PETSC_FALSE;
    if (p != k)
      for (PetscInt j = 0; j < w; j++) {
        const MatScalar t = aug[k * w + j];
        aug[k * w + j]    = aug[p * w + j];
        aug[p * w + j]    = t;
      }
    const MatScalar inv = 1.0 / aug[k * w + k];
    for (PetscInt j = 0; j < w; j++) aug[k * w + j] *= inv;
    for (PetscInt i = 0; i < bs; i++) {
      if (i == k) continue;
      const MatScalar f = aug[i * w + k];
      if (f != 0.0)
        for (PetscInt j = 0; j < w; j++) aug[i * w + j] -= f * aug[k * w + j];
    }
  }
  for (PetscInt i = 0; i < bs; i++)
    for (PetscInt j = 0; j < bs; j++) m[i * bs + j] = aug[i * w + bs + j];
  return PETSC_TRUE;
}

/* In-place inverse of one bs x bs block (either storage order: the inverse of the transpose is the
   transpose of the inverse); aug: scratch of 2 bs^2 scalars. *zp: a zero pivot was met (d is then
   garbage). One routine for MatInvertBlockDiagonal, MatSOR's diagonal and the variable blocks. */
static PetscErrorCode InvertBlock(PetscInt bs, MatScalar *d, MatScalar *aug, PetscBool *zp)
{
  PetscFunctionBegin;
  *zp = PETSC_FALSE;
  if (bs == 1) {
    *zp = PetscAbsScalar(d[0]) < PETSC_MACHINE_EPSILON ? PETSC_TRUE : PETSC_FALSE;
    if (!*zp) d[0] = 1.0 / d[0];
  } else if (bs == 3) {
    PetscCall(PetscKernel_A_gets_inverse_A_3(d, 0.0, PETSC_TRUE, zp));
  } else {
    *zp = InvertBlockGeneric(bs, d, aug) ? PETSC_FALSE : PETSC_TRUE;
  }
  PetscFunctionReturn(0);
}

/* out[r] = (D_r + shift I)^-1 for every block row r, column-major blocks (BAIJ's order); D_r is the
   stored diagonal block (zero if the row has none). A zero pivot is an error when the matrix errors on
   failure (MatSetErrorIfFailure) or zero_row is NULL; otherwise *zero_row is the first block row with
   one (-1: none) and it is recorded in A->factorerrortype. */
PetscErrorCode MatSeqBinBCSRInvertDiagonalBlocks(Mat A, PetscReal shift, MatScalar *out, PetscInt *zero_row)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bs = a->bs, bs2 = a->bs2;
  PetscBool       allowzeropivot = (PetscBool)(zero_row && !A->erroriffailure), zeropivot = PETSC_FALSE;
  MatScalar      *aug;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  if (zero_row) *zero_row = -1;
  PetscCall(PetscMalloc1(2 * bs2, &aug));
  for (PetscInt r = 0; r < a->mbs; r++) {
    MatScalar     *d = out + (size_t)r * bs2;
    const PetscInt s = a->diag_slot[r];
    /* the block, transposed into BAIJ's column-major order */
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt j = 0; j < bs; j++) d[j * bs + i] = (s < 0 ? 0.0 : BinBCSRGetValue(a, BinBCSRValueIndex(s, i * bs + j, a->bw, bs2))) + (i == j ? shift : 0.0);
    PetscBool zp;
    PetscCall(InvertBlock(bs, d, aug, &zp));
    if (zp) {
      if (!allowzeropivot) PetscCall(PetscFree(aug));
      PetscCheck(allowzeropivot, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT, "Zero pivot in the diagonal block of block row %" PetscInt_FMT, r);
      if (!zeropivot) *zero_row = r;
      zeropivot                      = PETSC_TRUE;
      A->factorerror_zeropivot_row   = r * bs;
      A->factorerror_zeropivot_value = 0.0;
    }
  }
  if (zeropivot) A->factorerrortype = MAT_FACTOR_NUMERIC_ZEROPIVOT;
  PetscCall(PetscFree(aug));
  PetscFunctionReturn(0);
}

PetscErrorCode MatInvertBlockDiagonal_SeqBinBCSR(Mat A, const PetscScalar **values)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        zero_row;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  if (!a->idiag) PetscCall(PetscMalloc1((size_t)a->mbs * a->bs2, &a->idiag));
  PetscCall(MatSeqBinBCSRInvertDiagonalBlocks(A, 0.0, a->idiag, &zero_row));
  if (values) *values = a->idiag;
  PetscFunctionReturn(0);
}

/* PCVPBJACOBI's blocks: diag gets, one after the other, the inverses of the diagonal blocks of the given
   point sizes (column-major, as MatInvertVariableBlockDiagonal_SeqAIJ leaves them). A variable block may
   cut across the bs x bs blocks of the layout, so its entries are read through MatGetValues (symmetric
   storage: the mirrored lower entries too); the inversion is MatInvertBlockDiagonal's. Zero pivots as
   there: an error under MatSetErrorIfFailure, else recorded in A->factorerrortype (PCVPBJACOBI turns it
   into its failed reason; aij's scalar blocks divide by zero silently). */
PetscErrorCode MatInvertVariableBlockDiagonal_SeqBinBCSR(Mat A, PetscInt nblocks, const PetscInt *bsizes, PetscScalar *diag)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        total = 0, nmax = 0, row = 0;
  PetscBool       zeropivot = PETSC_FALSE;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCheck(nblocks >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Negative number of blocks %" PetscInt_FMT, nblocks);
  for (PetscInt i = 0; i < nblocks; i++) {
    PetscCheck(bsizes[i] >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Block %" PetscInt_FMT " has negative size %" PetscInt_FMT, i, bsizes[i]);
    total += bsizes[i];
    nmax = PetscMax(nmax, bsizes[i]);
  }
  PetscCheck(total == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "The block sizes add up to %" PetscInt_FMT ", the matrix has %" PetscInt_FMT " rows", total, A->rmap->n);
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Diagonal blocks of a %" PetscInt_FMT " x %" PetscInt_FMT " matrix", A->rmap->n, A->cmap->n);
  std::vector<PetscInt>  idx(nmax);
  std::vector<MatScalar> rowmajor((size_t)nmax * nmax), aug(2 * (size_t)nmax * nmax);
  for (PetscInt b = 0; b < nblocks; row += bsizes[b], diag += bsizes[b] * bsizes[b], b++) {
    const PetscInt n = bsizes[b];
    PetscBool      zp;
    if (!n) continue;
    for (PetscInt i = 0; i < n; i++) idx[i] = row + i;
    PetscCall(MatGetValues(A, n, idx.data(), n, idx.data(), rowmajor.data()));
    for (PetscInt i = 0; i < n; i++)
      for (PetscInt j = 0; j < n; j++) diag[j * n + i] = rowmajor[i * n + j];
    PetscCall(InvertBlock(n, diag, aug.data(), &zp));
    if (!zp) continue;
    PetscCheck(!A->erroriffailure, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT, "Zero pivot in the diagonal block %" PetscInt_FMT " (rows %" PetscInt_FMT "..%" PetscInt_FMT ")", b, row, row + n - 1);
    if (!zeropivot) {
      A->factorerror_zeropivot_row   = row;
      A->factorerror_zeropivot_value = 0.0;
    }
    zeropivot = PETSC_TRUE;
  }
  if (zeropivot) A->factorerrortype = MAT_FACTOR_NUMERIC_ZEROPIVOT;
  PetscFunctionReturn(0);
}
