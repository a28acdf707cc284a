/* MATMPIBINBCSR: constructor, destructor, preallocation answers, options and the bin-width /
   precision setters (forwarded to both parts). The layout is described in mpibinbcsr.h. */
#include "mpibinbcsr.h"

#include <algorithm>
#include <cstring>

static PetscErrorCode MatDestroy_MPIBinBCSR(Mat mat)
{
  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRResetParts(mat));
  delete MPIBinBCSR(mat);
  mat->data = nullptr;
  PetscCall(PetscObjectChangeTypeName((PetscObject)mat, nullptr));
  const char *names[] = {"MatBinBCSRSetSymmetricStorage_C", "MatBinBCSRGetSymmetricStorage_C", "MatBinBCSRSetCOOMirror_C", "MatBinBCSRGetCOOMirror_C", "MatBinBCSRSetStreams_C", "MatBinBCSRGetStreams_C", "MatBinBCSRSetTune_C", "MatBinBCSRGetTune_C", "MatBinBCSRSetTuneCache_C", "MatBinBCSRGetTuneCache_C", "MatMPIAIJSetPreallocation_C", "MatMPIBAIJSetPreallocation_C", "MatSetPreallocationCOO_C", "MatSetValuesCOO_C", "MatMultDotLocal_C", "MatGetDiagonalBlock_C", "MatBinBCSRSetBinWidth_C", "MatBinBCSRGetBinWidth_C", "MatBinBCSRSetPrecision_C", "MatBinBCSRGetPrecision_C", "MatConvert_mpibinbcsr_mpiaij_C", "MatConvert_mpibinbcsr_hypre_C", "MatProductSetFromOptions_anytype_C", "MatAXPYGetPreallocation_C"};
  for (const char *name : names) PetscCall(PetscObjectComposeFunction((PetscObject)mat, name, (void (*)(void)) nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMPIBinBCSRSetUpLayouts(Mat mat)
{
  PetscFunctionBegin;
  PetscCall(PetscLayoutSetUp(mat->rmap));
  PetscCall(PetscLayoutSetUp(mat->cmap));
  if (mat->rmap->bs < 1) PetscCall(PetscLayoutSetBlockSize(mat->rmap, 1));
  if (mat->cmap->bs < 1) PetscCall(PetscLayoutSetBlockSize(mat->cmap, 1));
  PetscFunctionReturn(0);
}

/* Creates the diagonal part from the layouts of mat; B is created when the columns are compressed. */
static PetscErrorCode CreateDiagonalPart(Mat mat)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRSetUpLayouts(mat));
  PetscCheck(mat->rmap->bs == mat->cmap->bs, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_INCOMP, "MATMPIBINBCSR needs equal row and column block sizes (%" PetscInt_FMT " vs %" PetscInt_FMT ")", mat->rmap->bs, mat->cmap->bs);
  PetscCall(MatMPIBinBCSRResetParts(mat));
  PetscCall(MatMPIBinBCSRCreatePart(mat, mat->rmap->n, mat->cmap->n, &b->A));
  PetscFunctionReturn(0);
}

static PetscErrorCode AllowNewAllocations(Mat part)
{
  PetscBool isbin;

  PetscFunctionBegin;
  /* AIJ-like inner types: entries beyond the preallocation are allowed (slowly), as in MatSetUp. */
  PetscCall(PetscObjectTypeCompare((PetscObject)part, MATSEQBINBCSR, &isbin));
  if (!isbin) PetscCall(MatSetOption(part, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMPIAIJSetPreallocation_MPIBinBCSR(Mat mat, PetscInt d_nz, const PetscInt d_nnz[], PetscInt o_nz, const PetscInt o_nnz[])
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRSetUpLayouts(mat));
  if (mat->rmap->bs != mat->cmap->bs) { /* a layout the bins cannot hold (PCGAMG's prolongators, made in the operator's type) */
    PetscCall(PetscInfo(mat, "Row and column block sizes %" PetscInt_FMT " and %" PetscInt_FMT " differ: the matrix becomes %s\n", mat->rmap->bs, mat->cmap->bs, MATMPIAIJ));
    PetscCall(MatSetType(mat, MATMPIAIJ));
    PetscCall(MatMPIAIJSetPreallocation(mat, d_nz, d_nnz, o_nz, o_nnz));
    PetscFunctionReturn(0);
  }
  (void)o_nz;
  (void)o_nnz; /* B is sized exactly at the first final assembly */
  PetscCall(CreateDiagonalPart(mat));
  PetscCall(MatSeqAIJSetPreallocation(b->A, d_nz, d_nnz));
  PetscCall(AllowNewAllocations(b->A));
  mat->preallocated = PETSC_TRUE;
  mat->assembled    = PETSC_FALSE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMPIBAIJSetPreallocation_MPIBinBCSR(Mat mat, PetscInt bs, PetscInt d_nz, const PetscInt d_nnz[], PetscInt o_nz, const PetscInt o_nnz[])
{
  Mat_MPIBinBCSR       *b = MPIBinBCSR(mat);
  std::vector<PetscInt> dnnz;

  PetscFunctionBegin;
  (void)o_nz;
  (void)o_nnz;
  PetscCall(MatSetBlockSize(mat, PetscAbs(bs)));
  PetscCall(CreateDiagonalPart(mat));
  bs = mat->rmap->bs;
  const PetscInt mbs = mat->rmap->n / bs, nbs = mat->cmap->n / bs;
  if (d_nnz) dnnz.assign(d_nnz, d_nnz + mbs);
  else dnnz.assign(mbs, d_nz == PETSC_DEFAULT || d_nz == PETSC_DECIDE ? PetscMin(5, nbs) : PetscMin(d_nz, nbs));
  PetscCall(MatXAIJSetPreallocation(b->A, bs, dnnz.data(), nullptr, nullptr, nullptr));
  PetscCall(AllowNewAllocations(b->A));
  mat->preallocated = PETSC_TRUE;
  mat->assembled    = PETSC_FALSE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetUp_MPIBinBCSR(Mat mat)
{
  PetscFunctionBegin;
  if (!mat->preallocated) PetscCall(MatMPIAIJSetPreallocation_MPIBinBCSR(mat, PETSC_DEFAULT, nullptr, PETSC_DEFAULT, nullptr));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetBinWidth_MPIBinBCSR(Mat mat, PetscInt bw)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCheck(bw >= 1, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_OUTOFRANGE, "bin width must be >= 1, got %" PetscInt_FMT, bw);
  b->bin_width = bw;
  if (b->A) PetscCall(MatBinBCSRSetBinWidth(b->A, bw));
  if (b->B) PetscCall(MatBinBCSRSetBinWidth(b->B, bw));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetBinWidth_MPIBinBCSR(Mat mat, PetscInt *bw)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  *bw = b->bin_width;
  if (b->A) PetscCall(MatBinBCSRGetBinWidth(b->A, bw));
  if (!*bw) *bw = b->bin_width;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetStreams_MPIBinBCSR(Mat mat, PetscInt streams)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->streams = streams;
  if (b->A) PetscCall(MatBinBCSRSetStreams(b->A, streams));
  if (b->B) PetscCall(MatBinBCSRSetStreams(b->B, streams));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetStreams_MPIBinBCSR(Mat mat, PetscInt *streams)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetStreams(b->A, streams));
  else *streams = b->streams ? b->streams : BINBCSR_DEFAULT_STREAMS;
  PetscFunctionReturn(0);
}

/* Each rank tunes its own parts (diagonal and off-diagonal) when their layouts are built. */
static PetscErrorCode MatBinBCSRSetTune_MPIBinBCSR(Mat mat, MatBinBCSRTune t)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->tune = (PetscInt)t;
  if (b->A) PetscCall(MatBinBCSRSetTune(b->A, t));
  if (b->B) PetscCall(MatBinBCSRSetTune(b->B, t));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetTune_MPIBinBCSR(Mat mat, MatBinBCSRTune *t)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetTune(b->A, t));
  else *t = b->tune == (PetscInt)MAT_BINBCSR_TUNE_OFF ? MAT_BINBCSR_TUNE_OFF : MAT_BINBCSR_TUNE_AUTO;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetTuneCache_MPIBinBCSR(Mat mat, PetscBool flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->tune_cache = flg ? 1 : 0;
  if (b->A) PetscCall(MatBinBCSRSetTuneCache(b->A, flg));
  if (b->B) PetscCall(MatBinBCSRSetTuneCache(b->B, flg));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetTuneCache_MPIBinBCSR(Mat mat, PetscBool *flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (b->A) PetscCall(MatBinBCSRGetTuneCache(b->A, flg));
  else *flg = b->tune_cache == 0 ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetPrecision_MPIBinBCSR(Mat mat, MatBinBCSRPrecision p)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  b->precision_set = PETSC_TRUE;
  b->precision     = p;
  if (b->A) PetscCall(MatBinBCSRSetPrecision(b->A, p));
  if (b->B) PetscCall(MatBinBCSRSetPrecision(b->B, p));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetPrecision_MPIBinBCSR(Mat mat, MatBinBCSRPrecision *p)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  *p = b->precision;
  if (b->A && !b->precision_set) PetscCall(MatBinBCSRGetPrecision(b->A, p));
  PetscFunctionReturn(0);
}

/* Symmetric storage applies to the diagonal part: the off-diagonal part stays full, so every rank
   multiplies its own rows without sending transposed contributions to other ranks. */
static PetscErrorCode MatBinBCSRSetSymmetricStorage_MPIBinBCSR(Mat mat, PetscBool flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (flg == b->sym) PetscFunctionReturn(0);
  PetscCheck(!flg || mat->rmap->N < 0 || mat->cmap->N < 0 || mat->rmap->N == mat->cmap->N, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_SIZ, "Symmetric storage needs a square matrix, this one is %" PetscInt_FMT " x %" PetscInt_FMT, mat->rmap->N, mat->cmap->N);
  PetscCheck(!mat->assembled && !b->compressed, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONGSTATE, "Symmetric storage must be chosen before the layout is built (first final assembly or COO preallocation)");
  if (b->A) PetscCall(MatBinBCSRSetSymmetricStorage(b->A, flg));
  b->sym = flg;
  if (flg) {
    PetscCall(MatSetOption(mat, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(mat, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetSymmetricStorage_MPIBinBCSR(Mat mat, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = MPIBinBCSR(mat)->sym;
  PetscFunctionReturn(0);
}

/* The mirror is applied to the whole COO list before it is routed (a mirrored entry may belong to
   another rank's rows); the parts get plain lists. */
static PetscErrorCode MatBinBCSRSetCOOMirror_MPIBinBCSR(Mat mat, PetscBool flg)
{
  PetscFunctionBegin;
  MPIBinBCSR(mat)->coo_mirror = flg;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetCOOMirror_MPIBinBCSR(Mat mat, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = MPIBinBCSR(mat)->coo_mirror;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatGetDiagonalBlock_MPIBinBCSR(Mat mat, Mat *a)
{
  PetscFunctionBegin;
  *a = MPIBinBCSR(mat)->A;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetFromOptions_MPIBinBCSR(Mat mat, PetscOptionItems *PetscOptionsObject)
{
  Mat_MPIBinBCSR     *b  = MPIBinBCSR(mat);
  PetscInt            bw = b->bin_width;
  MatBinBCSRPrecision p  = b->precision;
  char                inner[64];
  PetscBool           flg, sym;

  PetscFunctionBegin;
  PetscOptionsHeadBegin(PetscOptionsObject, "MATMPIBINBCSR options");
  PetscCall(PetscOptionsString("-mat_mpibinbcsr_inner_type", "Type of the diagonal and off-diagonal parts", "MATMPIBINBCSR", b->inner_type, inner, sizeof(inner), &flg));
  if (flg) {
    PetscCheck(!b->A, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONGSTATE, "-mat_mpibinbcsr_inner_type must be set before preallocation");
    PetscCall(PetscStrncpy(b->inner_type, inner, sizeof(b->inner_type)));
  }
  PetscCall(PetscOptionsInt("-mat_binbcsr_bin_width", "Rows per bin", "MatBinBCSRSetBinWidth", bw, &bw, &flg));
  if (flg) PetscCall(MatBinBCSRSetBinWidth_MPIBinBCSR(mat, bw));
  PetscCall(PetscOptionsEnum("-mat_binbcsr_precision", "Value storage", "MatBinBCSRSetPrecision", MatBinBCSRPrecisions, (PetscEnum)p, (PetscEnum *)&p, &flg));
  if (flg) PetscCall(MatBinBCSRSetPrecision_MPIBinBCSR(mat, p));
  sym = b->sym;
  PetscCall(PetscOptionsBool("-mat_binbcsr_symmetric_storage", "Store the upper triangle of the diagonal part only (symmetric matrices; the lower triangle given is ignored)", "MatBinBCSRSetSymmetricStorage", sym, &sym, &flg));
  if (flg) PetscCall(MatBinBCSRSetSymmetricStorage_MPIBinBCSR(mat, sym));
  PetscCall(PetscOptionsBool("-mat_binbcsr_coo_mirror", "COO entries of off-diagonal blocks also fill the transposed place (give one triangle of a symmetric matrix)", "MatBinBCSRSetCOOMirror", b->coo_mirror, &b->coo_mirror, nullptr));
  {
    PetscInt streams = b->streams ? b->streams : BINBCSR_DEFAULT_STREAMS;
    PetscCall(PetscOptionsInt("-mat_binbcsr_streams", "Runs of bins the product sweeps side by side (1, 2, 4, 8)", "MatBinBCSRSetStreams", streams, &streams, &flg));
    if (flg) PetscCall(MatBinBCSRSetStreams(mat, streams));
  }
  {
    PetscEnum t = (PetscEnum)(b->tune == (PetscInt)MAT_BINBCSR_TUNE_OFF ? MAT_BINBCSR_TUNE_OFF : MAT_BINBCSR_TUNE_AUTO);
    PetscBool c = b->tune_cache == 0 ? PETSC_FALSE : PETSC_TRUE;
    PetscCall(PetscOptionsEnum("-mat_binbcsr_tune", "Time bin widths and stream counts on this machine at the layout build (each rank its parts)", "MatBinBCSRSetTune", MatBinBCSRTunes, t, &t, &flg));
    if (flg) PetscCall(MatBinBCSRSetTune_MPIBinBCSR(mat, (MatBinBCSRTune)t));
    PetscCall(PetscOptionsBool("-mat_binbcsr_tune_cache", "Read and write the tuner's cache file ($XDG_CACHE_HOME/petscbinbcsr/)", "MatBinBCSRSetTuneCache", c, &c, &flg));
    if (flg) PetscCall(MatBinBCSRSetTuneCache_MPIBinBCSR(mat, c));
  }
  PetscCall(MatBinBCSRKernelFromOptions_Private(PetscOptionsObject, mat, b->kernel));
  PetscOptionsHeadEnd();
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetOption_MPIBinBCSR(Mat mat, MatOption op, PetscBool flg)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  switch (op) {
  case MAT_NEW_NONZERO_LOCATIONS:
    b->ignore_new_offdiag = flg ? PETSC_FALSE : PETSC_TRUE;
    /* fall through */
  case MAT_NEW_NONZERO_ALLOCATION_ERR:
  case MAT_NEW_NONZERO_LOCATION_ERR:
  case MAT_UNUSED_NONZERO_LOCATION_ERR:
  case MAT_KEEP_NONZERO_PATTERN:
  case MAT_IGNORE_ZERO_ENTRIES:
  case MAT_USE_INODES:
    b->part_options.emplace_back(op, flg);
    if (b->A) PetscCall(MatSetOption(b->A, op, flg));
    if (b->B) PetscCall(MatSetOption(b->B, op, flg));
    break;
  case MAT_ROW_ORIENTED:
    b->roworiented = flg; /* our MatSetValues reads values in this order; the parts get rows */
    break;
  case MAT_IGNORE_OFF_PROC_ENTRIES:
    b->donotstash = flg;
    break;
  case MAT_SUBMAT_SINGLEIS: /* PCASM: one index set on every rank (passed on to the AIJ shadow) */
    mat->submat_singleis = flg;
    break;
  case MAT_SYMMETRIC:
  case MAT_SPD:
  case MAT_HERMITIAN:
  case MAT_STRUCTURALLY_SYMMETRIC:
  case MAT_SYMMETRY_ETERNAL:
  case MAT_STRUCTURAL_SYMMETRY_ETERNAL:
  case MAT_SPD_ETERNAL:
    /* a property of the whole matrix (kept by MatSetOption itself); the diagonal part inherits it */
    if (b->A) PetscCall(MatSetOption(b->A, op, flg));
    b->part_options.emplace_back(op, flg);
    break;
  default:
    PetscCall(PetscInfo(mat, "Option %s ignored\n", MatOptions[op]));
    break;
  }
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRCreatePart(Mat mat, PetscInt m, PetscInt n, Mat *part)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatCreate(PETSC_COMM_SELF, part));
  PetscCall(MatSetSizes(*part, m, n, m, n));
  PetscCall(MatSetBlockSizes(*part, mat->rmap->bs, mat->cmap->bs));
  PetscCall(MatSetType(*part, b->inner_type));
  if (b->bin_width) PetscCall(MatBinBCSRSetBinWidth(*part, b->bin_width));
  if (b->precision_set) PetscCall(MatBinBCSRSetPrecision(*part, b->precision));
  if (b->streams) PetscCall(MatBinBCSRSetStreams(*part, b->streams));
  if (b->tune >= 0) PetscCall(MatBinBCSRSetTune(*part, (MatBinBCSRTune)b->tune));
  if (b->tune_cache >= 0) PetscCall(MatBinBCSRSetTuneCache(*part, b->tune_cache ? PETSC_TRUE : PETSC_FALSE));
  if (b->kernel) PetscCall(MatBinBCSRSetKernel(*part, b->kernel));
  if (b->sym && part == &b->A) PetscCall(MatBinBCSRSetSymmetricStorage(*part, PETSC_TRUE)); /* B stays full */
  for (const auto &[op, flg] : b->part_options) {
    const bool wholematrix = op == MAT_SYMMETRIC || op == MAT_SPD || op == MAT_HERMITIAN || op == MAT_STRUCTURALLY_SYMMETRIC || op == MAT_SYMMETRY_ETERNAL || op == MAT_STRUCTURAL_SYMMETRY_ETERNAL || op == MAT_SPD_ETERNAL;
    if (wholematrix && part != &b->A) continue; /* not a property of the off-diagonal part (even when it happens to be square) */
    PetscCall(MatSetOption(*part, op, flg));
  }
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRResetParts(Mat mat)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatDestroy(&b->A));
  PetscCall(MatDestroy(&b->B));
  PetscCall(VecDestroy(&b->lvec));
  PetscCall(VecScatterDestroy(&b->Mvctx));
  PetscCall(MatMPIBinBCSRDestroyCoo(mat));
  b->garray.clear();
  b->b_staging.clear();
  b->stash_row.clear();
  b->stash_col.clear();
  b->stash_val.clear();
  b->compressed         = PETSC_FALSE;
  b->offdiag_rows_known = PETSC_FALSE;
  b->offdiag_rows.clear();
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRSetUpScatter(Mat mat)
{
  Mat_MPIBinBCSR *b  = MPIBinBCSR(mat);
  const PetscInt  bs = mat->cmap->bs, ng = static_cast<PetscInt>(b->garray.size());
  IS              from, to;
  Vec             gvec;

  PetscFunctionBegin;
  PetscCall(VecDestroy(&b->lvec));
  PetscCall(VecScatterDestroy(&b->Mvctx));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, ng * bs, &b->lvec));
  PetscCall(VecSetBlockSize(b->lvec, bs));
  PetscCall(ISCreateBlock(PetscObjectComm((PetscObject)mat), bs, ng, b->garray.data(), PETSC_COPY_VALUES, &from));
  PetscCall(ISCreateStride(PETSC_COMM_SELF, ng * bs, 0, 1, &to));
  PetscCall(VecCreateMPIWithArray(PetscObjectComm((PetscObject)mat), bs, mat->cmap->n, mat->cmap->N, nullptr, &gvec));
  PetscCall(VecScatterCreate(gvec, from, b->lvec, to, &b->Mvctx));
  PetscCall(VecDestroy(&gvec));
  PetscCall(ISDestroy(&from));
  PetscCall(ISDestroy(&to));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRGhostIndex(Mat mat, PetscInt gcol, PetscInt *lcol)
{
  Mat_MPIBinBCSR *b   = MPIBinBCSR(mat);
  const PetscInt  bs  = mat->cmap->bs;
  const PetscInt  blk = gcol / bs;
  const auto      it  = std::lower_bound(b->garray.begin(), b->garray.end(), blk);

  PetscFunctionBegin;
  *lcol = (it != b->garray.end() && *it == blk) ? static_cast<PetscInt>(it - b->garray.begin()) * bs + gcol % bs : -1;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRBuildSendSF(MPI_Comm comm, PetscInt nsend, const PetscMPIInt dest[], PetscSF *sf, PetscInt *nrecv)
{
  PetscMPIInt size;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<PetscMPIInt> scount(size, 0), rcount(size), rdispl(size), offset_at_dest(size);
  for (PetscInt q = 0; q < nsend; q++) scount[dest[q]]++;
  PetscCallMPI(MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, comm));
  PetscInt total = 0;
  for (PetscMPIInt s = 0; s < size; s++) {
    rdispl[s] = static_cast<PetscMPIInt>(total);
    total += rcount[s];
  }
  /* each sender learns where its entries start in each receiver's root array */
  PetscCallMPI(MPI_Alltoall(rdispl.data(), 1, MPI_INT, offset_at_dest.data(), 1, MPI_INT, comm));
  PetscSFNode *remote;
  PetscCall(PetscMalloc1(nsend, &remote));
  for (PetscInt q = 0; q < nsend; q++) {
    remote[q].rank  = dest[q];
    remote[q].index = offset_at_dest[dest[q]]++;
  }
  PetscCall(PetscSFCreate(comm, sf));
  PetscCall(PetscSFSetGraph(*sf, total, nsend, nullptr, PETSC_OWN_POINTER, remote, PETSC_OWN_POINTER));
  PetscCall(PetscSFSetUp(*sf));
  *nrecv = total;
  PetscFunctionReturn(0);
}

/*MC
   MATMPIBINBCSR - "mpibinbcsr": the parallel BIN-CSR / BIN-BCSR matrix. Each rank stores its rows as
   a diagonal part and an off-diagonal part with compressed columns, both MATSEQBINBCSR; the ghost
   exchange of MatMult is overlapped with the diagonal-part product. Chosen by -mat_type binbcsr on
   more than one rank.

   Options: -mat_binbcsr_bin_width, -mat_binbcsr_precision (forwarded to both parts),
            -mat_binbcsr_symmetric_storage (the diagonal part only; the off-diagonal part stays full),
            -mat_mpibinbcsr_inner_type (type of the parts, default seqbinbcsr).
M*/
PetscErrorCode MatCreate_MPIBinBCSR(Mat mat)
{
  PetscFunctionBegin;
  auto *b = new Mat_MPIBinBCSR();
  PetscCall(PetscStrncpy(b->inner_type, MATSEQBINBCSR, sizeof(b->inner_type)));
  mat->data = b;
  PetscCall(PetscMemzero(mat->ops, sizeof(struct _MatOps)));
  mat->ops->destroy             = MatDestroy_MPIBinBCSR;
  mat->ops->setup               = MatSetUp_MPIBinBCSR;
  mat->ops->setfromoptions      = MatSetFromOptions_MPIBinBCSR;
  mat->ops->setoption           = MatSetOption_MPIBinBCSR;
  mat->ops->setvalues           = MatSetValues_MPIBinBCSR;
  mat->ops->assemblybegin       = MatAssemblyBegin_MPIBinBCSR;
  mat->ops->assemblyend         = MatAssemblyEnd_MPIBinBCSR;
  mat->ops->mult                = MatMult_MPIBinBCSR;
  mat->ops->multadd             = MatMultAdd_MPIBinBCSR;
  mat->ops->multtranspose       = MatMultTranspose_MPIBinBCSR;
  mat->ops->multtransposeadd    = MatMultTransposeAdd_MPIBinBCSR;
  mat->ops->getdiagonal         = MatGetDiagonal_MPIBinBCSR;
  mat->ops->diagonalset         = MatDiagonalSet_MPIBinBCSR;
  mat->ops->invertblockdiagonal = MatInvertBlockDiagonal_MPIBinBCSR;
  mat->ops->invertvariableblockdiagonal = MatInvertVariableBlockDiagonal_MPIBinBCSR;
  mat->ops->sor                 = MatSOR_MPIBinBCSR;
  mat->ops->multdiagonalblock   = MatMultDiagonalBlock_MPIBinBCSR;
  mat->ops->scale               = MatScale_MPIBinBCSR;
  mat->ops->shift               = MatShift_MPIBinBCSR;
  mat->ops->zeroentries         = MatZeroEntries_MPIBinBCSR;
  mat->ops->zerorows            = MatZeroRows_MPIBinBCSR;
  mat->ops->zerorowscolumns     = MatZeroRowsColumns_MPIBinBCSR;
  mat->ops->getrow              = MatGetRow_MPIBinBCSR;
  mat->ops->restorerow          = MatRestoreRow_MPIBinBCSR;
  mat->ops->norm                = MatNorm_MPIBinBCSR;
  mat->ops->getinfo             = MatGetInfo_MPIBinBCSR;
  mat->ops->diagonalscale       = MatDiagonalScale_MPIBinBCSR;
  mat->ops->getrowmaxabs        = MatGetRowMaxAbs_MPIBinBCSR;
  mat->ops->getrowmax           = MatGetRowMax_MPIBinBCSR;
  mat->ops->getrowmin           = MatGetRowMin_MPIBinBCSR;
  mat->ops->getrowminabs        = MatGetRowMinAbs_MPIBinBCSR;
  mat->ops->getcolumnreductions = MatGetColumnReductions_MPIBinBCSR;
  mat->ops->missingdiagonal     = MatMissingDiagonal_MPIBinBCSR;
  mat->ops->equal               = MatEqual_MPIBinBCSR;
  mat->ops->getvalues           = MatGetValues_MPIBinBCSR;
  mat->ops->axpy                = MatAXPY_MPIBinBCSR;
  mat->ops->transpose           = MatTranspose_MPIBinBCSR;
  mat->ops->permute             = MatPermute_BinBCSR;
  mat->ops->issymmetric         = MatIsSymmetric_BinBCSR;
  mat->ops->findzerodiagonals   = MatFindZeroDiagonals_BinBCSR;
  mat->ops->findnonzerorows     = MatFindNonzeroRows_BinBCSR;
  mat->ops->setrandom           = MatSetRandom_BinBCSR;
  mat->ops->realpart            = MatRealPart_BinBCSR;
  mat->ops->imaginarypart       = MatImaginaryPart_BinBCSR;
  mat->ops->getrowij            = MatGetRowIJ_MPIBinBCSR;
  mat->ops->restorerowij        = MatRestoreRowIJ_MPIBinBCSR;
  mat->ops->getdiagonalblock    = MatGetDiagonalBlock_MPIBinBCSR;
  mat->ops->view                = MatView_MPIBinBCSR;
  mat->ops->load                = MatLoad_MPIBinBCSR;
  mat->ops->convertfrom         = MatConvertFrom_MPIBinBCSR;
  mat->ops->duplicate           = MatDuplicate_MPIBinBCSR;
  mat->ops->copy                = MatCopy_MPIBinBCSR;
  mat->ops->increaseoverlap     = MatIncreaseOverlap_BinBCSR;
  mat->ops->createsubmatrices   = MatCreateSubMatrices_BinBCSR;
  mat->ops->fdcoloringcreate    = MatFDColoringCreate_BinBCSR;
  mat->ops->fdcoloringsetup     = MatFDColoringSetUp_BinBCSR;
  mat->ops->fdcoloringapply     = MatFDColoringApply_BinBCSR;
  mat->ops->createsubmatricesmpi = MatCreateSubMatricesMPI_BinBCSR;
  mat->ops->createsubmatrix     = MatCreateSubMatrix_BinBCSR;
  mat->ops->creategraph         = MatCreateGraph_BinBCSR; /* PCGAMG, through the AIJ shadow */
  mat->ops->productsetfromoptions = MatProductSetFromOptions_BinBCSR;
  mat->assembled                = PETSC_FALSE;
  mat->insertmode               = NOT_SET_VALUES;

  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatMPIAIJSetPreallocation_C", MatMPIAIJSetPreallocation_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatMPIBAIJSetPreallocation_C", MatMPIBAIJSetPreallocation_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatSetPreallocationCOO_C", MatSetPreallocationCOO_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatSetValuesCOO_C", MatSetValuesCOO_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatMultDotLocal_C", MatMultDotLocal_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatAXPYGetPreallocation_C", MatAXPYGetPreallocation_BinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatGetDiagonalBlock_C", MatGetDiagonalBlock_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetBinWidth_C", MatBinBCSRSetBinWidth_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetSymmetricStorage_C", MatBinBCSRSetSymmetricStorage_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetSymmetricStorage_C", MatBinBCSRGetSymmetricStorage_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetCOOMirror_C", MatBinBCSRSetCOOMirror_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetCOOMirror_C", MatBinBCSRGetCOOMirror_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetStreams_C", MatBinBCSRSetStreams_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetStreams_C", MatBinBCSRGetStreams_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetTune_C", MatBinBCSRSetTune_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetTune_C", MatBinBCSRGetTune_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetTuneCache_C", MatBinBCSRSetTuneCache_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetTuneCache_C", MatBinBCSRGetTuneCache_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetBinWidth_C", MatBinBCSRGetBinWidth_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRSetPrecision_C", MatBinBCSRSetPrecision_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatBinBCSRGetPrecision_C", MatBinBCSRGetPrecision_MPIBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatConvert_mpibinbcsr_mpiaij_C", MatConvert_MPIBinBCSR_MPIAIJ));
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatProductSetFromOptions_anytype_C", MatProductSetFromOptions_BinBCSR)); /* products with other types */
#if defined(PETSC_HAVE_HYPRE)
  PetscCall(PetscObjectComposeFunction((PetscObject)mat, "MatConvert_mpibinbcsr_hypre_C", MatConvert_BinBCSR_HYPRE));
#endif
  PetscCall(PetscObjectChangeTypeName((PetscObject)mat, MATMPIBINBCSR));
  PetscFunctionReturn(0);
}
