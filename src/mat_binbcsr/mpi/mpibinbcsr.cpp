/* MATMPIBINBCSR as a PETSc type: ops table, composed functions, constructor, destructor, preallocation
   answers, options, the parts and the ghost scatter; the configuration setters (forwarded to both
   parts) are mpibinbcsr_config.cpp. The layout is described in mpibinbcsr.h. */
#include "mpibinbcsr.h"
#include "../common/binbcsr_type.h"

#include <algorithm>
#include <cstring>

static PetscErrorCode MatDestroy_MPIBinBCSR(Mat); /* after the composed list, at the end */

PetscErrorCode MatMPIBinBCSRSetUpLayouts(Mat mat)
{
  PetscFunctionBegin;
  PetscCall(PetscLayoutSetUp(mat->rmap));
  PetscCall(PetscLayoutSetUp(mat->cmap));
  if (mat->rmap->bs < 1) PetscCall(PetscLayoutSetBlockSize(mat->rmap, 1));
  if (mat->cmap->bs < 1) PetscCall(PetscLayoutSetBlockSize(mat->cmap, 1));
  /* symmetric storage decided on the global layouts, so that every rank stops here, not only those
     whose diagonal part is not square (the others would wait in the next collective) */
  if (MPIBinBCSR(mat)->sym) {
    PetscBool congruent;
    PetscCall(PetscLayoutCompare(mat->rmap, mat->cmap, &congruent));
    PetscCheck(congruent, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_SIZ,
               "Symmetric storage needs a square matrix with equal row and column layouts, this one is "
               "%" PetscInt_FMT " x %" PetscInt_FMT,
               mat->rmap->N, mat->cmap->N);
  }
  PetscFunctionReturn(0);
}

/* Creates the diagonal part from the layouts of mat; B is created when the columns are compressed. */
static PetscErrorCode CreateDiagonalPart(Mat mat)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRSetUpLayouts(mat));
  PetscCheck(mat->rmap->bs == mat->cmap->bs, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_INCOMP,
             "MATMPIBINBCSR needs equal row and column block sizes (%" PetscInt_FMT " vs %" PetscInt_FMT ")",
             mat->rmap->bs, mat->cmap->bs);
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

static PetscErrorCode MatMPIAIJSetPreallocation_MPIBinBCSR(Mat mat, PetscInt d_nz, const PetscInt d_nnz[],
                                                           PetscInt o_nz, const PetscInt o_nnz[])
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRSetUpLayouts(mat));
  if (mat->rmap->bs !=
      mat->cmap
        ->bs) { /* a layout the bins cannot hold (PCGAMG's prolongators, made in the operator's type) */
    PetscCall(PetscInfo(mat,
                        "Row and column block sizes %" PetscInt_FMT " and %" PetscInt_FMT
                        " differ: the matrix becomes %s\n",
                        mat->rmap->bs, mat->cmap->bs, MATMPIAIJ));
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

static PetscErrorCode MatMPIBAIJSetPreallocation_MPIBinBCSR(Mat mat, PetscInt bs, PetscInt d_nz,
                                                            const PetscInt d_nnz[], PetscInt o_nz,
                                                            const PetscInt o_nnz[])
{
  Mat_MPIBinBCSR       *b = MPIBinBCSR(mat);
  std::vector<PetscInt> dnnz;

  PetscFunctionBegin;
  (void)o_nz;
  (void)o_nnz;
  PetscCall(MatSetBlockSize(mat, PetscAbs(bs)));
  PetscCall(CreateDiagonalPart(mat));
  bs                 = mat->rmap->bs;
  const PetscInt mbs = mat->rmap->n / bs, nbs = mat->cmap->n / bs;
  if (d_nnz) dnnz.assign(d_nnz, d_nnz + mbs);
  else
    dnnz.assign(mbs, d_nz == PETSC_DEFAULT || d_nz == PETSC_DECIDE ? PetscMin(5, nbs) : PetscMin(d_nz, nbs));
  PetscCall(MatXAIJSetPreallocation(b->A, bs, dnnz.data(), nullptr, nullptr, nullptr));
  PetscCall(AllowNewAllocations(b->A));
  mat->preallocated = PETSC_TRUE;
  mat->assembled    = PETSC_FALSE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetUp_MPIBinBCSR(Mat mat)
{
  PetscFunctionBegin;
  if (!mat->preallocated)
    PetscCall(MatMPIAIJSetPreallocation_MPIBinBCSR(mat, PETSC_DEFAULT, nullptr, PETSC_DEFAULT, nullptr));
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
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  char            inner[64];
  PetscBool       flg;

  PetscFunctionBegin;
  PetscOptionsHeadBegin(PetscOptionsObject, "MATMPIBINBCSR options");
  PetscCall(PetscOptionsString("-mat_mpibinbcsr_inner_type", "Type of the diagonal and off-diagonal parts",
                               "MATMPIBINBCSR", b->inner_type, inner, sizeof(inner), &flg));
  if (flg) {
    PetscCheck(!b->A, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONGSTATE,
               "-mat_mpibinbcsr_inner_type must be set before preallocation");
    PetscCall(PetscStrncpy(b->inner_type, inner, sizeof(b->inner_type)));
  }
  PetscCall(MatBinBCSRReadOptions_Private(
    mat, PetscOptionsObject)); /* the -mat_binbcsr_* options, forwarded to both parts */
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
  /* the matrix's prefix: the options a part reads itself (the tuner's size threshold, sample and
     budget) are then the matrix's, as its other -mat_binbcsr_* options are */
  PetscCall(MatSetOptionsPrefix(*part, ((PetscObject)mat)->prefix));
  PetscCall(MatSetSizes(*part, m, n, m, n));
  PetscCall(MatSetBlockSizes(*part, mat->rmap->bs, mat->cmap->bs));
  PetscCall(MatSetType(*part, b->inner_type));
  if (b->bin_width) PetscCall(MatBinBCSRSetBinWidth(*part, b->bin_width));
  if (b->precision_set) PetscCall(MatBinBCSRSetPrecision(*part, b->precision));
  if (b->streams) PetscCall(MatBinBCSRSetStreams(*part, b->streams));
  if (b->prefetch >= 0) PetscCall(MatBinBCSRSetPrefetch(*part, b->prefetch));
  if (b->xload >= 0) PetscCall(MatBinBCSRSetXLoad(*part, (MatBinBCSRXLoad)b->xload));
  if (b->kernel) PetscCall(MatBinBCSRSetKernel(*part, b->kernel));
  if (b->tune >= 0) PetscCall(MatBinBCSRSetTune(*part, (MatBinBCSRTune)b->tune));
  if (b->tune_cache >= 0) PetscCall(MatBinBCSRSetTuneCache(*part, b->tune_cache ? PETSC_TRUE : PETSC_FALSE));
  if (b->sym && part == &b->A) PetscCall(MatBinBCSRSetSymmetricStorage(*part, PETSC_TRUE)); /* B stays full */
  for (const auto &[op, flg] : b->part_options) {
    const bool wholematrix = op == MAT_SYMMETRIC || op == MAT_SPD || op == MAT_HERMITIAN ||
                             op == MAT_STRUCTURALLY_SYMMETRIC || op == MAT_SYMMETRY_ETERNAL ||
                             op == MAT_STRUCTURAL_SYMMETRY_ETERNAL || op == MAT_SPD_ETERNAL;
    if (wholematrix && part != &b->A)
      continue; /* not a property of the off-diagonal part (even when it happens to be square) */
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
  PetscCall(
    ISCreateBlock(PetscObjectComm((PetscObject)mat), bs, ng, b->garray.data(), PETSC_COPY_VALUES, &from));
  PetscCall(ISCreateStride(PETSC_COMM_SELF, ng * bs, 0, 1, &to));
  PetscCall(
    VecCreateMPIWithArray(PetscObjectComm((PetscObject)mat), bs, mat->cmap->n, mat->cmap->N, nullptr, &gvec));
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
  *lcol = (it != b->garray.end() && *it == blk)
            ? static_cast<PetscInt>(it - b->garray.begin()) * bs + gcol % bs
            : -1;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMPIBinBCSRBuildSendSF(MPI_Comm comm, PetscInt nsend, const PetscMPIInt dest[],
                                                     PetscSF *sf, PetscInt *nrecv)
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

/* The ops table: every operation of the type, one named slot each (slots not named stay NULL).
   Filled once, copied into each new matrix by MatCreate_MPIBinBCSR; named assignments, so the table
   reads the same whatever slots a PETSc version adds or drops. */
static const struct _MatOps &MatOps_MPIBinBCSR(void)
{
  static const struct _MatOps ops = [] {
    struct _MatOps o = {};
    BinBCSRSetCommonOps(o); /* common/: the same function for seq and mpi */
    /* values in and out, assembly */
    o.setvalues      = MatSetValues_MPIBinBCSR;
    o.getvalues      = MatGetValues_MPIBinBCSR;
    o.getrow         = MatGetRow_MPIBinBCSR;
    o.restorerow     = MatRestoreRow_MPIBinBCSR;
    o.getrowij       = MatGetRowIJ_MPIBinBCSR;
    o.restorerowij   = MatRestoreRowIJ_MPIBinBCSR;
    o.assemblybegin  = MatAssemblyBegin_MPIBinBCSR;
    o.assemblyend    = MatAssemblyEnd_MPIBinBCSR;
    o.setoption      = MatSetOption_MPIBinBCSR;
    o.setup          = MatSetUp_MPIBinBCSR;
    o.setfromoptions = MatSetFromOptions_MPIBinBCSR;
    o.zeroentries    = MatZeroEntries_MPIBinBCSR;
    /* products and the diagonal */
    o.mult                        = MatMult_MPIBinBCSR;
    o.multadd                     = MatMultAdd_MPIBinBCSR;
    o.multtranspose               = MatMultTranspose_MPIBinBCSR;
    o.multtransposeadd            = MatMultTransposeAdd_MPIBinBCSR;
    o.getdiagonal                 = MatGetDiagonal_MPIBinBCSR;
    o.getdiagonalblock            = MatGetDiagonalBlock_MPIBinBCSR;
    o.invertblockdiagonal         = MatInvertBlockDiagonal_MPIBinBCSR;
    o.invertvariableblockdiagonal = MatInvertVariableBlockDiagonal_MPIBinBCSR;
    o.sor                         = MatSOR_MPIBinBCSR;
    o.multdiagonalblock           = MatMultDiagonalBlock_MPIBinBCSR;
    /* value operations */
    o.scale           = MatScale_MPIBinBCSR;
    o.shift           = MatShift_MPIBinBCSR;
    o.diagonalset     = MatDiagonalSet_MPIBinBCSR;
    o.axpy            = MatAXPY_MPIBinBCSR;
    o.zerorows        = MatZeroRows_MPIBinBCSR;
    o.zerorowscolumns = MatZeroRowsColumns_MPIBinBCSR;
    o.norm            = MatNorm_MPIBinBCSR;
    o.getinfo         = MatGetInfo_MPIBinBCSR;
    /* rows and columns (mpibinbcsr_rowops.cpp) */
    o.diagonalscale       = MatDiagonalScale_MPIBinBCSR;
    o.getrowmaxabs        = MatGetRowMaxAbs_MPIBinBCSR;
    o.getrowmax           = MatGetRowMax_MPIBinBCSR;
    o.getrowmin           = MatGetRowMin_MPIBinBCSR;
    o.getrowminabs        = MatGetRowMinAbs_MPIBinBCSR;
    o.getcolumnreductions = MatGetColumnReductions_MPIBinBCSR;
    o.missingdiagonal     = MatMissingDiagonal_MPIBinBCSR;
    o.equal               = MatEqual_MPIBinBCSR;
    /* new matrices, view, load */
    o.transpose   = MatTranspose_MPIBinBCSR;
    o.duplicate   = MatDuplicate_MPIBinBCSR;
    o.copy        = MatCopy_MPIBinBCSR;
    o.convertfrom = MatConvertFrom_MPIBinBCSR;
    o.destroy     = MatDestroy_MPIBinBCSR;
    o.view        = MatView_MPIBinBCSR;
    o.load        = MatLoad_MPIBinBCSR;
    /* submatrices through the AIJ shadow (common/) */
    o.createsubmatricesmpi = MatCreateSubMatricesMPI_BinBCSR;
    o.createsubmatrix      = MatCreateSubMatrix_BinBCSR;
    return o;
  }();
  return ops;
}

/* The composed functions, composed by MatCreate_MPIBinBCSR and cleared by MatDestroy_MPIBinBCSR. */
static const BinBCSRComposed composed[] = {
  BINBCSR_COMPOSED("MatMPIAIJSetPreallocation_C", MatMPIAIJSetPreallocation_MPIBinBCSR),
  BINBCSR_COMPOSED("MatMPIBAIJSetPreallocation_C", MatMPIBAIJSetPreallocation_MPIBinBCSR),
  BINBCSR_COMPOSED("MatSetPreallocationCOO_C", MatSetPreallocationCOO_MPIBinBCSR),
  BINBCSR_COMPOSED("MatSetValuesCOO_C", MatSetValuesCOO_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetValuesCOOSingle_C", MatBinBCSRSetValuesCOOSingle_MPIBinBCSR),
  BINBCSR_COMPOSED("MatMultDotLocal_C", MatMultDotLocal_MPIBinBCSR),
  BINBCSR_COMPOSED("MatAXPYGetPreallocation_C", MatAXPYGetPreallocation_BinBCSR),
  BINBCSR_COMPOSED("MatGetDiagonalBlock_C", MatGetDiagonalBlock_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetBinWidth_C", MatBinBCSRSetBinWidth_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetSymmetricStorage_C", MatBinBCSRSetSymmetricStorage_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetSymmetricStorage_C", MatBinBCSRGetSymmetricStorage_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetCOOMirror_C", MatBinBCSRSetCOOMirror_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetCOOMirror_C", MatBinBCSRGetCOOMirror_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetStreams_C", MatBinBCSRSetStreams_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetStreams_C", MatBinBCSRGetStreams_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetPrefetch_C", MatBinBCSRSetPrefetch_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetPrefetch_C", MatBinBCSRGetPrefetch_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetXLoad_C", MatBinBCSRSetXLoad_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetXLoad_C", MatBinBCSRGetXLoad_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetTune_C", MatBinBCSRSetTune_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetTune_C", MatBinBCSRGetTune_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetTuneCache_C", MatBinBCSRSetTuneCache_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetTuneCache_C", MatBinBCSRGetTuneCache_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetBinWidth_C", MatBinBCSRGetBinWidth_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetPrecision_C", MatBinBCSRSetPrecision_MPIBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetPrecision_C", MatBinBCSRGetPrecision_MPIBinBCSR),
  BINBCSR_COMPOSED("MatConvert_mpibinbcsr_mpiaij_C", MatConvert_MPIBinBCSR_MPIAIJ),
  BINBCSR_COMPOSED("MatProductSetFromOptions_anytype_C", MatProductSetFromOptions_BinBCSR),
#if defined(PETSC_HAVE_HYPRE)
  BINBCSR_COMPOSED("MatConvert_mpibinbcsr_hypre_C", MatConvert_BinBCSR_HYPRE),
#endif
};

static PetscErrorCode MatDestroy_MPIBinBCSR(Mat mat)
{
  PetscFunctionBegin;
  PetscCall(MatMPIBinBCSRResetParts(mat));
  delete MPIBinBCSR(mat);
  mat->data = nullptr;
  PetscCall(PetscObjectChangeTypeName((PetscObject)mat, nullptr));
  PetscCall(BinBCSRComposeList((PetscObject)mat, composed, PETSC_TRUE));
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
  PetscCall(PetscMemcpy(mat->ops, &MatOps_MPIBinBCSR(), sizeof(struct _MatOps)));
  mat->assembled  = PETSC_FALSE;
  mat->insertmode = NOT_SET_VALUES;
  PetscCall(BinBCSRComposeList((PetscObject)mat, composed, PETSC_FALSE));
  PetscCall(PetscObjectChangeTypeName((PetscObject)mat, MATMPIBINBCSR));
  PetscFunctionReturn(0);
}
