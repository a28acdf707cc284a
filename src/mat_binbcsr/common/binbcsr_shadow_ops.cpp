/* What PCGAMG asks of its operator beyond products with vectors, for seq and mpi binbcsr, through the
   AIJ shadow of binbcsr_submat.cpp (MatBinBCSRGetAIJShadow_Private: one copy, refreshed only when the
   matrix changed):

   - MatCreateGraph (the strength graph GAMG coarsens): the shadow's own, PETSc's AIJ code; of a
     sequential matrix of blocks the same graph made from the blocks (seq/binbcsr_graph.cpp).
   - Matrix products (MatProduct AB, AtB, ABt, PtAP, RARt, ABC: GAMG's prolongator smoothing A P and
     its coarse operators P^T A P) where any operand is binbcsr: PETSc's AIJ product of the operands with
     each binbcsr one replaced by its shadow. Except P^T A P of a sequential binbcsr and a SeqAIJ P
     (GAMG's Galerkin products on one rank): A P from the blocks, no shadow (seq/binbcsr_ptap.cpp).
     The result is AIJ (so are GAMG's coarse levels); the fine level keeps the binbcsr operator and its
     fast MatMult for the smoothers.

   A product is routed once, at its symbolic phase: the operands in the product are swapped for their
   shadows, PETSc's AIJ dispatch (MatProductSetFromOptions) picks the AIJ symbolic routine and runs it
   on the result matrix, and the numeric routine it leaves is kept in a context composed on the result.
   Every numeric phase (MatProductNumeric, MAT_REUSE_MATRIX, GAMG's reuse of its interpolation after a
   refill) first refreshes the shadows and then runs that routine with the shadows swapped in again.
   Between phases the product names the binbcsr operands, so PETSc's own checks (MatProductReplaceMats,
   GAMG's "B->product->A == A") see the matrices the caller gave. A shadow rebuilt for a new nonzero
   pattern cannot serve the old symbolic phase: that is an error (redo the product with
   MAT_INITIAL_MATRIX), as the AIJ product itself would give a wrong answer. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>
#include "binbcsr_composed.h"

namespace {
PetscErrorCode IsBinBCSR(Mat M, PetscBool *is)
{
  PetscFunctionBegin;
  *is = PETSC_FALSE;
  if (M) PetscCall(PetscObjectTypeCompareAny((PetscObject)M, is, MATSEQBINBCSR, MATMPIBINBCSR, ""));
  PetscFunctionReturn(0);
}

/* What the symbolic phase left for the numeric phases of one product. */
struct ShadowProduct {
  PetscObjectId shadow[3]        = {0, 0,
                                    0}; /* object ids of the shadows of operands A, B, C (0: not binbcsr); ids, not
                                          pointers: a rebuilt shadow may get the freed one's address */
  PetscErrorCode (*numeric)(Mat) = nullptr; /* the AIJ numeric routine */
};

const char product_key[] = "MatBinBCSR_ShadowProduct";

/* The operands of the product of C (A, B, C), any of them NULL. */
void Operands(Mat C, Mat *ops[3])
{
  ops[0] = &C->product->A;
  ops[1] = &C->product->B;
  ops[2] = &C->product->C;
}

/* Swaps the binbcsr operands of C's product for their (current) shadows: orig[] gets the operands. */
PetscErrorCode SwapInShadows(Mat C, Mat orig[3], Mat shadow[3])
{
  Mat *ops[3];

  PetscFunctionBegin;
  Operands(C, ops);
  for (int i = 0; i < 3; i++) {
    PetscBool bin;
    orig[i]   = *ops[i];
    shadow[i] = nullptr;
    PetscCall(IsBinBCSR(orig[i], &bin));
    if (bin) PetscCall(MatBinBCSRGetAIJShadow_Private(orig[i], &shadow[i]));
  }
  /* only now, so that an error above leaves the product naming (and referencing) its own operands */
  for (int i = 0; i < 3; i++)
    if (shadow[i]) *ops[i] = shadow[i];
  PetscFunctionReturn(0);
}

void SwapBack(Mat C, Mat orig[3])
{
  Mat *ops[3];
  Operands(C, ops);
  for (int i = 0; i < 3; i++) *ops[i] = orig[i];
}

PetscErrorCode ProductNumeric_Shadow(Mat C)
{
  ShadowProduct *sp;
  Mat            orig[3], shadow[3];

  PetscFunctionBegin;
  PetscCall(binbcsr::QueryComposed((PetscObject)C, product_key, &sp));
  PetscCheck(sp, PetscObjectComm((PetscObject)C), PETSC_ERR_PLIB,
             "binbcsr product: the numeric phase has lost its symbolic phase's context");
  PetscCall(SwapInShadows(C, orig, shadow)); /* refreshes each shadow (collective) */
  for (int i = 0; i < 3; i++) {
    if ((shadow[i] ? ((PetscObject)shadow[i])->id : 0) == sp->shadow[i]) continue;
    SwapBack(C, orig);
    SETERRQ(
      PetscObjectComm((PetscObject)C), PETSC_ERR_ARG_INCOMP,
      "binbcsr product: operand %d is not the matrix (or has not the nonzero pattern) the product's symbolic phase was made for; redo the product with MAT_INITIAL_MATRIX",
      i);
  }
  PetscErrorCode ierr = sp->numeric(C);
  SwapBack(C, orig);
  PetscCall(ierr);
  PetscFunctionReturn(0);
}

PetscErrorCode ProductSymbolic_Shadow(Mat C)
{
  Mat            orig[3], shadow[3];
  ShadowProduct *sp;

  PetscFunctionBegin;
  PetscCall(SwapInShadows(C, orig, shadow));
  /* PETSc's dispatch for the AIJ operands, then its symbolic phase on C (which makes C an AIJ matrix) */
  PetscErrorCode ierr = MatProductSetFromOptions(C);
  if (!ierr && !C->ops->productsymbolic) {
    SwapBack(C, orig);
    SETERRQ(PetscObjectComm((PetscObject)C), PETSC_ERR_SUP,
            "MatProduct %s of binbcsr (through its AIJ copy) with %s: not supported by PETSc's AIJ either",
            MatProductTypes[C->product->type], orig[1] ? ((PetscObject)orig[1])->type_name : "nothing");
  }
  if (!ierr) ierr = (*C->ops->productsymbolic)(C);
  SwapBack(C, orig);
  PetscCall(ierr);
  PetscCheck(C->ops->productnumeric, PetscObjectComm((PetscObject)C), PETSC_ERR_PLIB,
             "binbcsr product: PETSc's AIJ symbolic phase left no numeric phase");

  PetscCall(binbcsr::GetOrCompose((PetscObject)C, product_key, &sp));
  for (int i = 0; i < 3; i++)
    sp->shadow[i] = shadow[i] ? ((PetscObject)shadow[i])->id : 0; /* the shadows live with their matrices */
  sp->numeric             = C->ops->productnumeric;
  C->ops->productnumeric  = ProductNumeric_Shadow;
  C->ops->productsymbolic = ProductSymbolic_Shadow; /* MatProductReplaceMats may run it again */
  PetscFunctionReturn(0);
}
} // namespace

/* ops->productsetfromoptions of both binbcsr types, and their composed
   "MatProductSetFromOptions_anytype_C" (what PETSc asks when the operands' types differ). */
PetscErrorCode MatProductSetFromOptions_BinBCSR(Mat C)
{
  PetscBool dense = PETSC_FALSE, binA;

  PetscFunctionBegin;
  if (C->product->type == MATPRODUCT_AB || C->product->type == MATPRODUCT_AtB) {
    PetscCall(IsBinBCSR(C->product->A, &binA));
    if (binA)
      PetscCall(
        PetscObjectBaseTypeCompareAny((PetscObject)C->product->B, &dense, MATSEQDENSE, MATMPIDENSE, ""));
  }
  /* binbcsr times a dense block of vectors: PETSc's column-by-column product (MatProductSymbolic_X_Dense)
     with binbcsr's own MatMult / MatMultTranspose, no copy */
  if (dense) PetscFunctionReturn(0);
  if (C->product->type == MATPRODUCT_PtAP) { /* A P from the blocks, no shadow: binbcsr_ptap.cpp */
    PetscBool seqA, aijP;
    PetscCall(PetscObjectTypeCompare((PetscObject)C->product->A, MATSEQBINBCSR, &seqA));
    PetscCall(PetscObjectTypeCompare((PetscObject)C->product->B, MATSEQAIJ, &aijP));
    if (seqA && aijP) {
      C->ops->productsymbolic = MatProductSymbolic_PtAP_SeqBinBCSR_SeqAIJ;
      PetscFunctionReturn(0);
    }
  }
  switch (C->product->type) {
  case MATPRODUCT_AB:
  case MATPRODUCT_AtB:
  case MATPRODUCT_ABt:
  case MATPRODUCT_PtAP:
  case MATPRODUCT_RARt:
  case MATPRODUCT_ABC:
    C->ops->productsymbolic = ProductSymbolic_Shadow;
    break;
  default:
    break; /* left unset: PETSc reports the product as unsupported */
  }
  PetscFunctionReturn(0);
}

/* ops->creategraph (GAMG's aggregation): of a sequential matrix of blocks, MatCreateGraph of its block
   graph (MatSeqBinBCSRBlockGraph: what PETSc's AIJ code reduces the matrix to first, made from the
   blocks without a copy of the values); otherwise the shadow's graph. */
PetscErrorCode MatCreateGraph_BinBCSR(Mat A, PetscBool sym, PetscBool scale,
                                      PetscReal filter BINBCSR_CREATEGRAPH_ARGS, Mat *graph)
{
  Mat       S;
  PetscBool seq;
  PetscInt  bs;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQBINBCSR, &seq));
  PetscCall(MatGetBlockSize(A, &bs));
  if (seq && bs > 1 BINBCSR_CREATEGRAPH_WHOLE_BLOCKS) {
    Mat G0;
    PetscCall(MatSeqBinBCSRBlockGraph(A, &G0));
    PetscErrorCode ierr = MatCreateGraph(G0, sym, scale, filter BINBCSR_CREATEGRAPH_NO_INDEX, graph);
    PetscCall(MatDestroy(&G0));
    PetscCall(ierr);
    PetscFunctionReturn(0);
  }
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(MatCreateGraph(S, sym, scale, filter BINBCSR_CREATEGRAPH_PASS, graph));
  PetscFunctionReturn(0);
}
