/* MatSOR for MATMPIBINBCSR: processor-local sweeps (SOR_LOCAL_FORWARD/BACKWARD/SYMMETRIC_SWEEP), as
   PETSc's MPIAIJ offers: each outer iteration exchanges the ghost values once, moves the off-rank
   coupling to the right-hand side (b - B x_ghost) and sweeps the diagonal part. A global sweep in row
   order would serialise the ranks, so it is refused, as by MPIAIJ. */
#include "mpibinbcsr.h"

PETSC_INTERN PetscErrorCode MatSOR_MPIBinBCSR(Mat mat, Vec bb, PetscReal omega, MatSORType flag, PetscReal fshift, PetscInt its, PetscInt lits, Vec xx)
{
  Mat_MPIBinBCSR  *b     = MPIBinBCSR(mat);
  const MatSORType local = (MatSORType)(flag & SOR_LOCAL_SYMMETRIC_SWEEP);
  const PetscBool  ghosts = (PetscBool)!b->garray.empty();
  Vec              bb1    = nullptr;

  PetscFunctionBegin;
  PetscCheck(!(flag & ~(SOR_LOCAL_SYMMETRIC_SWEEP | SOR_ZERO_INITIAL_GUESS)), PetscObjectComm((PetscObject)mat), PETSC_ERR_SUP, "MATMPIBINBCSR's MatSOR does processor-local sweeps only (SOR_LOCAL_FORWARD/BACKWARD/SYMMETRIC_SWEEP, e.g. -pc_sor_local_symmetric; PCSOR's default symmetric sweep is local in parallel)");
  PetscCheck(local, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONG, "MatSOR: the flag %d asks for no sweep", (int)flag);
  PetscCheck(its > 0 && lits > 0, PetscObjectComm((PetscObject)mat), PETSC_ERR_ARG_WRONG, "MatSOR: its (%" PetscInt_FMT ") and lits (%" PetscInt_FMT ") must be positive", its, lits);
  if (flag & SOR_ZERO_INITIAL_GUESS) { /* x = 0: the ghosts contribute nothing to the first sweep */
    PetscUseTypeMethod(b->A, sor, bb, omega, (MatSORType)(local | SOR_ZERO_INITIAL_GUESS), fshift, lits, 1, xx);
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
