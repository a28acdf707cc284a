/* MATSEQBINBCSR as a PETSc type: its options, configuration setters, ops table, composed functions,
   constructor and destructor. The storage is described in binbcsr.h; staging, MatSetValues and
   assembly: binbcsr_assembly.cpp; the layout build: binbcsr_build.cpp; products: binbcsr_mult.cpp;
   value operations: binbcsr_ops.cpp. */
#include "binbcsr.h"
#include "binbcsr_ops.h"
#include "../common/binbcsr_type.h"
#include "../kernels/binbcsr_value_kernels.h" /* binbcsr::row_extreme_kind */

static PetscErrorCode MatSetOption_SeqBinBCSR(Mat A, MatOption op, PetscBool flg)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  switch (op) {
  case MAT_ROW_ORIENTED:
    a->roworiented = flg;
    break;
  case MAT_NEW_NONZERO_LOCATIONS:
    a->nonew = flg ? 0 : 1;
    break;
  case MAT_NEW_NONZERO_LOCATION_ERR:
    a->nonew = flg ? -1 : 0;
    break;
  case MAT_NEW_NONZERO_ALLOCATION_ERR:
    a->nonew = flg ? -2 : 0;
    break;
  case MAT_UNUSED_NONZERO_LOCATION_ERR:
  case MAT_SYMMETRIC:
  case MAT_STRUCTURALLY_SYMMETRIC:
  case MAT_HERMITIAN:
  case MAT_SPD:
  case MAT_SYMMETRY_ETERNAL:
  case MAT_STRUCTURAL_SYMMETRY_ETERNAL:
  case MAT_SPD_ETERNAL:
  case MAT_IGNORE_OFF_PROC_ENTRIES:
  case MAT_NO_OFF_PROC_ENTRIES:
  case MAT_KEEP_NONZERO_PATTERN: /* the pattern is always kept: it is frozen at the first assembly */
  case MAT_IGNORE_ZERO_ENTRIES:
  case MAT_USE_HASH_TABLE:
  case MAT_IGNORE_LOWER_TRIANGULAR:
  case MAT_GETROW_UPPERTRIANGULAR:
  case MAT_SORTED_FULL:
  case MAT_STRUCTURE_ONLY:
  case MAT_USE_INODES:
  case MAT_FORM_EXPLICIT_TRANSPOSE:
    PetscCall(PetscInfo(A, "Option %s accepted (no effect on the storage)\n", MatOptions[op]));
    break;
  default:
    PetscCall(PetscInfo(A, "Option %s ignored\n", MatOptions[op]));
    break;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetBinWidth_SeqBinBCSR(Mat A, PetscInt bw)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (bw == PETSC_DEFAULT || bw == PETSC_DECIDE) {
    PetscCheck(
      !a->built || !a->bw_set || a->bw == BinBCSRDefaultBinWidth(a->bs), PETSC_COMM_SELF,
      PETSC_ERR_ARG_WRONGSTATE,
      "The bin width must be set before the layout is built (first final assembly or COO preallocation)");
    a->bw_set = PETSC_FALSE;
    PetscFunctionReturn(0);
  }
  PetscCheck(bw >= 1 && bw <= 1024, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "Bin width %" PetscInt_FMT " must lie in [1, 1024]", bw);
  PetscCheck(
    !a->built || bw == a->bw, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
    "The bin width must be set before the layout is built (first final assembly or COO preallocation)");
  a->bw     = bw;
  a->bw_set = PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetBinWidth_SeqBinBCSR(Mat A, PetscInt *bw)
{
  PetscFunctionBegin;
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  *bw               = (a->built || a->bw_set) ? a->bw : BinBCSRDefaultBinWidth(PetscAbs(A->rmap->bs));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetPrecision_SeqBinBCSR(Mat A, MatBinBCSRPrecision p)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const size_t    nv = (size_t)a->nslots * a->bs2;

  PetscFunctionBegin;
  PetscCheck(p == MAT_BINBCSR_PRECISION_DOUBLE || p == MAT_BINBCSR_PRECISION_SINGLE, PETSC_COMM_SELF,
             PETSC_ERR_ARG_OUTOFRANGE, "Unknown precision %d", (int)p);
  if (p == a->precision) PetscFunctionReturn(0);
  if (a->built) {
    /* the old array stays alive until the new one holds its values */
    void            *old_mem = a->val_mem;
    const size_t     old_map = a->val_map;
    const MatScalar *oldd    = a->val;
    const float     *olds    = a->valf;
    a->val_mem               = nullptr;
    a->val_map               = 0;
    PetscCall(MatSeqBinBCSRAllocValues_Private(a, p, nv, PETSC_FALSE));
    if (p == MAT_BINBCSR_PRECISION_SINGLE)
      for (size_t i = 0; i < nv; i++) a->valf[i] = (float)oldd[i];
    else
      for (size_t i = 0; i < nv; i++) a->val[i] = (MatScalar)olds[i];
    PetscCall(MatSeqBinBCSRReleaseValues_Private(old_mem, old_map));
    PetscCall(PetscObjectStateIncrease((PetscObject)A));
    a->precision = p;
    PetscCall(MatSeqBinBCSRRetune(A));
  }
  a->precision = p;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetSymmetricStorage_SeqBinBCSR(Mat A, PetscBool flg)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (flg == a->sym) PetscFunctionReturn(0);
  PetscCheck(
    !a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
    "Symmetric storage must be chosen before the layout is built (first final assembly, COO preallocation, conversion or load)");
  PetscCheck(!flg || A->rmap->N < 0 || A->cmap->N < 0 || A->rmap->N == A->cmap->N, PETSC_COMM_SELF,
             PETSC_ERR_ARG_SIZ,
             "Symmetric storage needs a square matrix, this one is %" PetscInt_FMT " x %" PetscInt_FMT,
             A->rmap->N, A->cmap->N);
  a->sym = flg;
  if (a->staging && flg) PetscCall(MatSeqBinBCSRStagingDropLower(A));
  if (flg) {
    PetscCall(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  }
  PetscFunctionReturn(0);
}

/* Settings that are a field of Mat_SeqBinBCSR and nothing more (the COO mirror, the streams, and the
   getters of precision and storage): written and read as they are, by one pair of functions. */
template <class T, T Mat_SeqBinBCSR::*field> static PetscErrorCode MatSeqBinBCSRSetField(Mat A, T v)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->*field = v;
  PetscFunctionReturn(0);
}

template <class T, T Mat_SeqBinBCSR::*field> static PetscErrorCode MatSeqBinBCSRGetField(Mat A, T *v)
{
  PetscFunctionBegin;
  *v = ((Mat_SeqBinBCSR *)A->data)->*field;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetFromOptions_SeqBinBCSR(Mat A, PetscOptionItems *PetscOptionsObject)
{
  PetscFunctionBegin;
  PetscOptionsHeadBegin(PetscOptionsObject, "MATSEQBINBCSR options");
  PetscCall(MatBinBCSRReadOptions_Private(A, PetscOptionsObject));
  PetscOptionsHeadEnd();
  PetscFunctionReturn(0);
}

static PetscErrorCode MatDestroy_SeqBinBCSR(Mat);

/* The ops table: every operation of the type, one named slot each (slots not named stay NULL, so
   PETSc's generic code runs or MatXXX reports the operation as missing). Filled once, copied into
   each new matrix by MatCreate_SeqBinBCSR. Named assignments rather than PETSc's positional
   initialiser, so the table reads the same whatever slots a PETSc version adds or drops. */
static const struct _MatOps &MatOps_SeqBinBCSR(void)
{
  static const struct _MatOps ops = [] {
    struct _MatOps o = {};
    BinBCSRSetCommonOps(o); /* common/: the same function for seq and mpi */
    /* values in and out, assembly */
    o.setvalues        = MatSetValues_SeqBinBCSR;
    o.setvaluesblocked = MatSetValuesBlocked_SeqBinBCSR;
    o.getvalues        = MatGetValues_SeqBinBCSR;
    o.getrow           = MatGetRow_SeqBinBCSR;
    o.restorerow       = MatRestoreRow_SeqBinBCSR;
    o.getrowij         = MatGetRowIJ_SeqBinBCSR; /* binbcsr_rowij.cpp */
    o.restorerowij     = MatRestoreRowIJ_SeqBinBCSR;
    o.assemblyend      = MatAssemblyEnd_SeqBinBCSR;
    o.setoption        = MatSetOption_SeqBinBCSR;
    o.setup            = MatSetUp_SeqBinBCSR;
    o.setfromoptions   = MatSetFromOptions_SeqBinBCSR;
    o.zeroentries      = MatZeroEntries_SeqBinBCSR;
    /* products and the diagonal */
    o.mult                        = MatMult_SeqBinBCSR;
    o.multadd                     = MatMultAdd_SeqBinBCSR;
    o.multtranspose               = MatMultTranspose_SeqBinBCSR;
    o.multtransposeadd            = MatMultTransposeAdd_SeqBinBCSR;
    o.getdiagonal                 = MatGetDiagonal_SeqBinBCSR;
    o.invertblockdiagonal         = MatInvertBlockDiagonal_SeqBinBCSR;
    o.invertvariableblockdiagonal = MatInvertVariableBlockDiagonal_SeqBinBCSR;
    o.sor                         = MatSOR_SeqBinBCSR;
    o.multdiagonalblock           = MatMultDiagonalBlock_SeqBinBCSR;
    /* value operations (binbcsr_ops.cpp) */
    o.scale           = MatScale_SeqBinBCSR;
    o.shift           = MatShift_SeqBinBCSR;
    o.diagonalset     = MatDiagonalSet_SeqBinBCSR;
    o.axpy            = MatAXPY_SeqBinBCSR;
    o.zerorows        = MatZeroRows_SeqBinBCSR;
    o.zerorowscolumns = MatZeroRowsColumns_SeqBinBCSR;
    o.norm            = MatNorm_SeqBinBCSR;
    o.getinfo         = MatGetInfo_SeqBinBCSR;
    /* rows and columns (binbcsr_rowops.cpp) */
    o.diagonalscale       = MatDiagonalScale_SeqBinBCSR;
    o.getrowmaxabs        = MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_max_abs>;
    o.getrowmax           = MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_max>;
    o.getrowmin           = MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_min>;
    o.getrowminabs        = MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_min_abs>;
    o.getcolumnreductions = MatGetColumnReductions_SeqBinBCSR;
    o.missingdiagonal     = MatMissingDiagonal_SeqBinBCSR;
    o.equal               = MatEqual_SeqBinBCSR;
    /* new matrices, view, load */
    o.transpose   = MatTranspose_SeqBinBCSR;
    o.duplicate   = MatDuplicate_SeqBinBCSR;
    o.copy        = MatCopy_SeqBinBCSR;
    o.convertfrom = MatConvertFrom_SeqBinBCSR;
    o.destroy     = MatDestroy_SeqBinBCSR;
    o.view        = MatView_SeqBinBCSR;
    o.load        = MatLoad_SeqBinBCSR;
    /* through the AIJ shadow (common/; MatCreateSubMatrix uses createsubmatrices on one rank) */
    o.creatempimatconcatenateseqmat = MatCreateMPIMatConcatenateSeqMat_BinBCSR;
    return o;
  }();
  return ops;
}

/* Streams set by the user: the layout build's tuner keeps them. */
static PetscErrorCode MatBinBCSRSetStreams_SeqBinBCSR(Mat A, PetscInt streams)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->streams     = streams;
  ((Mat_SeqBinBCSR *)A->data)->streams_set = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* The x load set by the user: the tuner keeps it (the bins' hint holds both modes' arrays: it takes
   effect at the next product). */
static PetscErrorCode MatBinBCSRSetXLoad_SeqBinBCSR(Mat A, MatBinBCSRXLoad xload)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->xload       = xload;
  ((Mat_SeqBinBCSR *)A->data)->xload_set   = PETSC_TRUE;
  ((Mat_SeqBinBCSR *)A->data)->xload_trial = 0; /* the user's choice stands */
  PetscFunctionReturn(0);
}

/* A prefetch distance set by the user: the tuner keeps it. */
static PetscErrorCode MatBinBCSRSetPrefetch_SeqBinBCSR(Mat A, PetscInt bytes)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->prefetch     = bytes;
  ((Mat_SeqBinBCSR *)A->data)->prefetch_set = PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetTune_SeqBinBCSR(Mat A, MatBinBCSRTune t)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->tune = (PetscInt)t;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetTune_SeqBinBCSR(Mat A, MatBinBCSRTune *t)
{
  PetscFunctionBegin;
  *t = ((Mat_SeqBinBCSR *)A->data)->tune == (PetscInt)MAT_BINBCSR_TUNE_OFF ? MAT_BINBCSR_TUNE_OFF
                                                                           : MAT_BINBCSR_TUNE_AUTO;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetTuneCache_SeqBinBCSR(Mat A, PetscBool flg)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->tune_cache = flg ? 1 : 0;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetTuneCache_SeqBinBCSR(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = ((Mat_SeqBinBCSR *)A->data)->tune_cache == 0 ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* The composed functions, composed by MatCreate_SeqBinBCSR and cleared by MatDestroy_SeqBinBCSR. */
static const BinBCSRComposed composed[] = {
  BINBCSR_COMPOSED("MatBinBCSRSetBinWidth_C", MatBinBCSRSetBinWidth_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetBinWidth_C", MatBinBCSRGetBinWidth_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetPrecision_C", MatBinBCSRSetPrecision_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetPrecision_C",
                   (&MatSeqBinBCSRGetField<MatBinBCSRPrecision, &Mat_SeqBinBCSR::precision>)),
  BINBCSR_COMPOSED("MatBinBCSRSetSymmetricStorage_C", MatBinBCSRSetSymmetricStorage_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetSymmetricStorage_C",
                   (&MatSeqBinBCSRGetField<PetscBool, &Mat_SeqBinBCSR::sym>)),
  BINBCSR_COMPOSED("MatBinBCSRSetCOOMirror_C",
                   (&MatSeqBinBCSRSetField<PetscBool, &Mat_SeqBinBCSR::coo_mirror>)),
  BINBCSR_COMPOSED("MatBinBCSRGetCOOMirror_C",
                   (&MatSeqBinBCSRGetField<PetscBool, &Mat_SeqBinBCSR::coo_mirror>)),
  BINBCSR_COMPOSED("MatBinBCSRSetStreams_C", MatBinBCSRSetStreams_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetStreams_C", (&MatSeqBinBCSRGetField<PetscInt, &Mat_SeqBinBCSR::streams>)),
  BINBCSR_COMPOSED("MatBinBCSRSetPrefetch_C", MatBinBCSRSetPrefetch_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetPrefetch_C", (&MatSeqBinBCSRGetField<PetscInt, &Mat_SeqBinBCSR::prefetch>)),
  BINBCSR_COMPOSED("MatBinBCSRSetXLoad_C", MatBinBCSRSetXLoad_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetXLoad_C", (&MatSeqBinBCSRGetField<MatBinBCSRXLoad, &Mat_SeqBinBCSR::xload>)),
  BINBCSR_COMPOSED("MatBinBCSRSetTune_C", MatBinBCSRSetTune_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetTune_C", MatBinBCSRGetTune_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetTuneCache_C", MatBinBCSRSetTuneCache_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRGetTuneCache_C", MatBinBCSRGetTuneCache_SeqBinBCSR),
  BINBCSR_COMPOSED("MatSeqAIJSetPreallocation_C", MatSeqAIJSetPreallocation_SeqBinBCSR),
  BINBCSR_COMPOSED("MatSeqBAIJSetPreallocation_C", MatSeqBAIJSetPreallocation_SeqBinBCSR),
  BINBCSR_COMPOSED("MatSetPreallocationCOO_C", MatSetPreallocationCOO_SeqBinBCSR),
  BINBCSR_COMPOSED("MatSetValuesCOO_C", MatSetValuesCOO_SeqBinBCSR),
  BINBCSR_COMPOSED("MatBinBCSRSetValuesCOOSingle_C", MatBinBCSRSetValuesCOOSingle_SeqBinBCSR),
  BINBCSR_COMPOSED("MatMultDotLocal_C", MatMultDotLocal_SeqBinBCSR),
  BINBCSR_COMPOSED("MatConvert_seqbinbcsr_seqaij_C", MatConvert_SeqBinBCSR_SeqAIJ),
  BINBCSR_COMPOSED("MatConvert_seqbinbcsr_seqbaij_C", MatConvert_SeqBinBCSR_SeqBAIJ),
#if defined(PETSC_HAVE_HYPRE)
  BINBCSR_COMPOSED("MatConvert_seqbinbcsr_hypre_C", MatConvert_BinBCSR_HYPRE),
#endif
  BINBCSR_COMPOSED("MatProductSetFromOptions_anytype_C",
                   MatProductSetFromOptions_BinBCSR), /* products with other types */
  BINBCSR_COMPOSED("MatAXPYGetPreallocation_C", MatAXPYGetPreallocation_BinBCSR),
};

static PetscErrorCode MatDestroy_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (a) PetscCall(MatSeqBinBCSRFreeStorage(a));
  PetscCall(PetscFree(A->data));
  PetscCall(PetscObjectChangeTypeName((PetscObject)A, nullptr));
  PetscCall(BinBCSRComposeList((PetscObject)A, composed, PETSC_TRUE));
  PetscFunctionReturn(0);
}

PetscErrorCode MatCreate_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a;
  PetscMPIInt     size;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)A), &size));
  PetscCheck(size == 1, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
             "MATSEQBINBCSR is for one process; use MATBINBCSR or MATMPIBINBCSR");
  PetscCall(PetscNew(&a));
  A->data        = (void *)a;
  a->bw          = BinBCSRDefaultBinWidth(1);
  a->precision   = MAT_BINBCSR_PRECISION_DOUBLE;
  a->streams     = BINBCSR_DEFAULT_STREAMS;
  a->prefetch    = BINBCSR_DEFAULT_PREFETCH;
  a->tune        = -1;
  a->tune_cache  = -1;
  a->roworiented = PETSC_TRUE;
  a->bs          = 1;
  a->bs2         = 1;

  PetscCall(PetscMemcpy(A->ops, &MatOps_SeqBinBCSR(), sizeof(struct _MatOps)));
  PetscCall(PetscObjectChangeTypeName((PetscObject)A, MATSEQBINBCSR));
  PetscCall(BinBCSRComposeList((PetscObject)A, composed, PETSC_FALSE));
  PetscFunctionReturn(0);
}
