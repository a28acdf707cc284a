/* MATSEQBINBCSR factorisations (MATSOLVERPETSC): ICC and Cholesky through a seqsbaij shadow copy,
   ILU and LU through a seqbaij one.

   The bin layout is made for products, not for the row-by-row elimination of a factorisation, so the
   factor is PETSc's own: MatGetFactor converts the matrix once into a shadow of the type PETSc factors
   (seqsbaij: blocks on and above the diagonal; seqbaij: all blocks) and asks that shadow for its
   factor Mat. The factor's symbolic and numeric ops are then wrapped: they refill the shadow's values
   from the binbcsr matrix (a gather through a slot map built once, no MatSetValues) and call PETSc's
   own routine with the shadow in place of the binbcsr matrix. Solves are the factor's own.

   The shadow and the map live as long as the factor Mat (a PC keeps it between solves, so a refilled
   matrix costs one value copy plus the numeric factorisation). Orderings are BAIJ's: LU defaults to
   nested dissection and ILU to natural, and both take any of PETSc's orderings (computed on the
   binbcsr matrix through MatGetRowIJ); ICC and Cholesky are natural only, as PETSc's sbaij. */
#include "binbcsr.h"
#include "../binbcsr_factor_routing.h"
#include <vector>

namespace
{
struct FactorShadow {
  Mat              S = nullptr;     /* seqsbaij (ICC, Cholesky) or seqbaij (ILU, LU) */
  PetscObjectState nzstate = 0;     /* the binbcsr matrix's nonzero state when S was built */
  PetscInt         bs = 0, bw = 0;  /* of the binbcsr matrix */
  std::vector<PetscInt>  src;       /* per block of S: value index of the binbcsr slot's entry 0 */
  std::vector<char>      transpose; /* per block of S: read the stored block (c, r) transposed */
  /* PETSc's ops of the factor, called with S in place of the binbcsr matrix */
  PetscErrorCode (*iccsymbolic)(Mat, Mat, IS, const MatFactorInfo *)            = nullptr;
  PetscErrorCode (*choleskysymbolic)(Mat, Mat, IS, const MatFactorInfo *)       = nullptr;
  PetscErrorCode (*ilusymbolic)(Mat, Mat, IS, IS, const MatFactorInfo *)        = nullptr;
  PetscErrorCode (*lusymbolic)(Mat, Mat, IS, IS, const MatFactorInfo *)         = nullptr;
  PetscErrorCode (*choleskynumeric)(Mat, Mat, const MatFactorInfo *)            = nullptr;
  PetscErrorCode (*lunumeric)(Mat, Mat, const MatFactorInfo *)                  = nullptr;

  /* the routing (binbcsr_factor_routing.h) */
  static const char *key() { return "MatSeqBinBCSR_FactorShadow"; }
  static PetscErrorCode Destroy(void *ctx)
  {
    FactorShadow *f = (FactorShadow *)ctx;

    PetscFunctionBegin;
    PetscCall(MatDestroy(&f->S));
    delete f;
    PetscFunctionReturn(0);
  }
  PetscErrorCode Shadow(Mat A, Mat *shadow); /* refills S from A (RefillShadow) */
};

/* The block pattern of S from A's: upper = blocks with column >= row (for seqsbaij), else all blocks
   (with symmetric storage the lower ones are the stored upper ones transposed). Fills f->src and
   f->transpose in the order of S's blocks (CSR, ascending columns). */
PetscErrorCode BuildShadowPattern(Mat A, PetscBool upper, FactorShadow *f, std::vector<PetscInt> &bi, std::vector<PetscInt> &bj)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bw = a->bw, bs2 = a->bs2;

  PetscFunctionBegin;
  auto base = [&](PetscInt s) { return BinBCSRValueIndex(s, 0, bw, bs2); };
  if (a->sym && !upper) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  bi.assign(1, 0);
  bj.clear();
  f->src.clear();
  f->transpose.clear();
  for (PetscInt r = 0; r < a->mbs; r++) {
    if (!upper) {
      if (a->sym) {
        for (PetscInt p = a->lower_off[r]; p < a->lower_off[r + 1]; p++) {
          bj.push_back(a->lower_slot[2 * p + 1]);
          f->src.push_back(base(a->lower_slot[2 * p]));
          f->transpose.push_back(1);
        }
      }
    }
    for (PetscInt k = 0; k < a->row_nz[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k);
      if (upper && a->col[s] < r) continue;
      bj.push_back(a->col[s]);
      f->src.push_back(base(s));
      f->transpose.push_back(0);
    }
    bi.push_back((PetscInt)bj.size());
  }
  PetscFunctionReturn(0);
}

/* S's values from A's: one pass over S's blocks (column-major bs x bs, as BAIJ and SBAIJ store them).
   BS > 0: the block size known at compile time (the loops unroll); 0: f->bs. */
template <typename T, int BS>
void GatherValues(const T *val, const FactorShadow *f, PetscScalar *dst)
{
  const PetscInt bs = BS ? BS : f->bs, bw = f->bw, bs2 = bs * bs, nb = (PetscInt)f->src.size();
  for (PetscInt k = 0; k < nb; k++) {
    const T     *v = val + f->src[k];
    PetscScalar *d = dst + k * bs2;
    if (!f->transpose[k]) {
      for (PetscInt i = 0; i < bs; i++)
        for (PetscInt j = 0; j < bs; j++) d[j * bs + i] = v[(i * bs + j) * bw];
    } else {
      for (PetscInt i = 0; i < bs; i++)
        for (PetscInt j = 0; j < bs; j++) d[j * bs + i] = v[(j * bs + i) * bw];
    }
  }
}

PetscErrorCode RefillShadow(Mat A, FactorShadow *f)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscBool       upper;
  PetscScalar    *dst;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Factorisation needs an assembled MATSEQBINBCSR matrix");
  PetscCheck(A->nonzerostate == f->nzstate, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "The MATSEQBINBCSR pattern changed after the symbolic factorisation; redo it (MatGetFactor)");
  PetscCall(PetscObjectTypeCompare((PetscObject)f->S, MATSEQSBAIJ, &upper));
  if (upper) PetscCall(MatSeqSBAIJGetArray(f->S, &dst));
  else PetscCall(MatSeqBAIJGetArray(f->S, &dst));
  if (a->val) {
    if (f->bs == 3) GatherValues<MatScalar, 3>(a->val, f, dst);
    else if (f->bs == 1) GatherValues<MatScalar, 1>(a->val, f, dst);
    else GatherValues<MatScalar, 0>(a->val, f, dst);
  } else {
    if (f->bs == 3) GatherValues<float, 3>(a->valf, f, dst);
    else if (f->bs == 1) GatherValues<float, 1>(a->valf, f, dst);
    else GatherValues<float, 0>(a->valf, f, dst);
  }
  if (upper) PetscCall(MatSeqSBAIJRestoreArray(f->S, &dst));
  else PetscCall(MatSeqBAIJRestoreArray(f->S, &dst));
  PetscCall(PetscObjectStateIncrease((PetscObject)f->S));
  PetscFunctionReturn(0);
}

PetscErrorCode FactorShadow::Shadow(Mat A, Mat *shadow)
{
  PetscFunctionBegin;
  PetscCall(RefillShadow(A, this));
  *shadow = S;
  PetscFunctionReturn(0);
}

/* The permutation for S from the one PCFactor computed on the binbcsr matrix. PETSc's orderings read
   the block-compressed structure (MatGetRowIJ), so for bs > 1 they come out block-sized: what BAIJ's
   LU and ILU take, so they pass through. The identity (natural) may come point-sized; it becomes S's
   own natural ordering. SBAIJ (ICC, Cholesky) factors in natural order only. */
PetscErrorCode ShadowOrdering(FactorShadow *f, IS row, IS col, IS *rperm, IS *cperm)
{
  PetscBool      rid = PETSC_TRUE, cid = PETSC_TRUE, sbaij;
  const PetscInt mbs = f->S->rmap->n / f->bs;
  PetscInt       nr = -1, nc = -1;

  PetscFunctionBegin;
  if (row) PetscCall(ISIdentity(row, &rid));
  if (col) PetscCall(ISIdentity(col, &cid));
  if (rid && cid) {
    PetscCall(MatGetOrdering(f->S, MATORDERINGNATURAL, rperm, cperm));
    PetscFunctionReturn(0);
  }
  PetscCall(PetscObjectTypeCompare((PetscObject)f->S, MATSEQSBAIJ, &sbaij));
  PetscCheck(!sbaij, PETSC_COMM_SELF, PETSC_ERR_SUP, "ICC and Cholesky of MATSEQBINBCSR (PETSc's seqsbaij factor) support only the natural ordering (-pc_factor_mat_ordering_type natural), or use -pc_factor_mat_solver_type mumps");
  if (row) PetscCall(ISGetLocalSize(row, &nr));
  if (col) PetscCall(ISGetLocalSize(col, &nc));
  PetscCheck(nr == mbs && nc == mbs, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "LU and ILU of MATSEQBINBCSR take block orderings of its %" PetscInt_FMT " block rows (as MatGetOrdering gives), not index sets of %" PetscInt_FMT " and %" PetscInt_FMT " entries", mbs, nr, nc);
  PetscCall(PetscObjectReference((PetscObject)row));
  PetscCall(PetscObjectReference((PetscObject)col));
  *rperm = row;
  *cperm = col;
  PetscFunctionReturn(0);
}

/* The four symbolic factorisations: refill the shadow, translate the ordering to it, run PETSc's
   routine on it (the routing keeps the numeric kernel that routine chose on the shadow). */
template <class Symbolic>
PetscErrorCode ShadowSymbolic(Mat F, Mat A, IS row, IS col, Symbolic &&symbolic)
{
  PetscFunctionBegin;
  PetscCall(binbcsr_factor::OnShadow<FactorShadow>(F, A, [&](FactorShadow *f, Mat) {
    IS r, c;

    PetscFunctionBegin;
    PetscCall(ShadowOrdering(f, row, col, &r, &c));
    PetscCall(symbolic(f, r, c));
    PetscCall(ISDestroy(&r));
    PetscCall(ISDestroy(&c));
    PetscFunctionReturn(0);
  }));
  PetscFunctionReturn(0);
}

PetscErrorCode ICCSymbolic(Mat F, Mat A, IS perm, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(F, A, perm, nullptr, [&](FactorShadow *f, IS r, IS) { return (*f->iccsymbolic)(F, f->S, r, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode CholeskySymbolic(Mat F, Mat A, IS perm, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(F, A, perm, nullptr, [&](FactorShadow *f, IS r, IS) { return (*f->choleskysymbolic)(F, f->S, r, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode ILUSymbolic(Mat F, Mat A, IS row, IS col, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(F, A, row, col, [&](FactorShadow *f, IS r, IS c) { return (*f->ilusymbolic)(F, f->S, r, c, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode LUSymbolic(Mat F, Mat A, IS row, IS col, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(F, A, row, col, [&](FactorShadow *f, IS r, IS c) { return (*f->lusymbolic)(F, f->S, r, c, info); }));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode MatGetFactor_SeqBinBCSR_Petsc(Mat A, MatFactorType ftype, Mat *F)
{
  Mat_SeqBinBCSR       *a     = (Mat_SeqBinBCSR *)A->data;
  const PetscBool       upper = (ftype == MAT_FACTOR_ICC || ftype == MAT_FACTOR_CHOLESKY) ? PETSC_TRUE : PETSC_FALSE;
  FactorShadow         *f;
  std::vector<PetscInt> bi, bj;

  PetscFunctionBegin;
  PetscCheck(ftype == MAT_FACTOR_ICC || ftype == MAT_FACTOR_CHOLESKY || ftype == MAT_FACTOR_ILU || ftype == MAT_FACTOR_LU, PETSC_COMM_SELF, PETSC_ERR_SUP, "MATSEQBINBCSR provides ICC, Cholesky, ILU and LU (MATSOLVERPETSC), not %s", MatFactorTypes[ftype]);
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatGetFactor needs an assembled MATSEQBINBCSR matrix");
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Factorisation of a non-square MATSEQBINBCSR matrix (%" PetscInt_FMT " x %" PetscInt_FMT ")", A->rmap->n, A->cmap->n);
  f          = new FactorShadow;
  f->bs      = a->bs;
  f->bw      = a->bw;
  f->nzstate = A->nonzerostate;
  PetscCall(BuildShadowPattern(A, upper, f, bi, bj));
  PetscCall(MatCreate(PETSC_COMM_SELF, &f->S));
  PetscCall(MatSetSizes(f->S, A->rmap->n, A->cmap->n, A->rmap->n, A->cmap->n));
  PetscCall(MatSetType(f->S, upper ? MATSEQSBAIJ : MATSEQBAIJ));
  if (upper) PetscCall(MatSeqSBAIJSetPreallocationCSR(f->S, a->bs, bi.data(), bj.data(), nullptr));
  else PetscCall(MatSeqBAIJSetPreallocationCSR(f->S, a->bs, bi.data(), bj.data(), nullptr));
  PetscCall(MatPropagateSymmetryOptions(A, f->S));

  PetscCall(MatGetFactor(f->S, MATSOLVERPETSC, ftype, F));
  PetscCall(binbcsr_factor::Attach(*F, f));

  Mat B = *F;
  f->iccsymbolic      = B->ops->iccfactorsymbolic;
  f->choleskysymbolic = B->ops->choleskyfactorsymbolic;
  f->ilusymbolic      = B->ops->ilufactorsymbolic;
  f->lusymbolic       = B->ops->lufactorsymbolic;
  if (f->iccsymbolic) B->ops->iccfactorsymbolic = ICCSymbolic;
  if (f->choleskysymbolic) B->ops->choleskyfactorsymbolic = CholeskySymbolic;
  if (f->ilusymbolic) B->ops->ilufactorsymbolic = ILUSymbolic;
  if (f->lusymbolic) B->ops->lufactorsymbolic = LUSymbolic;
  if (upper) { /* LU and ILU keep BAIJ's preferences: nested dissection for LU, natural for ILU */
    PetscCall(PetscFree(B->preferredordering[ftype]));
    PetscCall(PetscStrallocpy(MATORDERINGNATURAL, (char **)&B->preferredordering[ftype]));
  }
  PetscFunctionReturn(0);
}
