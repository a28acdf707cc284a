/* MATSEQBINBCSR products: y = A x (+ z), y = A^T x (+ z) and the fused y = A x with x.y. The bodies
   are in src/mat_binbcsr/kernels/; binbcsr_dispatch.h's select_body picks the one for the matrix's
   shape and body set (MatBinBCSRSetKernel). */
#include "binbcsr.h"
#include "../kernels/binbcsr_dispatch.h"
#include "../common/binbcsr_machine.h"
#include <algorithm>

static_assert(sizeof(PetscInt) == sizeof(int), "the product bodies take 32-bit indices");

/* The plain view of a for the bodies, and the body for its shape. */
static binbcsr::BinMatrix BinMatrixOf(const Mat_SeqBinBCSR *a)
{
  binbcsr::BinMatrix m = {};
  m.bin_start          = a->bin_start;
  m.col                = a->col;
  m.row_nz             = a->row_nz;
  m.diag_slot          = a->diag_slot;
  m.val                = a->val;
  m.valf               = a->valf;
  m.nbins              = (int)a->nbins;
  m.mbs                = (int)a->mbs;
  m.nbs                = (int)a->nbs;
  m.bs                 = (int)a->bs;
  m.bw                 = (int)a->bw;
  m.streams            = (int)a->streams;
  m.prefetch           = (int)a->prefetch;
  m.sym                = a->sym ? true : false;
  m.bin_xload = a->bin_xload && a->xload == MAT_BINBCSR_XLOAD_GATHER ? a->bin_xload + a->nbins : a->bin_xload;
  return m;
}

static bool ReadsXLoad(const Mat_SeqBinBCSR *a, binbcsr::BodySet set)
{
  return BinBCSRShapeReadsXLoad(a->sym, a->bs, a->bw, set);
}

PetscBool MatSeqBinBCSRReadsXLoad(const Mat_SeqBinBCSR *a)
{
  return ReadsXLoad(a, MatSeqBinBCSRSelectBody(a).set) ? PETSC_TRUE : PETSC_FALSE;
}

/* The AVX-512 whole-storage body's per-bin hint (BinMatrix::bin_xload), made at the first product that
   runs that body and kept with the layout: one pass over the column indices. Two halves: the hint
   (MAT_BINBCSR_XLOAD_LOADS) and XC_GATHER (MAT_BINBCSR_XLOAD_GATHER, gather everywhere), so that the x
   load can change from one product to the next without a pass. */
static PetscErrorCode MatSeqBinBCSRXLoadBins(Mat_SeqBinBCSR *a, const binbcsr::Body &body)
{
  PetscFunctionBegin;
  if (a->bin_xload || !a->nbins || !ReadsXLoad(a, body.set)) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(2 * a->nbins, &a->bin_xload));
  binbcsr::xload_bins<PetscInt>(a->bin_start, a->col, a->row_nz, a->mbs, a->nbins, 8, a->nbs, a->bin_xload);
  std::fill(a->bin_xload + a->nbins, a->bin_xload + 2 * a->nbins, binbcsr::XC_GATHER);
  PetscInt n = 0;
  for (PetscInt b = 0; b < a->nbins; b++) n += a->bin_xload[b] == binbcsr::XC_NEAR_UNIT;
  PetscCall(PetscInfo(
    NULL, "x_c by block loads in %" PetscInt_FMT " of %" PetscInt_FMT " bins, lane by lane in the others\n",
    n, a->nbins));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRXLoadHint(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (a->built) PetscCall(MatSeqBinBCSRXLoadBins(a, MatSeqBinBCSRSelectBody(a)));
  PetscFunctionReturn(0);
}

binbcsr::Body MatSeqBinBCSRSelectBody(const Mat_SeqBinBCSR *a)
{
  const binbcsr::Shape s = {(int)a->bs, (int)a->bw, (int)a->streams,
                            a->precision == MAT_BINBCSR_PRECISION_SINGLE, a->sym ? true : false};
  return binbcsr::select_body(s, (binbcsr::BodySet)a->kernel);
}

/* The x load decided by the matrix's own first products (MatSeqBinBCSRTune starts the trial where it
   chose the x load itself): the tuner times a cold sample, whose order of loads and gathers did not
   match the whole matrix's on a Zen 5 VM (48^3 stencil, double: the sample 3-8% faster loading, the
   whole matrix in one process 7% faster gathering). The first product after the build is not timed
   (first touches); the next ones alternate loads and gathers, each mode's fastest counts, and the
   trial's end keeps the faster (the tuner's choice unless the other is 2% ahead). The same x_c either
   way, so the same results throughout. Products of every kind count (y = A x, y = z + A x, with x.y):
   they differ by a vector pass, a few percent of a product, which a caller alternating two kinds in
   step with the modes would add to one of them; the 2% margin covers part of that, not all. */
static PetscErrorCode MatSeqBinBCSRXLoadTrialMode(Mat_SeqBinBCSR *a)
{
  PetscFunctionBegin;
  /* products left: 2n+1 (the untimed first) down to 1; even counts the tuner's choice, odd the other */
  if (a->xload_trial < BINBCSR_XLOAD_TRIAL)
    a->xload = (MatBinBCSRXLoad)(a->xload_trial % 2 == 0 ? a->xload_chosen : 1 - a->xload_chosen);
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSeqBinBCSRXLoadTrialRecord(Mat_SeqBinBCSR *a, double sec)
{
  PetscFunctionBegin;
  if (a->xload_trial < BINBCSR_XLOAD_TRIAL) a->xload_sec[a->xload] = PetscMin(a->xload_sec[a->xload], sec);
  if (--a->xload_trial > 0) PetscFunctionReturn(0);
  const PetscInt c = a->xload_chosen, o = 1 - c;
  a->xload = (MatBinBCSRXLoad)(a->xload_sec[o] < 0.98 * a->xload_sec[c] ? o : c);
  char line[160];
  PetscCall(PetscSNPrintf(line, sizeof line, "; the first products: loads %.3g ms, gather %.3g ms, so %s",
                          1e3 * a->xload_sec[0], 1e3 * a->xload_sec[1], MatBinBCSRXLoads[a->xload]));
  PetscCall(PetscStrlcat(a->tune_info, line, sizeof(a->tune_info)));
  PetscCall(PetscInfo(NULL, "x load by the first products: loads %g s, gather %g s: %s\n", a->xload_sec[0],
                      a->xload_sec[1], MatBinBCSRXLoads[a->xload]));
  PetscFunctionReturn(0);
}

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
  const PetscScalar *x, *z   = nullptr;
  PetscScalar       *y, *acc = nullptr, acc_small[8];
  binbcsr::Body      body;
  binbcsr::BinMatrix m;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  body = MatSeqBinBCSRSelectBody(a);
  PetscCall(MatSeqBinBCSRXLoadBins(a, body));
  /* only products that read the x load can time it (a body set after the tuner's may not) */
  const bool trial = a->xload_trial > 0 && a->bin_xload && ReadsXLoad(a, body.set);
  if (trial) PetscCall(MatSeqBinBCSRXLoadTrialMode(a));
  m = BinMatrixOf(a);
  if (a->bs > 8) PetscCall(PetscMalloc1(a->bs, &acc)); /* the lane-by-lane bodies' accumulators */
  else acc = acc_small;
  PetscCall(VecGetArrayRead(xx, &x));
  if (a->sym) { /* y = z (or 0), then y += A x with scatters */
    if (zz && zz != yy) PetscCall(VecCopy(zz, yy));
    PetscCall(VecGetArray(yy, &y));
    if (!zz) PetscCall(PetscArrayzero(y, A->rmap->n));
    body.mult(m, x, nullptr, y, dot, acc);
    PetscCall(VecRestoreArray(yy, &y));
    PetscCall(VecRestoreArrayRead(xx, &x));
    if (acc != acc_small) PetscCall(PetscFree(acc));
    PetscCall(PetscLogFlops(2.0 * (2 * a->nz - CountDiagonal(a)) * a->bs2 - (zz ? 0.0 : (double)A->rmap->n) +
                            (dot ? 2.0 * A->rmap->n : 0.0)));
    PetscFunctionReturn(0);
  }
  if (zz == yy) {
    PetscCall(VecGetArray(yy, &y));
    z = y;
  } else {
    if (zz) PetscCall(VecGetArrayRead(zz, &z));
    PetscCall(VecGetArrayWrite(yy, &y));
  }
  if (trial) {
    const double t0 = binbcsr::thread_cpu_seconds();
    body.mult(m, x, z, y, dot, acc);
    PetscCall(MatSeqBinBCSRXLoadTrialRecord(a, binbcsr::thread_cpu_seconds() - t0));
  } else body.mult(m, x, z, y, dot, acc);
  PetscCall(VecRestoreArrayRead(xx, &x));
  if (zz == yy) PetscCall(VecRestoreArray(yy, &y));
  else {
    if (zz) PetscCall(VecRestoreArrayRead(zz, &z));
    PetscCall(VecRestoreArrayWrite(yy, &y));
  }
  if (acc != acc_small) PetscCall(PetscFree(acc));
  PetscCall(
    PetscLogFlops(2.0 * a->nz * a->bs2 - (zz ? 0.0 : (double)A->rmap->n) + (dot ? 2.0 * A->rmap->n : 0.0)));
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
  PetscCheck(nx == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Mat A,Vec x: local dim %" PetscInt_FMT " %" PetscInt_FMT, A->cmap->n, nx);
  PetscCheck(ny == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Mat A,Vec y: local dim %" PetscInt_FMT " %" PetscInt_FMT, A->rmap->n, ny);
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
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  if (A->symmetric == PETSC_BOOL3_TRUE || a->sym) { /* A^T = A: the vectorised product */
    PetscCall(MatMultKernel_SeqBinBCSR(A, xx, zz, yy, nullptr));
    PetscFunctionReturn(0);
  }
  if (zz && zz != yy) PetscCall(VecCopy(zz, yy));
  else if (!zz) PetscCall(VecSet(yy, 0.0));
  PetscCall(VecGetArrayRead(xx, &x));
  PetscCall(VecGetArray(yy, &y));
  MatSeqBinBCSRSelectBody(a).mult_transpose(BinMatrixOf(a), x, y);
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
