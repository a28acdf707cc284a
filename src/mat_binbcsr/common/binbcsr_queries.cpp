/* Whole-matrix questions for seq and mpi binbcsr: MatFindZeroDiagonals (what
   -pc_fieldsplit_detect_saddle_point asks), MatFindNonzeroRows and MatIsSymmetric.

   MatFindZeroDiagonals: the rows whose diagonal entry is zero or not stored, from MatGetDiagonal (the
   stored diagonal slots), as global rows of this rank.

   MatFindNonzeroRows: the rows with a nonzero value, from MatGetRowMaxAbs (exact, where PETSc's generic
   path multiplies by a random vector), the rows it finds zero looked at again for NaN (which the
   maximum skips and aij counts as nonzero), with aij's conventions: NULL when no row is zero (on any
   rank), global rows of this rank otherwise (a stored zero does not make a row nonzero).

   MatIsSymmetric: Symmetric storage is symmetric by construction. Otherwise the
   transpose (MatTranspose of the type: a new layout, or the MPI exchange) is compared row by row with
   the matrix: symmetric when |a_ij - a_ji| <= tol everywhere, an entry one side lacks counting as zero
   (aij also asks for the same pattern; the simulation matrices have symmetric patterns). */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

#include <cmath>
#include <map>
#include <vector>

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

PETSC_INTERN PetscErrorCode MatFindZeroDiagonals_BinBCSR(Mat A, IS *zrows)
{
  Vec                   d;
  const PetscScalar    *da;
  std::vector<PetscInt> rows;

  PetscFunctionBegin;
  PetscCall(MatCreateVecs(A, nullptr, &d));
  PetscCall(MatGetDiagonal(A, d));
  PetscCall(VecGetArrayRead(d, &da));
  for (PetscInt i = 0; i < A->rmap->n; i++)
    if (da[i] == 0.0) rows.push_back(A->rmap->rstart + i);
  PetscCall(VecRestoreArrayRead(d, &da));
  PetscCall(VecDestroy(&d));
  PetscCall(ISCreateGeneral(PetscObjectComm((PetscObject)A), (PetscInt)rows.size(), rows.data(),
                            PETSC_COPY_VALUES, zrows));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatFindNonzeroRows_BinBCSR(Mat A, IS *keptrows)
{
  Vec                   m;
  const PetscScalar    *ma;
  std::vector<PetscInt> rows;
  PetscInt              nzero, gzero;

  PetscFunctionBegin;
  PetscCall(MatCreateVecs(A, nullptr, &m));
  PetscCall(MatGetRowMaxAbs(A, m, nullptr));
  PetscCall(VecGetArrayRead(m, &ma));
  for (PetscInt i = 0; i < A->rmap->n; i++) {
    PetscBool nonzero = ma[i] != 0.0 ? PETSC_TRUE : PETSC_FALSE;
    if (!nonzero) { /* the maximum skips NaN; aij counts it (NaN != 0): look at the (few) rows left */
      PetscInt           n;
      const PetscScalar *v;
      PetscCall(MatGetRow(A, A->rmap->rstart + i, &n, nullptr, &v));
      for (PetscInt k = 0; k < n && !nonzero; k++) nonzero = v[k] != 0.0 ? PETSC_TRUE : PETSC_FALSE;
      PetscCall(MatRestoreRow(A, A->rmap->rstart + i, &n, nullptr, &v));
    }
    if (nonzero) rows.push_back(A->rmap->rstart + i);
  }
  PetscCall(VecRestoreArrayRead(m, &ma));
  PetscCall(VecDestroy(&m));
  nzero = A->rmap->n - (PetscInt)rows.size();
  PetscCall(MPIU_Allreduce(&nzero, &gzero, 1, MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)A)));
  *keptrows = nullptr;
  if (gzero)
    PetscCall(ISCreateGeneral(PetscObjectComm((PetscObject)A), (PetscInt)rows.size(), rows.data(),
                              PETSC_COPY_VALUES, keptrows));
  PetscFunctionReturn(0);
}
