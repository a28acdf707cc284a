/* C = P^T A P for A MATSEQBINBCSR and P SeqAIJ (PCGAMG's coarse operators, MatPtAP): A P made here from
   the blocks, P^T (A P) by PETSc's AIJ product (MATPRODUCT_AtB).

   Every other product with a binbcsr operand runs PETSc's AIJ code on the matrix's AIJ shadow
   (common/binbcsr_shadow_ops.cpp). For the Galerkin product that shadow was the larger part of GAMG's
   set-up: linear_38k's 40K-unknown operator copied into 19 MB of AIJ plus a 6 MB value map (~90 ms on a
   VM where a first touch of a page costs ~10 us), then PETSc's PtAP of it (~50 ms). A P has the rows of
   A and a few coarse columns per row (plain aggregation: the columns of the aggregates of the row's
   neighbours), so it is made directly: per block row one column pattern (all rows of a block row have
   the same: every block is stored whole), then the values block by block.

   A P is kept with C (its pattern is C's symbolic phase), and every numeric phase computes it again from
   A's and P's current values before PETSc's AtB numeric phase: GAMG's reuse of its interpolation after a
   refill (MAT_REUSE_MATRIX) gets the new values. A or P with another nonzero pattern is an error (redo
   the product with MAT_INITIAL_MATRIX), as for PETSc's own products. */
#include "binbcsr.h"
#include "../common/binbcsr_composed.h"
#include <petsc/private/matimpl.h>
#include <algorithm>
#include <vector>

namespace {

const char ptap_key[] = "MatBinBCSR_PtAP_AP";

struct PtAPContext {
  Mat              AP   = nullptr;
  PetscObjectState a_nz = 0, p_nz = 0;      /* the nonzero states the pattern was made for */
  PetscErrorCode (*numeric)(Mat) = nullptr; /* PETSc's AtB numeric phase */
  ~PtAPContext() { (void)MatDestroy(&AP); }
};

/* P's CSR arrays (SeqAIJ: its own, sorted rows). */
PetscErrorCode GetCSR(Mat P, const PetscInt **pi, const PetscInt **pj)
{
  PetscInt  n;
  PetscBool done;

  PetscFunctionBegin;
  PetscCall(MatGetRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &n, pi, pj, &done));
  PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP, "binbcsr PtAP: no row structure from P");
  PetscFunctionReturn(0);
}

PetscErrorCode RestoreCSR(Mat P, const PetscInt **pi, const PetscInt **pj)
{
  PetscInt  n;
  PetscBool done;

  PetscFunctionBegin;
  PetscCall(MatRestoreRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &n, pi, pj, &done));
  PetscFunctionReturn(0);
}

/* *AP: a new SeqAIJ with the pattern of A P (block row br: the union of the rows of P that its blocks'
   columns name), values unset. */
PetscErrorCode APSymbolic(Mat A, Mat P, Mat *AP)
{
  Mat_SeqBinBCSR       *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt        bs = a->bs, mbs = a->mbs, pn = P->cmap->n;
  const PetscInt       *pi, *pj;
  std::vector<PetscInt> mark(pn, -1), start(mbs + 1, 0), cols;
  PetscInt             *nnz, *idx;

  PetscFunctionBegin;
  if (a->sym) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  PetscCall(GetCSR(P, &pi, &pj));
  for (PetscInt br = 0; br < mbs; br++) {
    const size_t first = cols.size();
    ForEachFullRowBlock(a, br, [&](PetscInt bc, PetscInt, bool) {
      for (PetscInt r = bc * bs; r < bc * bs + bs; r++)
        for (PetscInt k = pi[r]; k < pi[r + 1]; k++)
          if (mark[pj[k]] != br) mark[pj[k]] = br, cols.push_back(pj[k]);
    });
    std::sort(cols.begin() + first, cols.end());
    start[br + 1] = (PetscInt)cols.size();
  }
  PetscCall(RestoreCSR(P, &pi, &pj));
  PetscCall(MatCreate(PETSC_COMM_SELF, AP));
  PetscCall(MatSetSizes(*AP, A->rmap->n, pn, A->rmap->n, pn));
  PetscCall(MatSetType(*AP, MATSEQAIJ));
  PetscCall(PetscMalloc1(A->rmap->n, &nnz));
  for (PetscInt br = 0; br < mbs; br++)
    for (PetscInt i = 0; i < bs; i++) nnz[br * bs + i] = start[br + 1] - start[br];
  PetscCall(MatSeqAIJSetPreallocation(*AP, 0, nnz));
  PetscCall(PetscFree(nnz));
  PetscCall(PetscMalloc1(PetscMax((size_t)bs * cols.size(), (size_t)1), &idx));
  size_t n = 0;
  for (PetscInt br = 0; br < mbs; br++)
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt p = start[br]; p < start[br + 1]; p++) idx[n++] = cols[p];
  PetscCall(MatSeqAIJSetColumnIndices(*AP, idx));
  PetscCall(PetscFree(idx));
  PetscCall(MatAssemblyBegin(*AP, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*AP, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

/* AP's values = A P, block by block: column j of block (br, bc) times row bc bs + j of P. The rows of
   block row br are consecutive in AP and of one length, so an entry of P's row lands at the same place
   q in each: one lookup serves the bs rows. */
template <typename V>
void APValues(const Mat_SeqBinBCSR *a, const V *val, const PetscInt *pi, const PetscInt *pj,
              const PetscScalar *pv, const PetscInt *ai, const PetscInt *aj, PetscInt *pos, PetscScalar *apv)
{
  const PetscInt bs = a->bs, bw = a->bw;
  for (PetscInt br = 0; br < a->mbs; br++) {
    const PetscInt row0 = br * bs, len = ai[row0 + 1] - ai[row0];
    PetscScalar   *out = apv + ai[row0]; /* row i of br at out + i len */
    for (PetscInt p = 0; p < len; p++) pos[aj[ai[row0] + p]] = p;
    std::fill(out, out + bs * len, 0.0);
    ForEachFullRowBlock(a, br, [&](PetscInt bc, PetscInt vb, bool t) {
      for (PetscInt j = 0; j < bs; j++) {
        const PetscInt r = bc * bs + j;
        for (PetscInt k = pi[r]; k < pi[r + 1]; k++) {
          const PetscInt    q  = pos[pj[k]];
          const PetscScalar pk = pv[k];
          for (PetscInt i = 0; i < bs; i++)
            out[i * len + q] += (PetscScalar)val[FullRowEntry(vb, t, i, j, bs, bw)] * pk;
        }
      }
    });
  }
}

PetscErrorCode APNumeric(Mat A, Mat P, Mat AP)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscInt    *pi, *pj, *ai, *aj;
  const PetscScalar *pv;
  PetscScalar       *apv;
  PetscInt           n;
  PetscBool          done;

  PetscFunctionBegin;
  if (a->sym) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  std::vector<PetscInt> pos(P->cmap->n);
  PetscCall(GetCSR(P, &pi, &pj));
  PetscCall(MatGetRowIJ(AP, 0, PETSC_FALSE, PETSC_FALSE, &n, &ai, &aj, &done));
  PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_PLIB, "binbcsr PtAP: no row structure from A P");
  PetscCall(MatSeqAIJGetArrayRead(P, &pv));
  PetscCall(MatSeqAIJGetArrayWrite(AP, &apv));
  if (a->val) APValues(a, a->val, pi, pj, pv, ai, aj, pos.data(), apv);
  else APValues(a, a->valf, pi, pj, pv, ai, aj, pos.data(), apv);
  PetscCall(MatSeqAIJRestoreArrayWrite(AP, &apv));
  PetscCall(MatSeqAIJRestoreArrayRead(P, &pv));
  PetscCall(MatRestoreRowIJ(AP, 0, PETSC_FALSE, PETSC_FALSE, &n, &ai, &aj, &done));
  PetscCall(RestoreCSR(P, &pi, &pj));
  PetscFunctionReturn(0);
}

/* Runs f on C with its product turned into AtB of (P, AP), then turns it back (also on an error). */
template <class F> PetscErrorCode AsAtB(Mat C, Mat AP, F &&f)
{
  Mat_Product         *product = C->product;
  const MatProductType type    = product->type;
  Mat                  A = product->A, P = product->B;

  PetscFunctionBegin;
  product->type       = MATPRODUCT_AtB;
  product->A          = P;
  product->B          = AP;
  PetscErrorCode ierr = f();
  product->type       = type;
  product->A          = A;
  product->B          = P;
  PetscCall(ierr);
  PetscFunctionReturn(0);
}

PetscErrorCode ProductNumeric_PtAP(Mat C)
{
  PtAPContext     *ctx;
  Mat              A = C->product->A, P = C->product->B;
  PetscObjectState anz, pnz;

  PetscFunctionBegin;
  PetscCall(binbcsr::QueryComposed((PetscObject)C, ptap_key, &ctx));
  PetscCheck(ctx && ctx->AP && ctx->numeric, PetscObjectComm((PetscObject)C), PETSC_ERR_PLIB,
             "binbcsr PtAP: the numeric phase has lost its symbolic phase's context");
  PetscCall(MatGetNonzeroState(A, &anz));
  PetscCall(MatGetNonzeroState(P, &pnz));
  PetscCheck(
    anz == ctx->a_nz && pnz == ctx->p_nz, PetscObjectComm((PetscObject)C), PETSC_ERR_ARG_INCOMP,
    "binbcsr PtAP: A or P has not the nonzero pattern the product's symbolic phase was made for; redo the product with MAT_INITIAL_MATRIX");
  PetscCall(APNumeric(A, P, ctx->AP));
  PetscCall(AsAtB(C, ctx->AP, [&]() { return ctx->numeric(C); }));
  PetscFunctionReturn(0);
}
} // namespace

/* ops->productsymbolic of C = P^T A P, A MATSEQBINBCSR, P SeqAIJ (MatProductSetFromOptions_BinBCSR). */
PetscErrorCode MatProductSymbolic_PtAP_SeqBinBCSR_SeqAIJ(Mat C)
{
  Mat          A = C->product->A, P = C->product->B, AP;
  PtAPContext *ctx;

  PetscFunctionBegin;
  PetscCheck(((Mat_SeqBinBCSR *)A->data)->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatPtAP needs an assembled MATSEQBINBCSR matrix");
  PetscCall(APSymbolic(A, P, &AP));
  PetscCall(binbcsr::GetOrCompose((PetscObject)C, ptap_key, &ctx));
  PetscCall(MatDestroy(&ctx->AP));
  ctx->AP = AP;
  PetscCall(MatGetNonzeroState(A, &ctx->a_nz));
  PetscCall(MatGetNonzeroState(P, &ctx->p_nz));
  /* PETSc's dispatch and symbolic phase for AtB of two SeqAIJ (which make C a SeqAIJ) */
  PetscCall(AsAtB(C, AP, [&]() -> PetscErrorCode {
    PetscErrorCode ierr = MatProductSetFromOptions(C);
    if (ierr) return ierr;
    if (!C->ops->productsymbolic)
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_PLIB, "binbcsr PtAP: PETSc has no AtB product of two SeqAIJ");
    return (*C->ops->productsymbolic)(C);
  }));
  PetscCheck(C->ops->productnumeric, PetscObjectComm((PetscObject)C), PETSC_ERR_PLIB,
             "binbcsr PtAP: PETSc's AtB symbolic phase left no numeric phase");
  ctx->numeric           = C->ops->productnumeric;
  C->ops->productnumeric = ProductNumeric_PtAP;
  C->ops->productsymbolic =
    MatProductSymbolic_PtAP_SeqBinBCSR_SeqAIJ; /* MatProductReplaceMats may run it again */
  PetscFunctionReturn(0);
}
