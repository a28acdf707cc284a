/* KSPMCG's own point-block Jacobi: the inverses of the 3x3 diagonal blocks, for the fused vector pass.

   They come from MatInvertBlockDiagonal() (binbcsr reads each diagonal block from the slot it keeps
   for it, whole or symmetric storage, double or single values; aij and baij have their own), and are
   copied so that the pass reads one contiguous array the matrix cannot move. Rebuilt when the
   preconditioning matrix or its values change (a refill bumps the state), except when the PC is told
   to reuse its preconditioner. A singular block is an error naming its block row: PCPBJACOBI would
   apply garbage there. */
#include "mcg_impl.h"
#include <petsc/private/kernels/blockinvert.h>

/* The first (global) block row whose diagonal block the 3x3 inversion kernel finds singular (-1: none).
   Only called after an inversion failed, so it may read the blocks one by one with MatGetValues: the
   matrix types do not all say which row failed, and each says it in its own way. Collective. */
static PetscErrorCode MCGFirstSingularBlock(Mat P, PetscInt *row)
{
  PetscInt rstart, rend, first = PETSC_MAX_INT;

  PetscFunctionBegin;
  PetscCall(MatGetOwnershipRange(P, &rstart, &rend));
  for (PetscInt r = rstart / 3; r < rend / 3 && first == PETSC_MAX_INT; r++) {
    const PetscInt idx[3] = {3 * r, 3 * r + 1, 3 * r + 2};
    MatScalar      v[9];
    PetscScalar    d[9];
    PetscBool      zp = PETSC_FALSE;
    PetscCall(MatGetValues(P, 3, idx, 3, idx, v));
    for (int k = 0; k < 9; k++) d[k] = v[k];
    PetscCall(PetscKernel_A_gets_inverse_A_3(d, 0.0, PETSC_TRUE, &zp));
    for (int k = 0; !zp && k < 9; k++) zp = PetscIsInfOrNanScalar(d[k]) ? PETSC_TRUE : PETSC_FALSE;
    if (zp) first = r;
  }
  PetscCall(MPIU_Allreduce(&first, row, 1, MPIU_INT, MPI_MIN, PetscObjectComm((PetscObject)P)));
  if (*row == PETSC_MAX_INT) *row = -1;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MCGUpdateBlockDiagonal(KSP ksp)
{
  KSP_MCG           *mcg = (KSP_MCG *)ksp->data;
  Mat                Pmat;
  PetscObjectId      id;
  PetscObjectState   state;
  PetscBool          stale;
  PetscInt           n, nb, bad, bad_all;
  MatFactorError     err;
  const PetscScalar *inv;

  PetscFunctionBegin;
  PetscCall(MCGPreconditionerStale(ksp, (PetscBool) !!mcg->binv, mcg->binv_id, mcg->binv_state, &Pmat, &id,
                                   &state, &stale));
  PetscCall(MatGetLocalSize(Pmat, &n, nullptr));
  nb = n / 3;
  if (!stale && mcg->binv_n == nb) PetscFunctionReturn(0);
  if (mcg->binv_n != nb) {
    PetscCall(PetscFree(mcg->binv));
    mcg->binv_n = 0;
  }
  if (!mcg->binv) {
    PetscCall(PetscMalloc1(9 * (size_t)nb + 1, &mcg->binv));
    mcg->binv_n = nb;
  }
  PetscCall(MatFactorClearError(Pmat));
  PetscCall(MatInvertBlockDiagonal(Pmat, &inv));
  PetscCall(MatFactorGetError(Pmat, &err));
  bad = err == MAT_FACTOR_NUMERIC_ZEROPIVOT ? 1 : 0;
  for (PetscInt k = 0; !bad && k < 9 * nb; k++)
    if (PetscIsInfOrNanScalar(inv[k])) bad = 1;
  PetscCall(MPIU_Allreduce(&bad, &bad_all, 1, MPIU_INT, MPI_MAX, PetscObjectComm((PetscObject)ksp)));
  PetscCall(MatFactorClearError(Pmat));
  if (bad_all) {
    PetscInt row;
    PetscCall(MCGFirstSingularBlock(Pmat, &row));
    SETERRQ(
      PetscObjectComm((PetscObject)ksp), PETSC_ERR_MAT_LU_ZRPVT,
      "KSPMCG point-block Jacobi (-pc_type pbjacobi): the 3x3 diagonal block of block row %" PetscInt_FMT
      " (rows %" PetscInt_FMT "..%" PetscInt_FMT ") is singular",
      row, 3 * row, 3 * row + 2);
  }
  PetscCall(PetscArraycpy(mcg->binv, inv, 9 * (size_t)nb));
  mcg->binv_id    = id;
  mcg->binv_state = state;
  PetscFunctionReturn(0);
}
