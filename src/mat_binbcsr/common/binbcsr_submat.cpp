/* Submatrices of MATSEQBINBCSR and MATMPIBINBCSR: what PCASM, PCGASM, PCREDUNDANT and PCFIELDSPLIT
   ask a matrix for (MatIncreaseOverlap, MatCreateSubMatrices, MatCreateSubMatricesMPI,
   MatCreateSubMatrix, MatCreateMPIMatConcatenateSeqMat), and PCHYPRE's MatConvert to MATHYPRE.

   The index-set exchange of a parallel extraction is PETSc's own (src/mat/impls/aij/mpi/mpiov.c):
   the matrix keeps an AIJ shadow of itself (seqaij or mpiaij, composed on the matrix, so it goes with
   MatDestroy) and asks it. The shadow is refreshed only when the matrix changed: rebuilt when its
   nonzero state moved, refilled in place when only its values did (PetscObjectStateGet; the decision
   is reduced over the communicator, so that every rank refreshes or none does). The AIJ submatrices
   it returns are turned into binbcsr ones with the parent's block size, bin width, precision and,
   for a symmetric extraction (same rows and columns), symmetric storage; then they are freed.

   MAT_REUSE_MATRIX: the AIJ submatrices are extracted afresh (MAT_INITIAL_MATRIX on the shadow) and
   their values written into the caller's binbcsr submatrices in place, which keep their layout and
   nonzero state, so a PC on them redoes only its numeric set-up. Nothing is kept between calls but
   the shadow: no PETSc-internal reuse data whose life would have to follow the caller's arrays. */
#include "../mpi/mpibinbcsr.h"
#include "../seq/binbcsr.h"
#include "binbcsr_composed.h"

namespace {
/* A MATSEQBINBCSR matrix (the matrix itself, or a part of the parallel one) and the seqaij matrix of
   the shadow that holds its values, with the value map between them. */
struct PartMap {
  Mat bin = nullptr,
      aij = nullptr; /* referenced, but bin not when it is the matrix itself (which owns the shadow) */
  PetscBool             bin_referenced = PETSC_FALSE;
  std::vector<PetscInt> map;
};

struct AIJShadow {
  Mat                  S       = nullptr;
  PetscObjectState     state   = 0; /* of the binbcsr matrix when S got its values */
  PetscObjectState     nzstate = 0; /* its nonzero state when S was built */
  std::vector<PartMap> parts;       /* the refill by value maps; empty: by MatConvert */
};

PetscErrorCode ClearParts(AIJShadow *sh)
{
  PetscFunctionBegin;
  for (PartMap &p : sh->parts) {
    if (p.bin_referenced) PetscCall(MatDestroy(&p.bin));
    PetscCall(MatDestroy(&p.aij));
  }
  sh->parts.clear();
  PetscFunctionReturn(0);
}

PetscErrorCode AddPart(AIJShadow *sh, Mat bin, Mat aij, PetscBool reference_bin)
{
  PetscFunctionBegin;
  sh->parts.emplace_back();
  PartMap &p = sh->parts.back();
  PetscCall(MatSeqBinBCSRAIJValueMap(bin, aij, p.map));
  if (reference_bin)
    PetscCall(PetscObjectReference((PetscObject)bin)); /* a reference to the matrix itself would be a cycle */
  PetscCall(PetscObjectReference((PetscObject)aij));
  p.bin            = bin;
  p.bin_referenced = reference_bin;
  p.aij            = aij;
  PetscFunctionReturn(0);
}

/* The parts of A whose values the shadow S holds, each with its value map; none (refill by
   MatConvert) when a part is not MATSEQBINBCSR (-mat_mpibinbcsr_inner_type). */
PetscErrorCode BuildParts(Mat A, AIJShadow *sh)
{
  PetscBool mpi, binA, binB = PETSC_TRUE;

  PetscFunctionBegin;
  PetscCall(ClearParts(sh));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  if (!mpi) {
    PetscCall(AddPart(sh, A, sh->S, PETSC_FALSE));
    PetscFunctionReturn(0);
  }
  Mat_MPIBinBCSR *b = MPIBinBCSR(A);
  Mat             Ad, Ao;
  const PetscInt *colmap;
  PetscCall(MatMPIAIJGetSeqAIJ(sh->S, &Ad, &Ao, &colmap));
  PetscCall(PetscObjectTypeCompare((PetscObject)b->A, MATSEQBINBCSR, &binA));
  if (b->B) PetscCall(PetscObjectTypeCompare((PetscObject)b->B, MATSEQBINBCSR, &binB));
  /* the shadow's off-diagonal columns are B's (it was made from the parts: mpibinbcsr_convert.cpp) */
  const PetscBool same_cols =
    (b->B ? Ao->cmap->n == b->B->cmap->n : Ao->cmap->n == 0) ? PETSC_TRUE : PETSC_FALSE;
  if (!binA || !binB || !same_cols) PetscFunctionReturn(0);
  PetscCall(AddPart(sh, b->A, Ad, PETSC_TRUE));
  if (b->B) PetscCall(AddPart(sh, b->B, Ao, PETSC_TRUE));
  PetscFunctionReturn(0);
}

/* The parts still those of A (a new preallocation replaces them). */
PetscBool PartsCurrent(Mat A, const AIJShadow *sh)
{
  PetscBool mpi;
  PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi);
  if (!mpi) return sh->parts.size() == 1 && sh->parts[0].bin == A ? PETSC_TRUE : PETSC_FALSE;
  const Mat_MPIBinBCSR *b = MPIBinBCSR(A);
  const size_t          n = b->B ? 2 : 1;
  return sh->parts.size() == n && sh->parts[0].bin == b->A && (n == 1 || sh->parts[1].bin == b->B)
           ? PETSC_TRUE
           : PETSC_FALSE;
}

const char shadow_key[] = "MatBinBCSR_AIJShadow";

PetscErrorCode DestroyShadow(void *ctx)
{
  AIJShadow *sh = static_cast<AIJShadow *>(ctx);

  PetscFunctionBegin;
  PetscCall(ClearParts(sh));
  PetscCall(MatDestroy(&sh->S));
  delete sh;
  PetscFunctionReturn(0);
}

} // namespace

/* The AIJ shadow of A holding A's current values. Collective on A. */
PetscErrorCode MatBinBCSRGetAIJShadow_Private(Mat A, Mat *S)
{
  AIJShadow       *sh;
  PetscObjectState state;
  PetscBool        mpi;
  PetscMPIInt      todo[2];

  PetscFunctionBegin;
  PetscCheck(A->assembled, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_WRONGSTATE,
             "Submatrices of an unassembled binbcsr matrix");
  PetscCall(binbcsr::GetOrCompose((PetscObject)A, shadow_key, &sh, DestroyShadow));
  PetscCall(PetscObjectStateGet((PetscObject)A, &state));
  todo[0] = (!sh->S || sh->nzstate != A->nonzerostate || (!sh->parts.empty() && !PartsCurrent(A, sh)))
              ? 1
              : 0;                                   /* rebuild */
  todo[1] = (todo[0] || sh->state != state) ? 1 : 0; /* refill */
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, todo, 2, MPI_INT, MPI_MAX, PetscObjectComm((PetscObject)A)));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  /* The shadow is internal: its assemblies must not answer the user's -mat_view (on several ranks the
     parts' views are per rank and unsynchronised, and interleave with rank 0's output). */
  PetscCall(PetscOptionsPushCreateViewerOff(PETSC_TRUE));
  if (todo[0]) {
    PetscCall(ClearParts(sh));
    PetscCall(MatDestroy(&sh->S));
    PetscCall(MatConvert(A, mpi ? MATMPIAIJ : MATSEQAIJ, MAT_INITIAL_MATRIX, &sh->S));
    PetscCall(BuildParts(A, sh));
  } else if (todo[1] && !sh->parts.empty()) { /* values only: one gather per part */
    for (const PartMap &p : sh->parts) PetscCall(MatSeqBinBCSRAIJGather(p.bin, p.map, p.aij));
    PetscCall(PetscObjectStateIncrease((PetscObject)sh->S));
  } else if (todo[1]) PetscCall(MatConvert(A, mpi ? MATMPIAIJ : MATSEQAIJ, MAT_REUSE_MATRIX, &sh->S));
  if (todo[1]) PetscCall(MatPropagateSymmetryOptions(A, sh->S)); /* external factors read them (MUMPS: SPD) */
  PetscCall(PetscOptionsPopCreateViewerOff());
  sh->state   = state;
  sh->nzstate = A->nonzerostate;
  *S          = sh->S;
  PetscFunctionReturn(0);
}

/* The reverse direction: the shadow's values (computed into it, e.g. by a finite-difference colouring)
   written into A through the value maps, and the two marked in step. Collective on A. */
PetscErrorCode MatBinBCSRSetValuesFromAIJShadow_Private(Mat A)
{
  AIJShadow       *sh;
  PetscObjectState state;

  PetscFunctionBegin;
  PetscCall(binbcsr::QueryComposed((PetscObject)A, shadow_key, &sh));
  PetscCheck(sh, PETSC_COMM_SELF, PETSC_ERR_PLIB, "No AIJ shadow to take the values from");
  PetscCheck(sh->S && sh->nzstate == A->nonzerostate, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "The matrix's pattern changed after its AIJ shadow was made");
  PetscCheck(!sh->parts.empty(), PETSC_COMM_SELF, PETSC_ERR_SUP,
             "Values from the AIJ shadow need MATSEQBINBCSR parts (not -mat_mpibinbcsr_inner_type)");
  for (const PartMap &p : sh->parts) PetscCall(MatSeqBinBCSRAIJScatter(p.aij, p.map, p.bin));
  if (sh->parts[0].bin != A)
    PetscCall(
      PetscObjectStateIncrease((PetscObject)A)); /* the parts' states moved, not the parallel matrix's */
  PetscCall(PetscObjectStateGet((PetscObject)A, &state));
  sh->state = state;
  PetscFunctionReturn(0);
}

namespace {
/* A new binbcsr matrix (seq or mpi by T's communicator) with T's sizes and values and the storage
   settings of parent. symmetric: T is a symmetric extraction (same rows and columns) of parent. */
PetscErrorCode NewFromAIJ(Mat parent, Mat T, PetscBool symmetric, Mat *B)
{
  PetscMPIInt         size;
  PetscInt            bs = T->rmap->bs, pbs = parent->rmap->bs, bw;
  MatBinBCSRPrecision prec;
  PetscBool           sym;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)T), &size));
  if (bs < 1 || bs != T->cmap->bs) bs = 1; /* binbcsr needs equal row and column block sizes */
  PetscCall(MatCreate(PetscObjectComm((PetscObject)T), B));
  PetscCall(MatSetSizes(*B, T->rmap->n, T->cmap->n, T->rmap->N, T->cmap->N));
  PetscCall(MatSetBlockSize(*B, bs));
  PetscCall(MatSetType(*B, size > 1 ? MATMPIBINBCSR : MATSEQBINBCSR));
  PetscCall(MatBinBCSRGetBinWidth(parent, &bw));
  if (bw > 0 && bs == pbs)
    PetscCall(MatBinBCSRSetBinWidth(*B, bw)); /* a different block size keeps its own default */
  PetscCall(MatBinBCSRGetPrecision(parent, &prec));
  PetscCall(MatBinBCSRSetPrecision(*B, prec));
  PetscCall(MatBinBCSRGetSymmetricStorage(parent, &sym));
  if (sym && symmetric && T->rmap->N == T->cmap->N) PetscCall(MatBinBCSRSetSymmetricStorage(*B, PETSC_TRUE));
  PetscCall(MatBinBCSRPreallocateAndFill_Private(T, *B));
  PetscFunctionReturn(0);
}

const char submap_key[] = "MatBinBCSR_SubmatrixValueMap";

/* A sequential submatrix B refilled from T (seqaij, the same extraction as the one B was made from) by
   the value map composed on B, made at the first refill and remade if T's entry count differs. */
PetscErrorCode RefillSeqByMap(Mat T, Mat B)
{
  std::vector<PetscInt> *map;
  const PetscInt        *ia, *ja;
  PetscInt               n;
  PetscBool              done;

  PetscFunctionBegin;
  PetscCall(binbcsr::GetOrCompose((PetscObject)B, submap_key, &map));
  PetscCall(MatGetRowIJ(T, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  const size_t nz = done ? (size_t)ia[n] : 0;
  PetscCall(MatRestoreRowIJ(T, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  if (map->size() != nz || map->empty()) PetscCall(MatSeqBinBCSRAIJValueMap(B, T, *map));
  PetscCall(MatSeqBinBCSRAIJScatter(T, *map, B));
  PetscFunctionReturn(0);
}

/* A parallel submatrix B (mpibinbcsr) refilled from T (mpiaij) part by part through value maps, when
   every rank's parts line up (the off-diagonal columns the same); *done says whether it was. */
PetscErrorCode RefillMPIByParts(Mat T, Mat B, PetscBool *done)
{
  PetscBool ok;
  Mat       Td = nullptr, To = nullptr;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)T, MATMPIAIJ, &ok));
  Mat_MPIBinBCSR *b = MPIBinBCSR(B);
  if (ok) {
    PetscBool binA, binB = PETSC_TRUE;
    PetscCall(PetscObjectTypeCompare((PetscObject)b->A, MATSEQBINBCSR, &binA));
    if (b->B) PetscCall(PetscObjectTypeCompare((PetscObject)b->B, MATSEQBINBCSR, &binB));
    ok = (binA && binB && b->compressed) ? PETSC_TRUE : PETSC_FALSE;
  }
  if (ok) {
    const PetscInt *colmap;
    const PetscInt  bs = B->cmap->bs;
    PetscCall(MatMPIAIJGetSeqAIJ(T, &Td, &To, &colmap));
    ok = (To->cmap->n == static_cast<PetscInt>(b->garray.size()) * bs && (b->B || To->cmap->n == 0))
           ? PETSC_TRUE
           : PETSC_FALSE;
    for (PetscInt k = 0; ok && k < To->cmap->n; k++)
      ok = colmap[k] == b->garray[k / bs] * bs + k % bs ? PETSC_TRUE : PETSC_FALSE;
  }
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &ok, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)B)));
  *done = ok;
  if (!ok) PetscFunctionReturn(0);
  PetscCall(RefillSeqByMap(Td, b->A));
  if (b->B) PetscCall(RefillSeqByMap(To, b->B));
  PetscCall(PetscObjectStateIncrease((PetscObject)B));
  PetscFunctionReturn(0);
}

/* MAT_REUSE_MATRIX: T's values into B, which must have T's sizes and hold its pattern. */
PetscErrorCode RefillFromAIJ(Mat T, Mat B)
{
  PetscBool isbin, seq;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)B, &isbin, MATSEQBINBCSR, MATMPIBINBCSR, ""));
  PetscCheck(isbin, PetscObjectComm((PetscObject)B), PETSC_ERR_ARG_WRONG,
             "MAT_REUSE_MATRIX: the submatrix to refill is of type %s, not one this binbcsr matrix made",
             ((PetscObject)B)->type_name);
  PetscCheck(B->rmap->N == T->rmap->N && B->cmap->N == T->cmap->N && B->rmap->n == T->rmap->n &&
               B->cmap->n == T->cmap->n,
             PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "MAT_REUSE_MATRIX: the submatrix to refill is %" PetscInt_FMT " x %" PetscInt_FMT
             " (local %" PetscInt_FMT " x %" PetscInt_FMT "), the index sets select %" PetscInt_FMT
             " x %" PetscInt_FMT " (local %" PetscInt_FMT " x %" PetscInt_FMT ")",
             B->rmap->N, B->cmap->N, B->rmap->n, B->cmap->n, T->rmap->N, T->cmap->N, T->rmap->n, T->cmap->n);
  PetscCall(PetscObjectTypeCompare((PetscObject)B, MATSEQBINBCSR, &seq));
  if (seq) PetscCall(PetscObjectTypeCompare((PetscObject)T, MATSEQAIJ, &seq));
  if (seq) PetscCall(RefillSeqByMap(T, B));
  else {
    PetscBool done = PETSC_FALSE;
    PetscCall(PetscObjectTypeCompare((PetscObject)B, MATMPIBINBCSR, &isbin));
    if (isbin) PetscCall(RefillMPIByParts(T, B, &done));
    if (!done) {
      PetscCall(MatZeroEntries(B));
      PetscCall(MatBinBCSRInsertRows_Private(T, B));
    }
  }
  PetscFunctionReturn(0);
}

/* MAT_REUSE_MATRIX of sequential submatrices: checked before anything is extracted, so that a wrong
   call fails clean. */
PetscErrorCode CheckReuse(PetscInt n, const IS irow[], const IS icol[], Mat B[])
{
  PetscFunctionBegin;
  for (PetscInt i = 0; i < n; i++) {
    PetscInt  m, k;
    PetscBool isbin;
    PetscCall(ISGetLocalSize(irow[i], &m));
    PetscCall(ISGetLocalSize(icol[i], &k));
    PetscCall(PetscObjectTypeCompare((PetscObject)B[i], MATSEQBINBCSR, &isbin));
    PetscCheck(isbin, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
               "MAT_REUSE_MATRIX: submatrix %" PetscInt_FMT
               " is of type %s, not one this binbcsr matrix made",
               i, ((PetscObject)B[i])->type_name);
    PetscCheck(B[i]->rmap->n == m && B[i]->cmap->n == k, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
               "MAT_REUSE_MATRIX: submatrix %" PetscInt_FMT " is %" PetscInt_FMT " x %" PetscInt_FMT
               ", its index sets select %" PetscInt_FMT " x %" PetscInt_FMT,
               i, B[i]->rmap->n, B[i]->cmap->n, m, k);
  }
  PetscFunctionReturn(0);
}

/* The binbcsr counterparts of the AIJ matrices T[0..n): created (MAT_INITIAL_MATRIX) or refilled. */
PetscErrorCode FromAIJ(Mat parent, PetscInt n, const IS irow[], const IS icol[], Mat T[], MatReuse scall,
                       Mat B[])
{
  PetscFunctionBegin;
  for (PetscInt i = 0; i < n; i++) {
    if (scall == MAT_INITIAL_MATRIX) {
      PetscBool symmetric;
      PetscCall(ISEqualUnsorted(irow[i], icol[i], &symmetric));
      PetscCall(NewFromAIJ(parent, T[i], symmetric, &B[i]));
    } else PetscCall(RefillFromAIJ(T[i], B[i]));
  }
  PetscFunctionReturn(0);
}

/* The array forms (MatCreateSubMatrices, MatCreateSubMatricesMPI) take no MAT_INPLACE_MATRIX; op is the
   caller's name for the message. */
PetscErrorCode CheckArrayReuse(Mat A, MatReuse scall, const char *op)
{
  PetscFunctionBegin;
  PetscCheck(scall == MAT_INITIAL_MATRIX || scall == MAT_REUSE_MATRIX, PetscObjectComm((PetscObject)A),
             PETSC_ERR_ARG_WRONG, "%s takes MAT_INITIAL_MATRIX or MAT_REUSE_MATRIX", op);
  PetscFunctionReturn(0);
}

/* What both array forms do with the shadow S: its submatrices, made by create and freed by destroy
   (the pair that matches how create made them), turned into binbcsr ones in *submat (allocated here
   with n + 1 entries on MAT_INITIAL_MATRIX). */
PetscErrorCode
ArrayFromShadow(Mat A, Mat S, PetscInt n, const IS irow[], const IS icol[], MatReuse scall, Mat *submat[],
                PetscErrorCode (*create)(Mat, PetscInt, const IS[], const IS[], MatReuse, Mat *[]),
                PetscErrorCode (*destroy)(PetscInt, Mat *[]))
{
  Mat *T;

  PetscFunctionBegin;
  PetscCall(create(S, n, irow, icol, MAT_INITIAL_MATRIX, &T));
  if (scall == MAT_INITIAL_MATRIX) PetscCall(PetscCalloc1(n + 1, submat));
  PetscCall(FromAIJ(A, n, irow, icol, T, scall, *submat));
  PetscCall(destroy(n, &T));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode MatIncreaseOverlap_BinBCSR(Mat A, PetscInt n, IS is[], PetscInt ov)
{
  Mat S;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(MatIncreaseOverlap(S, n, is, ov));
  PetscFunctionReturn(0);
}

/* MatConvert to MATHYPRE (PCHYPRE): the shadow's own conversion, which copies its CSR arrays; a
   refilled matrix reaches hypre through MAT_REUSE_MATRIX like aij. */
PetscErrorCode MatConvert_BinBCSR_HYPRE(Mat A, MatType type, MatReuse reuse, Mat *newmat)
{
  Mat S;

  PetscFunctionBegin;
  PetscCheck(reuse != MAT_INPLACE_MATRIX, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP,
             "In-place conversion of binbcsr to %s is not supported", type);
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(MatConvert(S, type, reuse, newmat));
  PetscFunctionReturn(0);
}

/* Sequential submatrices (PCASM's blocks, PCREDUNDANT's copy): MATSEQBINBCSR. The array has n+1
   entries like PETSc's own (the last one unused), freed by MatDestroySubMatrices or MatDestroyMatrices. */
PetscErrorCode MatCreateSubMatrices_BinBCSR(Mat A, PetscInt n, const IS irow[], const IS icol[],
                                            MatReuse scall, Mat *submat[])
{
  Mat S;

  PetscFunctionBegin;
  PetscCall(CheckArrayReuse(A, scall, "MatCreateSubMatrices"));
  if (scall == MAT_REUSE_MATRIX) PetscCall(CheckReuse(n, irow, icol, *submat));
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  S->submat_singleis =
    A->submat_singleis; /* PCASM's hint: one index set on every rank; used once, as MPIAIJ does */
  A->submat_singleis = PETSC_FALSE;
  PetscCall(ArrayFromShadow(A, S, n, irow, icol, scall, submat, MatCreateSubMatrices, MatDestroySubMatrices));
  PetscFunctionReturn(0);
}

/* Parallel submatrices on the index sets' subcommunicators (PCGASM): binbcsr of the kind each
   subcommunicator's size calls for. */
PetscErrorCode MatCreateSubMatricesMPI_BinBCSR(Mat A, PetscInt n, const IS irow[], const IS icol[],
                                               MatReuse scall, Mat *submat[])
{
  Mat S;

  PetscFunctionBegin;
  PetscCall(CheckArrayReuse(A, scall, "MatCreateSubMatricesMPI"));
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  /* MatDestroyMatrices, not MatDestroySubMatrices: these are parallel (as in PCGASM) */
  PetscCall(ArrayFromShadow(A, S, n, irow, icol, scall, submat, MatCreateSubMatricesMPI, MatDestroyMatrices));
  PetscFunctionReturn(0);
}

/* One parallel submatrix (PCFIELDSPLIT's fields): MATMPIBINBCSR on A's communicator. */
PetscErrorCode MatCreateSubMatrix_BinBCSR(Mat A, IS isrow, IS iscol, MatReuse cll, Mat *newmat)
{
  Mat S, T;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(MatCreateSubMatrix(S, isrow, iscol, MAT_INITIAL_MATRIX, &T));
  PetscCall(FromAIJ(A, 1, &isrow, &iscol, &T, cll, newmat));
  PetscCall(MatDestroy(&T));
  PetscFunctionReturn(0);
}

/* PCREDUNDANT with fewer subcommunicators than ranks: the sequential copies of the rows joined into
   one matrix on each subcommunicator, through MPIAIJ's own concatenation. */
PetscErrorCode MatCreateMPIMatConcatenateSeqMat_BinBCSR(MPI_Comm comm, Mat seqmat, PetscInt n, MatReuse reuse,
                                                        Mat *mpimat)
{
  Mat Taij, T;

  PetscFunctionBegin;
  PetscCall(MatConvert(seqmat, MATSEQAIJ, MAT_INITIAL_MATRIX, &Taij));
  PetscCall(MatCreateMPIMatConcatenateSeqMat(comm, Taij, n, MAT_INITIAL_MATRIX, &T));
  PetscCall(MatDestroy(&Taij));
  /* seqmat is a strip of rows, never symmetric itself: the copy gets full storage */
  if (reuse == MAT_REUSE_MATRIX) PetscCall(RefillFromAIJ(T, *mpimat));
  else PetscCall(NewFromAIJ(seqmat, T, PETSC_FALSE, mpimat));
  PetscCall(MatDestroy(&T));
  PetscFunctionReturn(0);
}
