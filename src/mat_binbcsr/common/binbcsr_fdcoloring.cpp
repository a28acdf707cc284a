/* Finite-difference Jacobians by colouring (MatFDColoring) for MATSEQBINBCSR and MATMPIBINBCSR: what
   SNES uses by default on a DMDA without a Jacobian routine (snes ex19), and -snes_fd_color.

   PETSc's colouring code writes the differences straight into the value array of an AIJ (or BAIJ)
   matrix through addresses it precomputes at set-up; binbcsr's values are interleaved by bin, and in
   single precision not even PetscScalars. So the colouring is PETSc's own on the matrix's AIJ shadow
   (binbcsr_submat.cpp): created and set up on the shadow, applied to it, and the shadow's values then
   written into the binbcsr matrix through the value maps the shadow keeps (one pass, no MatSetValues).
   The pattern is frozen, so the shadow (and the addresses in the colouring) stay valid. Cost: the
   shadow's memory, and one copy of the values per Jacobian. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

PetscErrorCode MatFDColoringCreate_BinBCSR(Mat A, ISColoring iscoloring, MatFDColoring c)
{
  Mat S;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCheck(S->ops->fdcoloringcreate, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP,
             "No finite-difference colouring for the AIJ shadow of type %s", ((PetscObject)S)->type_name);
  PetscCall((*S->ops->fdcoloringcreate)(S, iscoloring, c));
  PetscFunctionReturn(0);
}

PetscErrorCode MatFDColoringSetUp_BinBCSR(Mat A, ISColoring iscoloring, MatFDColoring c)
{
  Mat S;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  if (S->ops->fdcoloringsetup) PetscCall((*S->ops->fdcoloringsetup)(S, iscoloring, c));
  PetscFunctionReturn(0);
}

PetscErrorCode MatFDColoringApply_BinBCSR(Mat A, MatFDColoring c, Vec x, void *sctx)
{
  Mat S;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetAIJShadow_Private(A, &S));
  PetscCall(PetscOptionsPushCreateViewerOff(PETSC_TRUE)); /* S's assembly is internal: no -mat_view of it */
  PetscCall((*S->ops->fdcoloringapply)(S, c, x, sctx));   /* zeroes S, fills it, assembles it */
  PetscCall(PetscOptionsPopCreateViewerOff());
  PetscCall(MatBinBCSRSetValuesFromAIJShadow_Private(A));
  /* an AIJ Jacobian is viewed by -mat_view each time the colouring assembles it: so is this one */
  PetscCall(MatViewFromOptions(A, nullptr, "-mat_view"));
  PetscFunctionReturn(0);
}
