/* MATMPIBINBCSR's settings (the -mat_binbcsr_* options and their MatBinBCSRSet/Get functions): kept by the
   matrix for the parts it makes later, and forwarded to the parts that exist (composed in
   mpibinbcsr.cpp). */
#include "mpibinbcsr.h"

/* A setting of the matrix applied to each part that exists (the parts made later get it from the
   matrix's own copy, MatMPIBinBCSRCreatePart). */
template <class T> static PetscErrorCode MatMPIBinBCSRSetOnParts(Mat mat, PetscErrorCode (*set)(Mat, T), T v)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(set(b->A, v));
  if (b->B) PetscCall(set(b->B, v));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetBinWidth_MPIBinBCSR(Mat mat, PetscInt bw)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCheck(bw >= 1, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_OUTOFRANGE,
             "bin width must be >= 1, got %" PetscInt_FMT, bw);
  b->bin_width = bw;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetBinWidth, bw));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetBinWidth_MPIBinBCSR(Mat mat, PetscInt *bw)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  *bw = b->bin_width;
  if (b->A) PetscCall(MatBinBCSRGetBinWidth(b->A, bw));
  if (!*bw) *bw = b->bin_width;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetStreams_MPIBinBCSR(Mat mat, PetscInt streams)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->streams = streams;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetStreams, streams));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetStreams_MPIBinBCSR(Mat mat, PetscInt *streams)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetStreams(b->A, streams));
  else *streams = b->streams ? b->streams : BINBCSR_DEFAULT_STREAMS;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetPrefetch_MPIBinBCSR(Mat mat, PetscInt bytes)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->prefetch = bytes;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetPrefetch, bytes));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetXLoad_MPIBinBCSR(Mat mat, MatBinBCSRXLoad xload)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->xload = (PetscInt)xload;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetXLoad, xload));
  PetscFunctionReturn(0);
}

/* the diagonal part's (each part tunes its own where it is not set) */
PetscErrorCode MatBinBCSRGetXLoad_MPIBinBCSR(Mat mat, MatBinBCSRXLoad *xload)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetXLoad(b->A, xload));
  else *xload = b->xload >= 0 ? (MatBinBCSRXLoad)b->xload : MAT_BINBCSR_XLOAD_LOADS;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetPrefetch_MPIBinBCSR(Mat mat, PetscInt *bytes)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetPrefetch(b->A, bytes));
  else *bytes = b->prefetch >= 0 ? b->prefetch : BINBCSR_DEFAULT_PREFETCH;
  PetscFunctionReturn(0);
}

/* Each rank tunes its own parts (diagonal and off-diagonal) when their layouts are built. */
PetscErrorCode MatBinBCSRSetTune_MPIBinBCSR(Mat mat, MatBinBCSRTune t)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->tune = (PetscInt)t;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetTune, t));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetTune_MPIBinBCSR(Mat mat, MatBinBCSRTune *t)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetTune(b->A, t));
  else *t = b->tune == (PetscInt)MAT_BINBCSR_TUNE_OFF ? MAT_BINBCSR_TUNE_OFF : MAT_BINBCSR_TUNE_AUTO;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetTuneCache_MPIBinBCSR(Mat mat, PetscBool flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->tune_cache = flg ? 1 : 0;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetTuneCache, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetTuneCache_MPIBinBCSR(Mat mat, PetscBool *flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetTuneCache(b->A, flg));
  else *flg = b->tune_cache == 0 ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetPrecision_MPIBinBCSR(Mat mat, MatBinBCSRPrecision p)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->precision_set = PETSC_TRUE;
  b->precision     = p;
  PetscCall(MatMPIBinBCSRSetOnParts(mat, MatBinBCSRSetPrecision, p));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetPrecision_MPIBinBCSR(Mat mat, MatBinBCSRPrecision *p)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  *p = b->precision;
  if (b->A && !b->precision_set) PetscCall(MatBinBCSRGetPrecision(b->A, p));
  PetscFunctionReturn(0);
}

/* Symmetric storage applies to the diagonal part: the off-diagonal part stays full, so every rank
   multiplies its own rows without sending transposed contributions to other ranks. */
PetscErrorCode MatBinBCSRSetSymmetricStorage_MPIBinBCSR(Mat mat, PetscBool flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (flg == b->sym) PetscFunctionReturn(0);
  PetscCheck(!flg || mat->rmap->N < 0 || mat->cmap->N < 0 || mat->rmap->N == mat->cmap->N,
             PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_SIZ,
             "Symmetric storage needs a square matrix, this one is %" PetscInt_FMT " x %" PetscInt_FMT,
             mat->rmap->N, mat->cmap->N);
  PetscCheck(
    !mat->assembled && !b->compressed, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONGSTATE,
    "Symmetric storage must be chosen before the layout is built (first final assembly or COO preallocation)");
  if (b->A) PetscCall(MatBinBCSRSetSymmetricStorage(b->A, flg));
  b->sym = flg;
  if (flg) {
    PetscCall(MatSetOption(mat, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(mat, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetSymmetricStorage_MPIBinBCSR(Mat mat, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = MPIBinBCSR(mat)->sym;
  PetscFunctionReturn(0);
}

/* The mirror is applied to the whole COO list before it is routed (a mirrored entry may belong to
   another rank's rows); the parts get plain lists. */
PetscErrorCode MatBinBCSRSetCOOMirror_MPIBinBCSR(Mat mat, PetscBool flg)
{
  PetscFunctionBegin;
  MPIBinBCSR(mat)->coo_mirror = flg;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetCOOMirror_MPIBinBCSR(Mat mat, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = MPIBinBCSR(mat)->coo_mirror;
  PetscFunctionReturn(0);
}
