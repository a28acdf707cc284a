/* MatPermute for seq and mpi binbcsr: B(i, j) = A(row[i], col[j]) (PETSc's convention: the index sets
   map rows/columns of B to those of A), built as a new matrix of A's type and configuration (bin width,
   precision, storage; the MPI inner type) by sending each local row of A, renumbered, to its new
   owner. A permutation that splits blocks is allowed: the blocks it touches are stored whole, with
   zeros. Symmetric storage stays symmetric only under the same permutation on both sides; anything
   else is refused. */
#include "mpi/mpibinbcsr.h"
#include <petsc/private/matimpl.h>
#include <petscis.h>

#include <vector>

PETSC_INTERN PetscErrorCode MatPermute_BinBCSR(Mat A, IS rowp, IS colp, Mat *B)
{
  MPI_Comm        comm = PetscObjectComm((PetscObject)A);
  PetscMPIInt     size;
  PetscBool       mpi, sym;
  IS              irow, call, icol;
  const PetscInt *inew_row, *inew_col;
  Mat             C;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym));
  if (sym) {
    PetscBool same = rowp == colp ? PETSC_TRUE : PETSC_FALSE;
    if (!same) PetscCall(ISEqualUnsorted(rowp, colp, &same)); /* ISEqual compares sets: every permutation would pass */
    PetscCheck(same, comm, PETSC_ERR_SUP, "MatPermute with symmetric storage (-mat_binbcsr_symmetric_storage) needs the same row and column permutation: P A Q^T is not symmetric");
  }
  /* new row of each local row of A; new column of every column */
  PetscCall(ISInvertPermutation(rowp, A->rmap->n, &irow));
  if (size > 1) PetscCall(ISAllGather(colp, &call));
  else {
    PetscCall(PetscObjectReference((PetscObject)colp));
    call = colp;
  }
  PetscCall(ISInvertPermutation(call, PETSC_DECIDE, &icol));
  PetscCall(ISGetIndices(irow, &inew_row));
  PetscCall(ISGetIndices(icol, &inew_col));

  PetscCall(MatCreate(comm, &C));
  PetscCall(MatSetSizes(C, A->rmap->n, A->cmap->n, A->rmap->N, A->cmap->N));
  PetscCall(MatSetBlockSizesFromMats(C, A, A));
  PetscCall(MatSetType(C, ((PetscObject)A)->type_name));
  if (mpi) PetscCall(MatMPIBinBCSRCopyConfig(A, C));
  else {
    PetscInt            bw;
    MatBinBCSRPrecision prec;
    PetscCall(MatBinBCSRGetBinWidth(A, &bw));
    PetscCall(MatBinBCSRGetPrecision(A, &prec));
    PetscCall(MatBinBCSRSetBinWidth(C, bw));
    PetscCall(MatBinBCSRSetPrecision(C, prec));
    PetscCall(MatBinBCSRSetSymmetricStorage(C, sym));
  }
  PetscCall(MatSetUp(C));
  std::vector<PetscInt> cols_new;
  for (PetscInt r = A->rmap->rstart; r < A->rmap->rend; r++) {
    PetscInt           nz;
    const PetscInt    *cols;
    const PetscScalar *vals;
    const PetscInt     rnew = inew_row[r - A->rmap->rstart];
    PetscCall(MatGetRow(A, r, &nz, &cols, &vals));
    cols_new.resize(nz);
    for (PetscInt k = 0; k < nz; k++) cols_new[k] = inew_col[cols[k]];
    PetscCall(MatSetValues(C, 1, &rnew, nz, cols_new.data(), vals, INSERT_VALUES));
    PetscCall(MatRestoreRow(A, r, &nz, &cols, &vals));
  }
  PetscCall(MatAssemblyBegin(C, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(C, MAT_FINAL_ASSEMBLY));
  PetscCall(ISRestoreIndices(irow, &inew_row));
  PetscCall(ISRestoreIndices(icol, &inew_col));
  PetscCall(ISDestroy(&irow));
  PetscCall(ISDestroy(&icol));
  PetscCall(ISDestroy(&call));
  if (rowp == colp) PetscCall(MatPropagateSymmetryOptions(A, C));
  *B = C;
  PetscFunctionReturn(0);
}
