/* MATSEQBINBCSR factorisations (MATSOLVERPETSC): ICC and Cholesky through a seqsbaij shadow copy,
   ILU and LU through a seqbaij one.

   The bin layout is made for products, not for the row-by-row elimination of a factorisation, so the
   factor is PETSc's own: MatGetFactor converts the matrix once into a shadow of the type PETSc factors
   (seqsbaij: blocks on and above the diagonal; seqbaij: all blocks) and asks that shadow for its
   factor Mat. The factor's symbolic and numeric ops are then wrapped: they refill the shadow's values
   from the binbcsr matrix (a gather through a slot map built once, no MatSetValues) and call PETSc's
   own routine with the shadow in place of the binbcsr matrix. Solves are the factor's own.

   The shadow and the map live as long as the factor Mat (a PC keeps it between solves, so a refilled
   matrix costs one value copy plus the numeric factorisation). All four take PETSc's orderings
   (computed on the binbcsr matrix through MatGetRowIJ): LU and ILU pass them to BAIJ's factor; ICC and
   Cholesky, which seqsbaij factors in natural order only, get a shadow of the renumbered matrix and
   permuting solves. LU and Cholesky default to nested dissection, ILU and ICC to natural. */
#include "binbcsr.h"
#include "../common/binbcsr_factor_routing.h"
#include <algorithm>
#include <vector>

namespace {
struct FactorShadow {
  Mat                   S       = nullptr; /* seqsbaij (ICC, Cholesky) or seqbaij (ILU, LU) */
  PetscObjectState      nzstate = 0;       /* the binbcsr matrix's nonzero state when S was built */
  PetscInt              bs = 0, bw = 0;    /* of the binbcsr matrix */
  std::vector<PetscInt> src;               /* per block of S: value index of the binbcsr slot's entry 0 */
  std::vector<char>     transpose;         /* per block of S: read the stored block (c, r) transposed */
  /* PETSc's ops of the factor, called with S in place of the binbcsr matrix */
  PetscErrorCode (*iccsymbolic)(Mat, Mat, IS, const MatFactorInfo *)      = nullptr;
  PetscErrorCode (*choleskysymbolic)(Mat, Mat, IS, const MatFactorInfo *) = nullptr;
  PetscErrorCode (*ilusymbolic)(Mat, Mat, IS, IS, const MatFactorInfo *)  = nullptr;
  PetscErrorCode (*lusymbolic)(Mat, Mat, IS, IS, const MatFactorInfo *)   = nullptr;
  PetscErrorCode (*choleskynumeric)(Mat, Mat, const MatFactorInfo *)      = nullptr;
  PetscErrorCode (*lunumeric)(Mat, Mat, const MatFactorInfo *)            = nullptr;
  /* ICC and Cholesky in an ordering: S holds the permuted matrix (seqsbaij factors in its natural
     order only), and the factor's solves are wrapped to permute in and out */
  std::vector<PetscInt> perm; /* new block row -> A's block row; empty: natural */
  Vec                   bp = nullptr, xp = nullptr;
  PetscErrorCode (*solve)(Mat, Vec, Vec)         = nullptr;
  PetscErrorCode (*forwardsolve)(Mat, Vec, Vec)  = nullptr;
  PetscErrorCode (*backwardsolve)(Mat, Vec, Vec) = nullptr;

  /* the routing (binbcsr_factor_routing.h) */
  static const char    *key() { return "MatSeqBinBCSR_FactorShadow"; }
  static PetscErrorCode Destroy(void *ctx)
  {
    FactorShadow *f = (FactorShadow *)ctx;

    PetscFunctionBegin;
    PetscCall(MatDestroy(&f->S));
    PetscCall(VecDestroy(&f->bp));
    PetscCall(VecDestroy(&f->xp));
    delete f;
    PetscFunctionReturn(0);
  }
  PetscErrorCode Shadow(Mat A, Mat *shadow); /* refills S from A (RefillShadow) */
  PetscErrorCode Routed(Mat F);              /* the permuting solves, when perm is set */
};

/* The block pattern of S from A's, in the numbering of f->perm (new block row i is A's block row
   perm[i]; natural when empty): upper = blocks with new column >= new row (for seqsbaij), else all
   blocks (with symmetric storage the lower ones are the stored upper ones transposed). Fills f->src and
   f->transpose in the order of S's blocks (CSR, ascending columns). */
PetscErrorCode BuildShadowPattern(Mat A, PetscBool upper, FactorShadow *f, std::vector<PetscInt> &bi,
                                  std::vector<PetscInt> &bj)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bw = a->bw, bs2 = a->bs2;
  const bool      permuted = !f->perm.empty();
  struct Block {
    PetscInt col, src;
    char     transpose;
  };
  std::vector<PetscInt> iperm;
  std::vector<Block>    row;

  PetscFunctionBegin;
  auto base = [&](PetscInt s) { return BinBCSRValueIndex(s, 0, bw, bs2); };
  /* the lower part of a row is needed unless only the (unpermuted) upper triangle is */
  if (a->sym && (!upper || permuted)) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  if (permuted) {
    iperm.resize(a->mbs);
    for (PetscInt i = 0; i < a->mbs; i++) iperm[f->perm[i]] = i;
  }
  bi.assign(1, 0);
  bj.clear();
  f->src.clear();
  f->transpose.clear();
  for (PetscInt i = 0; i < a->mbs; i++) {
    const PetscInt r   = permuted ? f->perm[i] : i;
    auto           add = [&](PetscInt c, PetscInt s, char transpose) {
      const PetscInt j = permuted ? iperm[c] : c;
      if (!upper || j >= i) row.push_back({j, base(s), transpose});
    };
    row.clear();
    if (a->sym && a->lower_off)
      for (PetscInt p = a->lower_off[r]; p < a->lower_off[r + 1]; p++)
        add(a->lower_slot[2 * p + 1], a->lower_slot[2 * p], 1);
    for (PetscInt k = 0; k < a->row_nz[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k);
      add(a->col[s], s, 0);
    }
    if (permuted)
      std::sort(row.begin(), row.end(), [](const Block &x, const Block &y) { return x.col < y.col; });
    for (const Block &b : row) {
      bj.push_back(b.col);
      f->src.push_back(b.src);
      f->transpose.push_back(b.transpose);
    }
    bi.push_back((PetscInt)bj.size());
  }
  PetscFunctionReturn(0);
}

/* S's values from A's: one pass over S's blocks (column-major bs x bs, as BAIJ and SBAIJ store them).
   BS > 0: the block size known at compile time (the loops unroll); 0: f->bs. */
template <typename T, int BS> void GatherValues(const T *val, const FactorShadow *f, PetscScalar *dst)
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
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "Factorisation needs an assembled MATSEQBINBCSR matrix");
  PetscCheck(A->nonzerostate == f->nzstate, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "The MATSEQBINBCSR pattern changed after the symbolic factorisation; redo it (MatGetFactor)");
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

/* S (re)built from A's pattern in the numbering of f->perm: seqsbaij (upper) or seqbaij; f's block
   size, bin width and nonzero state taken from A. Before A's first assembly (PCSetFromOptions asks for
   the factor then, e.g. in ts ex2) S has A's sizes and block size but no blocks, and a nonzero state
   that no matrix has: the symbolic phase builds the pattern. */
PetscErrorCode BuildShadow(Mat A, PetscBool upper, FactorShadow *f)
{
  Mat_SeqBinBCSR       *a = (Mat_SeqBinBCSR *)A->data;
  std::vector<PetscInt> bi, bj;

  PetscFunctionBegin;
  if (a->built) {
    f->bs      = a->bs;
    f->bw      = a->bw;
    f->nzstate = A->nonzerostate;
    PetscCall(BuildShadowPattern(A, upper, f, bi, bj));
  } else {
    PetscCall(MatGetBlockSize(A, &f->bs));
    f->nzstate = -1;
    bi.assign(A->rmap->n / f->bs + 1, 0);
  }
  PetscCall(MatDestroy(&f->S));
  PetscCall(MatCreate(PETSC_COMM_SELF, &f->S));
  PetscCall(MatSetSizes(f->S, A->rmap->n, A->cmap->n, A->rmap->n, A->cmap->n));
  PetscCall(MatSetType(f->S, upper ? MATSEQSBAIJ : MATSEQBAIJ));
  if (upper) PetscCall(MatSeqSBAIJSetPreallocationCSR(f->S, f->bs, bi.data(), bj.data(), nullptr));
  else PetscCall(MatSeqBAIJSetPreallocationCSR(f->S, f->bs, bi.data(), bj.data(), nullptr));
  PetscCall(MatPropagateSymmetryOptions(A, f->S));
  PetscFunctionReturn(0);
}

/* The permutation for S from the one PCFactor computed on the binbcsr matrix. PETSc's orderings read
   the block-compressed structure (MatGetRowIJ), so for bs > 1 they come out block-sized. LU and ILU:
   BAIJ's factor takes them, so they pass through. ICC and Cholesky: seqsbaij factors in natural order
   only (bs > 1), so S itself is rebuilt as the permuted matrix P^T A P and the solves permute in and
   out (FactorShadow::Routed); S's factor then runs in its natural order. The identity (natural) may
   come point-sized; it becomes S's own natural ordering. */
PetscErrorCode ShadowOrdering(Mat A, FactorShadow *f, IS row, IS col, IS *rperm, IS *cperm)
{
  PetscBool      rid = PETSC_TRUE, cid = PETSC_TRUE, sbaij;
  const PetscInt mbs = A->rmap->n / f->bs;
  PetscInt       nr = -1, nc = -1;

  PetscFunctionBegin;
  if (row) PetscCall(ISIdentity(row, &rid));
  if (col) PetscCall(ISIdentity(col, &cid));
  PetscCall(PetscObjectTypeCompare((PetscObject)f->S, MATSEQSBAIJ, &sbaij));
  if (rid && cid) {
    if (!f->perm.empty()) {
      f->perm.clear();
      PetscCall(BuildShadow(A, sbaij, f));
    }
    PetscCall(MatGetOrdering(f->S, MATORDERINGNATURAL, rperm, cperm));
    PetscFunctionReturn(0);
  }
  if (row) PetscCall(ISGetLocalSize(row, &nr));
  if (col) PetscCall(ISGetLocalSize(col, &nc));
  PetscCheck(nr == mbs && (sbaij || nc == mbs), PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Factorisations of MATSEQBINBCSR take block orderings of its %" PetscInt_FMT
             " block rows (as MatGetOrdering gives), not index sets of %" PetscInt_FMT " and %" PetscInt_FMT
             " entries",
             mbs, nr, nc);
  if (!sbaij) {
    PetscCall(PetscObjectReference((PetscObject)row));
    PetscCall(PetscObjectReference((PetscObject)col));
    *rperm = row;
    *cperm = col;
    PetscFunctionReturn(0);
  }
  {
    const PetscInt       *idx;
    std::vector<PetscInt> perm(mbs);
    std::vector<char>     seen(mbs, 0);

    PetscCall(ISGetIndices(row, &idx));
    for (PetscInt i = 0; i < mbs; i++) perm[i] = idx[i];
    PetscCall(ISRestoreIndices(row, &idx));
    for (PetscInt i = 0; i < mbs; i++) {
      PetscCheck(
        perm[i] >= 0 && perm[i] < mbs && !seen[perm[i]], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
        "The ordering for the factorisation of MATSEQBINBCSR is not a permutation of its %" PetscInt_FMT
        " block rows (entry %" PetscInt_FMT " is %" PetscInt_FMT ")",
        mbs, i, perm[i]);
      seen[perm[i]] = 1;
    }
    if (perm != f->perm) {
      f->perm = std::move(perm);
      PetscCall(BuildShadow(A, PETSC_TRUE, f));
    }
  }
  PetscCall(MatGetOrdering(f->S, MATORDERINGNATURAL, rperm, cperm));
  PetscFunctionReturn(0);
}

/* Between A's numbering and S's (f->perm) for the permuting solves: to = from, moved block by block. */
PetscErrorCode Permute(const FactorShadow *f, Vec from, Vec to, PetscBool into_shadow)
{
  const PetscScalar *src;
  PetscScalar       *dst;
  const PetscInt     bs = f->bs, mbs = (PetscInt)f->perm.size();

  PetscFunctionBegin;
  PetscCall(VecGetArrayRead(from, &src));
  PetscCall(VecGetArrayWrite(to, &dst));
  for (PetscInt i = 0; i < mbs; i++) {
    const PetscInt o = f->perm[i] * bs;
    for (PetscInt d = 0; d < bs; d++) {
      if (into_shadow) dst[i * bs + d] = src[o + d];
      else dst[o + d] = src[i * bs + d];
    }
  }
  PetscCall(VecRestoreArrayRead(from, &src));
  PetscCall(VecRestoreArrayWrite(to, &dst));
  PetscFunctionReturn(0);
}

PetscErrorCode WorkVectors(FactorShadow *f)
{
  PetscFunctionBegin;
  if (!f->bp) PetscCall(VecCreateSeq(PETSC_COMM_SELF, f->S->rmap->n, &f->bp));
  if (!f->xp) PetscCall(VecCreateSeq(PETSC_COMM_SELF, f->S->rmap->n, &f->xp));
  PetscFunctionReturn(0);
}

/* One of the factor's solves between the two numberings: the right-hand side moved into S's (in), the
   result moved back into A's (out). The split solves of PCApplySymmetricLeft/Right keep the
   intermediate vector in S's numbering: forward moves in only, backward out only. */
PetscErrorCode PermutedApply(Mat F, Vec b, Vec x, PetscErrorCode (*FactorShadow::*op)(Mat, Vec, Vec), bool in,
                             bool out)
{
  FactorShadow *f;

  PetscFunctionBegin;
  PetscCall(binbcsr_factor::Get(F, &f));
  PetscCall(WorkVectors(f));
  if (in) PetscCall(Permute(f, b, f->bp, PETSC_TRUE));
  PetscCall((*(f->*op))(F, in ? f->bp : b, out ? f->xp : x));
  if (out) PetscCall(Permute(f, f->xp, x, PETSC_FALSE));
  PetscFunctionReturn(0);
}

/* x = P (L D L^T)^-1 P^T b; the transpose solve is the same (the factor is symmetric) */
PetscErrorCode PermutedSolve(Mat F, Vec b, Vec x)
{
  return PermutedApply(F, b, x, &FactorShadow::solve, true, true);
}
PetscErrorCode PermutedForwardSolve(Mat F, Vec b, Vec x)
{
  return PermutedApply(F, b, x, &FactorShadow::forwardsolve, true, false);
}
PetscErrorCode PermutedBackwardSolve(Mat F, Vec b, Vec x)
{
  return PermutedApply(F, b, x, &FactorShadow::backwardsolve, false, true);
}

/* seqsbaij's symbolic and numeric routines set the factor's solves (per block size and ordering), so
   the permuting wrappers go back on after each of them. */
PetscErrorCode FactorShadow::Routed(Mat F)
{
  PetscFunctionBegin;
  if (perm.empty()) PetscFunctionReturn(0);
  auto route = [](PetscErrorCode (*&op)(Mat, Vec, Vec), PetscErrorCode (*&saved)(Mat, Vec, Vec),
                  PetscErrorCode (*wrapper)(Mat, Vec, Vec)) {
    if (op && op != wrapper) {
      saved = op;
      op    = wrapper;
    }
  };
  route(F->ops->solve, solve, PermutedSolve);
  route(F->ops->forwardsolve, forwardsolve, PermutedForwardSolve);
  route(F->ops->backwardsolve, backwardsolve, PermutedBackwardSolve);
  if (F->ops->solvetranspose) F->ops->solvetranspose = PermutedSolve;
  /* MatMatSolve falls back to one MatSolve per column */
  F->ops->matsolve          = nullptr;
  F->ops->matsolvetranspose = nullptr;
  PetscFunctionReturn(0);
}

/* The factor of a matrix without rows: nothing to compute or solve. PETSc 3.18's BAIJ and SBAIJ
   factorisations of an empty matrix with block size 3 read past their arrays (SEGV in the numeric
   ICC), and such matrices come with every rank that holds no rows (the sub-matrix of PCBJACOBI). */
PetscErrorCode EmptyNumeric(Mat F, Mat, const MatFactorInfo *)
{
  PetscFunctionBegin;
  F->assembled    = PETSC_TRUE;
  F->preallocated = PETSC_TRUE;
  PetscFunctionReturn(0);
}

PetscErrorCode EmptySolve(Mat, Vec, Vec) { return 0; }

PetscErrorCode EmptyFactor(Mat F)
{
  PetscFunctionBegin;
  F->ops->lufactornumeric       = EmptyNumeric;
  F->ops->choleskyfactornumeric = EmptyNumeric;
  F->ops->solve                 = EmptySolve;
  F->ops->solvetranspose        = EmptySolve;
  F->ops->forwardsolve          = EmptySolve;
  F->ops->backwardsolve         = EmptySolve;
  F->ops->matsolve              = nullptr;
  F->ops->matsolvetranspose     = nullptr;
  PetscFunctionReturn(0);
}

/* The four symbolic factorisations: refill the shadow, translate the ordering to it, run PETSc's
   routine on it (the routing keeps the numeric kernel that routine chose on the shadow). */
template <class Symbolic> PetscErrorCode ShadowSymbolic(Mat F, Mat A, IS row, IS col, Symbolic &&symbolic)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  FactorShadow   *f;

  PetscFunctionBegin;
  if (A->rmap->n == 0) {
    PetscCall(EmptyFactor(F));
    PetscFunctionReturn(0);
  }
  /* a new pattern (or the first one: the factor was asked for before the matrix was assembled) */
  PetscCall(binbcsr_factor::Get(F, &f));
  if (f->nzstate != A->nonzerostate) {
    PetscBool sbaij;
    PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
               "Symbolic factorisation needs an assembled MATSEQBINBCSR matrix");
    PetscCall(PetscObjectTypeCompare((PetscObject)f->S, MATSEQSBAIJ, &sbaij));
    f->perm.clear();
    PetscCall(BuildShadow(A, sbaij, f));
  }
  PetscCall(binbcsr_factor::OnShadow<FactorShadow>(F, A, [&](FactorShadow *f, Mat) {
    IS r, c;

    PetscFunctionBegin;
    PetscCall(ShadowOrdering(A, f, row, col, &r, &c));
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
  PetscCall(ShadowSymbolic(F, A, perm, nullptr,
                           [&](FactorShadow *f, IS r, IS) { return (*f->iccsymbolic)(F, f->S, r, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode CholeskySymbolic(Mat F, Mat A, IS perm, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(F, A, perm, nullptr, [&](FactorShadow *f, IS r, IS) {
    return (*f->choleskysymbolic)(F, f->S, r, info);
  }));
  PetscFunctionReturn(0);
}

PetscErrorCode ILUSymbolic(Mat F, Mat A, IS row, IS col, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(
    F, A, row, col, [&](FactorShadow *f, IS r, IS c) { return (*f->ilusymbolic)(F, f->S, r, c, info); }));
  PetscFunctionReturn(0);
}

PetscErrorCode LUSymbolic(Mat F, Mat A, IS row, IS col, const MatFactorInfo *info)
{
  PetscFunctionBegin;
  PetscCall(ShadowSymbolic(
    F, A, row, col, [&](FactorShadow *f, IS r, IS c) { return (*f->lusymbolic)(F, f->S, r, c, info); }));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode MatGetFactor_SeqBinBCSR_Petsc(Mat A, MatFactorType ftype, Mat *F)
{
  const PetscBool upper =
    (ftype == MAT_FACTOR_ICC || ftype == MAT_FACTOR_CHOLESKY) ? PETSC_TRUE : PETSC_FALSE;
  FactorShadow *f;

  PetscFunctionBegin;
  PetscCheck(ftype == MAT_FACTOR_ICC || ftype == MAT_FACTOR_CHOLESKY || ftype == MAT_FACTOR_ILU ||
               ftype == MAT_FACTOR_LU,
             PETSC_COMM_SELF, PETSC_ERR_SUP,
             "MATSEQBINBCSR provides ICC, Cholesky, ILU and LU (MATSOLVERPETSC), not %s",
             MatFactorTypes[ftype]);
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
             "Factorisation of a non-square MATSEQBINBCSR matrix (%" PetscInt_FMT " x %" PetscInt_FMT ")",
             A->rmap->n, A->cmap->n);
  f = new FactorShadow;
  PetscCall(BuildShadow(A, upper, f));

  PetscCall(MatGetFactor(f->S, MATSOLVERPETSC, ftype, F));
  PetscCall(binbcsr_factor::Attach(*F, f));

  Mat B               = *F;
  f->iccsymbolic      = B->ops->iccfactorsymbolic;
  f->choleskysymbolic = B->ops->choleskyfactorsymbolic;
  f->ilusymbolic      = B->ops->ilufactorsymbolic;
  f->lusymbolic       = B->ops->lufactorsymbolic;
  if (f->iccsymbolic) B->ops->iccfactorsymbolic = ICCSymbolic;
  if (f->choleskysymbolic) B->ops->choleskyfactorsymbolic = CholeskySymbolic;
  if (f->ilusymbolic) B->ops->ilufactorsymbolic = ILUSymbolic;
  if (f->lusymbolic) B->ops->lufactorsymbolic = LUSymbolic;
  if (upper) { /* LU and ILU keep BAIJ's preferences (nested dissection for LU, natural for ILU); ICC and
                  Cholesky take AIJ's (natural for ICC, nested dissection for Cholesky) */
    PetscCall(PetscFree(B->preferredordering[ftype]));
    PetscCall(PetscStrallocpy(ftype == MAT_FACTOR_CHOLESKY ? MATORDERINGND : MATORDERINGNATURAL,
                              (char **)&B->preferredordering[ftype]));
  }
  PetscFunctionReturn(0);
}
