/* MatIsSymmetric for seq and mpi binbcsr. Symmetric storage is symmetric by construction. Otherwise the
   transpose (MatTranspose of the type: a new layout, or the MPI exchange) is compared row by row with
   the matrix: symmetric when |a_ij - a_ji| <= tol everywhere, an entry one side lacks counting as zero
   (aij also asks for the same pattern; the simulation matrices have symmetric patterns). */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

#include <cmath>
#include <map>

PETSC_INTERN PetscErrorCode MatIsSymmetric_BinBCSR(Mat A, PetscReal tol, PetscBool *flg)
{
  PetscBool sym, local = PETSC_TRUE;
  Mat       T;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym));
  if (sym) {
    *flg = PETSC_TRUE;
    PetscFunctionReturn(0);
  }
  if (A->rmap->N != A->cmap->N || A->rmap->n != A->cmap->n) {
    *flg = PETSC_FALSE;
    PetscFunctionReturn(0);
  }
  PetscCall(MatTranspose(A, MAT_INITIAL_MATRIX, &T));
  std::map<PetscInt, PetscScalar> diff;
  for (PetscInt r = A->rmap->rstart; r < A->rmap->rend && local; r++) {
    PetscInt           n;
    const PetscInt    *cols;
    const PetscScalar *vals;
    diff.clear();
    PetscCall(MatGetRow(A, r, &n, &cols, &vals));
    for (PetscInt k = 0; k < n; k++) diff[cols[k]] += vals[k];
    PetscCall(MatRestoreRow(A, r, &n, &cols, &vals));
    PetscCall(MatGetRow(T, r, &n, &cols, &vals));
    for (PetscInt k = 0; k < n; k++) diff[cols[k]] -= vals[k];
    PetscCall(MatRestoreRow(T, r, &n, &cols, &vals));
    for (const auto &d : diff)
      if (!(PetscAbsScalar(d.second) <= tol)) local = PETSC_FALSE; /* NaN is not symmetric */
  }
  PetscCall(MatDestroy(&T));
  PetscCall(MPIU_Allreduce(&local, flg, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)A)));
  PetscFunctionReturn(0);
}
