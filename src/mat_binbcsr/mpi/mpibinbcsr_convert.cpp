/* MATMPIBINBCSR conversion to and from other types, parallel MatLoad, MatView (per-rank info of
   the parts; other formats through an MPIAIJ copy), MatDuplicate and MatCopy. */
#include "mpibinbcsr.h"
#include "../common/binbcsr_load.h"

#include <algorithm>

/* Refills an existing matrix with src's values (its pattern must hold src's). */
static PetscErrorCode RefillByRows(Mat src, Mat dst)
{
  PetscFunctionBegin;
  PetscCall(MatZeroEntries(dst));
  PetscCall(MatBinBCSRInsertRows_Private(src, dst));
  PetscFunctionReturn(0);
}

/* B's local columns as global point columns (garray holds block columns). */
static std::vector<PetscInt> PointGarray(Mat mat)
{
  const Mat_MPIBinBCSR *b  = MPIBinBCSR(mat);
  const PetscInt        bs = mat->cmap->bs;
  std::vector<PetscInt> cols(b->garray.size() * bs);
  for (size_t k = 0; k < b->garray.size(); k++)
    for (PetscInt c = 0; c < bs; c++) cols[k * bs + c] = b->garray[k] * bs + c;
  return cols;
}

/* An assembled matrix as MPIAIJ without communicating its entries: each part converted to seqaij (the
   diagonal one with both triangles under symmetric storage) and joined by MatCreateMPIAIJWithSeqAIJ,
   the off-diagonal part's compressed columns mapped through garray. */
static PetscErrorCode ConvertByParts(Mat mat, Mat *M)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  Mat             Ad, Ao;

  PetscFunctionBegin;
  const std::vector<PetscInt> cols = PointGarray(mat);
  /* the parts and the join are internal steps: -mat_view must not see them (per-rank, unsynchronised) */
  PetscCall(PetscOptionsPushCreateViewerOff(PETSC_TRUE));
  PetscCall(MatConvert(b->A, MATSEQAIJ, MAT_INITIAL_MATRIX, &Ad));
  if (b->B) PetscCall(MatConvert(b->B, MATSEQAIJ, MAT_INITIAL_MATRIX, &Ao));
  else {
    PetscCall(MatCreateSeqAIJ(PETSC_COMM_SELF, mat->rmap->n, 0, 0, nullptr, &Ao));
    PetscCall(MatAssemblyBegin(Ao, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(Ao, MAT_FINAL_ASSEMBLY));
  }
  PetscCheck(Ao->cmap->n == static_cast<PetscInt>(cols.size()), PETSC_COMM_SELF, PETSC_ERR_PLIB,
             "Off-diagonal part has %" PetscInt_FMT " columns, garray %zu", Ao->cmap->n, cols.size());
  PetscCall(MatCreateMPIAIJWithSeqAIJ(PetscObjectComm((PetscObject)mat), Ad, Ao, cols.data(), M));
  PetscCall(PetscOptionsPopCreateViewerOff());
  PetscCall(
    MatSetOption(*M, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_FALSE)); /* as any other conversion's result */
  PetscCall(MatPropagateSymmetryOptions(mat, *M));
  PetscFunctionReturn(0);
}

/* MAT_REUSE_MATRIX into an MPIAIJ made by ConvertByParts (same rows, same off-diagonal columns): each
   part's values into the MPIAIJ's part, no communication. Collective: every rank takes this path or
   none does (*done). */
static PetscErrorCode RefillByParts(Mat mat, Mat M, PetscBool *done)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  PetscBool       ok;
  Mat             Ad = nullptr, Ao = nullptr;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)M, MATMPIAIJ, &ok));
  if (ok)
    ok = (b->compressed && mat->assembled && M->rmap->n == mat->rmap->n && M->cmap->n == mat->cmap->n &&
          M->rmap->N == mat->rmap->N && M->cmap->N == mat->cmap->N)
           ? PETSC_TRUE
           : PETSC_FALSE;
  if (ok) {
    const PetscInt *colmap;
    PetscCall(MatMPIAIJGetSeqAIJ(M, &Ad, &Ao, &colmap));
    const std::vector<PetscInt> cols = PointGarray(mat);
    ok = (Ao->cmap->n == static_cast<PetscInt>(cols.size()) && std::equal(cols.begin(), cols.end(), colmap) &&
          (b->B || cols.empty()))
           ? PETSC_TRUE
           : PETSC_FALSE;
  }
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &ok, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)mat)));
  *done = ok;
  if (!ok) PetscFunctionReturn(0);
  PetscCall(MatConvert(b->A, MATSEQAIJ, MAT_REUSE_MATRIX, &Ad));
  if (b->B) PetscCall(MatConvert(b->B, MATSEQAIJ, MAT_REUSE_MATRIX, &Ao));
  PetscCall(PetscObjectStateIncrease((PetscObject)M));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatConvert_MPIBinBCSR_MPIAIJ(Mat mat, MatType newtype, MatReuse reuse,
                                                         Mat *newmat)
{
  Mat M;

  PetscFunctionBegin;
  (void)newtype;
  if (reuse == MAT_REUSE_MATRIX) {
    PetscBool done;
    PetscCall(RefillByParts(mat, *newmat, &done));
    if (!done) PetscCall(RefillByRows(mat, *newmat));
    PetscFunctionReturn(0);
  }
  if (MPIBinBCSR(mat)->compressed && mat->assembled) PetscCall(ConvertByParts(mat, &M));
  else {
    PetscCall(MatBinBCSRCreateLike_Private(mat, MATMPIAIJ, &M));
    PetscCall(MatBinBCSRPreallocateAndFill_Private(mat, M));
  }
  if (reuse == MAT_INPLACE_MATRIX) PetscCall(MatHeaderReplace(mat, &M));
  else *newmat = M;
  PetscFunctionReturn(0);
}

/* MatConvert(any type with MatGetRow -> mpibinbcsr). */
PETSC_INTERN PetscErrorCode MatConvertFrom_MPIBinBCSR(Mat src, MatType newtype, MatReuse reuse, Mat *newmat)
{
  Mat M;

  PetscFunctionBegin;
  if (reuse == MAT_REUSE_MATRIX) {
    PetscCall(RefillByRows(src, *newmat));
    PetscFunctionReturn(0);
  }
  PetscCall(MatBinBCSRCreateLike_Private(src, newtype, &M));
  PetscCall(MatBinBCSRSetFromOptions(M)); /* the -mat_binbcsr_* options apply to converted matrices too */
  PetscCall(MatBinBCSRPreallocateAndFill_Private(src, M));
  if (reuse == MAT_INPLACE_MATRIX) PetscCall(MatHeaderReplace(src, &M));
  else *newmat = M;
  PetscFunctionReturn(0);
}

/* Reads this rank's rows with the reader the serial loader uses (same checks on every rank, repeated
   entries summed: mpiaij's own reader would drop a negative column and keep only the last of a
   repeated one), makes them an MPIAIJ matrix and fills this matrix from it. */
PETSC_INTERN PetscErrorCode MatLoad_MPIBinBCSR(Mat mat, PetscViewer viewer)
{
  Mat                      T;
  std::vector<PetscInt>    rowptr, cols;
  std::vector<PetscScalar> vals;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRReadBinaryRows_Private(mat, viewer, rowptr, cols, vals));
  PetscCall(MatCreateMPIAIJWithArrays(PetscObjectComm((PetscObject)mat), mat->rmap->n, mat->cmap->n,
                                      mat->rmap->N, mat->cmap->N, rowptr.data(), cols.data(), vals.data(),
                                      &T));
  PetscCall(MatBinBCSRPreallocateAndFill_Private(T, mat));
  PetscCall(MatDestroy(&T));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatView_MPIBinBCSR(Mat mat, PetscViewer viewer)
{
  Mat_MPIBinBCSR   *b = MPIBinBCSR(mat);
  PetscBool         iascii;
  PetscViewerFormat format;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &iascii));
  PetscCall(PetscViewerGetFormat(viewer, &format));
  if (iascii && (format == PETSC_VIEWER_ASCII_INFO || format == PETSC_VIEWER_ASCII_INFO_DETAIL)) {
    PetscMPIInt rank, size;
    PetscViewer sv;
    PetscCallMPI(MPI_Comm_rank(PetscObjectComm((PetscObject)mat), &rank));
    PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)mat), &size));
    PetscCall(PetscViewerASCIIPrintf(
      viewer,
      "MATMPIBINBCSR on %d ranks: diagonal and off-diagonal parts of type %s, block size %" PetscInt_FMT "\n",
      size, b->inner_type, mat->rmap->bs));
    if (b->coo_mirror)
      PetscCall(PetscViewerASCIIPrintf(
        viewer,
        "COO mirror on: entries of off-diagonal blocks also fill the transposed place (routed to its owner)\n"));
    if (!b->A) PetscFunctionReturn(0);
    PetscCall(PetscViewerASCIIPushSynchronized(viewer));
    PetscCall(PetscViewerGetSubViewer(viewer, PETSC_COMM_SELF, &sv));
    PetscCall(PetscViewerASCIIPrintf(
      sv, "[%d] rows %" PetscInt_FMT " to %" PetscInt_FMT ", %" PetscInt_FMT " ghost block columns\n", rank,
      mat->rmap->rstart, mat->rmap->rend, static_cast<PetscInt>(b->garray.size())));
    PetscCall(PetscViewerASCIIPushTab(sv));
    PetscCall(PetscViewerASCIIPrintf(sv, "[%d] diagonal part:\n", rank));
    PetscCall(MatView(b->A, sv));
    if (b->B) {
      PetscCall(PetscViewerASCIIPrintf(sv, "[%d] off-diagonal part:\n", rank));
      PetscCall(MatView(b->B, sv));
    }
    PetscCall(PetscViewerASCIIPopTab(sv));
    PetscCall(PetscViewerRestoreSubViewer(viewer, PETSC_COMM_SELF, &sv));
    PetscCall(PetscViewerFlush(viewer));
    PetscCall(PetscViewerASCIIPopSynchronized(viewer));
    PetscFunctionReturn(0);
  }
  /* values (ASCII, binary, draw, ...): through an MPIAIJ copy, whose viewers write every format */
  Mat T;
  PetscCall(MatConvert_MPIBinBCSR_MPIAIJ(mat, MATMPIAIJ, MAT_INITIAL_MATRIX, &T));
  PetscCall(PetscObjectSetName((PetscObject)T, ((PetscObject)mat)->name));
  PetscUseTypeMethod(T, view, viewer);
  PetscCall(MatDestroy(&T));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRCopyConfig(Mat from, Mat to)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(from), *c = MPIBinBCSR(to);

  PetscFunctionBegin;
  PetscCall(PetscStrncpy(c->inner_type, b->inner_type, sizeof(c->inner_type)));
  c->part_options       = b->part_options;
  c->ignore_new_offdiag = b->ignore_new_offdiag;
  c->donotstash         = b->donotstash;
  c->bin_width          = b->bin_width;
  c->precision_set      = b->precision_set;
  c->precision          = b->precision;
  c->streams            = b->streams;
  c->prefetch           = b->prefetch;
  c->xload              = b->xload;
  c->tune               = b->tune;
  c->tune_cache         = b->tune_cache;
  c->kernel             = b->kernel;
  c->sym                = b->sym;
  c->coo_mirror         = b->coo_mirror;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatDuplicate_MPIBinBCSR(Mat mat, MatDuplicateOption op, Mat *newmat)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  Mat             C;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRCreateLike_Private(mat, ((PetscObject)mat)->type_name, &C));
  PetscCall(PetscLayoutSetUp(C->rmap));
  PetscCall(PetscLayoutSetUp(C->cmap));
  PetscCall(MatMPIBinBCSRCopyConfig(mat, C));
  Mat_MPIBinBCSR *c = MPIBinBCSR(C);
  c->garray         = b->garray;
  c->compressed     = b->compressed;
  c->b_staging      = b->b_staging;
  if (op != MAT_COPY_VALUES)
    for (auto &e : c->b_staging) e.second = 0;
  if (b->A) PetscCall(MatDuplicate(b->A, op, &c->A));
  if (b->B) PetscCall(MatDuplicate(b->B, op, &c->B));
  if (b->lvec) PetscCall(VecDuplicate(b->lvec, &c->lvec));
  if (b->Mvctx) PetscCall(VecScatterCopy(b->Mvctx, &c->Mvctx));
  C->preallocated = mat->preallocated;
  C->assembled    = mat->assembled;
  C->nonzerostate = mat->nonzerostate;
  *newmat         = C;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatCopy_MPIBinBCSR(Mat A, Mat B, MatStructure str)
{
  PetscBool same;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)B, MATMPIBINBCSR, &same));
  if (same) {
    Mat_MPIBinBCSR *a = MPIBinBCSR(A), *b = MPIBinBCSR(B);
    same =
      (a->compressed && b->compressed && a->garray == b->garray && a->B && b->B) ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &same, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)A)));
    if (same) {
      PetscCall(MatCopy(a->A, b->A, str));
      PetscCall(MatCopy(a->B, b->B, str));
      PetscCall(PetscObjectStateIncrease((PetscObject)B));
      PetscFunctionReturn(0);
    }
  }
  PetscCall(RefillByRows(A, B));
  PetscFunctionReturn(0);
}
