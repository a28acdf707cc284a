/* MatSOR for MATMPIBINBCSR: processor-local sweeps (SOR_LOCAL_FORWARD/BACKWARD/SYMMETRIC_SWEEP), as
   PETSc's MPIAIJ offers: each outer iteration exchanges the ghost values once, moves the off-rank
   coupling to the right-hand side (b - B x_ghost) and sweeps the diagonal part. A global sweep in row
   order would serialise the ranks, so it is refused, as by MPIAIJ.

   PCEISENSTAT as MPIAIJ does it: SOR_APPLY_UPPER and the diagonal scaling are the diagonal part's;
   SOR_EISENSTAT sweeps the diagonal part locally and adds the off-rank coupling between the two
   sweeps, so the preconditioned operator is (L_loc + E)^-1 A (U_loc + E)^-1 with the whole A. */
#include "mpibinbcsr.h"

namespace {
/* x = (L + E)^-1 A (U + E)^-1 b with L, U the diagonal part's triangles:
     y = (U + E)^-1 b                                   local backward sweep from zero
     t = b - (2/omega - 1) D y + B y_ghost              A y = (L + E) y + (U + E) y - (2E - D) y + B y_ghost
     x = y + (L + E)^-1 t                               local forward sweep from zero */
PetscErrorCode SOREisenstat(Mat mat, Vec bb, PetscReal omega, PetscReal fshift, PetscInt lits, Vec xx)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  Vec             t, z;
  PetscBool       hasop;

  PetscFunctionBegin;
  PetscCall(VecDuplicate(bb, &t));
  PetscCall(VecDuplicate(bb, &z));
  PetscUseTypeMethod(b->A, sor, bb, omega, (MatSORType)(SOR_ZERO_INITIAL_GUESS | SOR_LOCAL_BACKWARD_SWEEP),
                     fshift, lits, 1, xx);
  PetscCall(VecScatterBegin(b->Mvctx, xx, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(MatHasOperation(b->A, MATOP_MULT_DIAGONAL_BLOCK, &hasop));
  if (hasop) PetscCall(MatMultDiagonalBlock(b->A, xx, t));
  else { /* another inner type (-mat_mpibinbcsr_inner_type): the point diagonal */
    PetscCall(MatGetDiagonal(b->A, t));
    PetscCall(VecPointwiseMult(t, t, xx));
  }
  if (fshift != 0.0) PetscCall(VecAXPY(t, fshift, xx));
  PetscCall(VecAYPX(t, (omega - 2.0) / omega, bb));
  PetscCall(VecScatterEnd(b->Mvctx, xx, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  if (!b->garray.empty()) PetscUseTypeMethod(b->B, multadd, b->lvec, t, t);
  PetscUseTypeMethod(b->A, sor, t, omega, (MatSORType)(SOR_ZERO_INITIAL_GUESS | SOR_LOCAL_FORWARD_SWEEP),
                     fshift, lits, 1, z);
  PetscCall(VecAXPY(xx, 1.0, z));
  PetscCall(VecDestroy(&t));
  PetscCall(VecDestroy(&z));
  PetscFunctionReturn(0);
}
} // namespace

PETSC_INTERN PetscErrorCode MatSOR_MPIBinBCSR(Mat mat, Vec bb, PetscReal omega, MatSORType flag,
                                              PetscReal fshift, PetscInt its, PetscInt lits, Vec xx)
{
  Mat_MPIBinBCSR  *b      = MPIBinBCSR(mat);
  const MatSORType local  = (MatSORType)(flag & SOR_LOCAL_SYMMETRIC_SWEEP);
  const PetscBool  ghosts = (PetscBool)!b->garray.empty();
  Vec              bb1    = nullptr;

  PetscFunctionBegin;
  if (flag == SOR_APPLY_UPPER) { /* (U + E) b of the diagonal part, as MPIAIJ */
    PetscUseTypeMethod(b->A, sor, bb, omega, flag, fshift, lits, 1, xx);
    PetscFunctionReturn(0);
  }
  if (flag & SOR_EISENSTAT) {
    PetscCall(SOREisenstat(mat, bb, omega, fshift, lits, xx));
    mat->factorerrortype = b->A->factorerrortype;
    PetscFunctionReturn(0);
  }
  PetscCheck(
    !(flag & ~(SOR_LOCAL_SYMMETRIC_SWEEP | SOR_ZERO_INITIAL_GUESS)), PetscObjectComm((PetscObject)mat),
    PETSC_ERR_SUP,
    "MATMPIBINBCSR's MatSOR does processor-local sweeps (SOR_LOCAL_FORWARD/BACKWARD/SYMMETRIC_SWEEP, e.g. -pc_sor_local_symmetric; PCSOR's default symmetric sweep is local in parallel), SOR_EISENSTAT and SOR_APPLY_UPPER");
  PetscCheck(local, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONG,
             "MatSOR: the flag %d asks for no sweep", (int)flag);
  PetscCheck(its > 0 && lits > 0, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONG,
             "MatSOR: its (%" PetscInt_FMT ") and lits (%" PetscInt_FMT ") must be positive", its, lits);
  if (flag & SOR_ZERO_INITIAL_GUESS) { /* x = 0: the ghosts contribute nothing to the first sweep */
    PetscUseTypeMethod(b->A, sor, bb, omega, (MatSORType)(local | SOR_ZERO_INITIAL_GUESS), fshift, lits, 1,
                       xx);
    its--;
  }
  if (its > 0) PetscCall(VecDuplicate(bb, &bb1));
  while (its-- > 0) {
    PetscCall(VecScatterBegin(b->Mvctx, xx, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(b->Mvctx, xx, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
    if (ghosts) { /* bb1 = bb - B x_ghost */
      PetscCall(VecScale(b->lvec, -1.0));
      PetscUseTypeMethod(b->B, multadd, b->lvec, bb, bb1);
    } else PetscCall(VecCopy(bb, bb1));
    PetscUseTypeMethod(b->A, sor, bb1, omega, local, fshift, lits, 1, xx);
  }
  PetscCall(VecDestroy(&bb1));
  PetscFunctionReturn(0);
}

/* y = D x with D the diagonal part's block diagonal (PCEISENSTAT's diagonal scaling). */
PETSC_INTERN PetscErrorCode MatMultDiagonalBlock_MPIBinBCSR(Mat mat, Vec xx, Vec yy)
{
  PetscFunctionBegin;
  PetscCall(MatMultDiagonalBlock(MPIBinBCSR(mat)->A, xx, yy));
  PetscFunctionReturn(0);
}
