/* Matrices of a binbcsr matrix's type and configuration with another pattern, seq and mpi: the empty
   one that MatPermute, MatTranspose, MatAXPY fill.

   MatPermute for seq and mpi binbcsr: B(i, j) = A(row[i], col[j]) (PETSc's convention: the index sets
   map rows/columns of B to those of A), built as a new matrix of A's type and configuration (bin width,
   precision, storage; the MPI inner type) by sending each local row of A, renumbered, to its new
   owner. A permutation that splits blocks is allowed: the blocks it touches are stored whole, with
   zeros. Symmetric storage stays symmetric only under the same permutation on both sides; anything
   else is refused. */
#include "../mpi/mpibinbcsr.h"
#include <petsc/private/matimpl.h>
#include <petscis.h>

#include <vector>

PetscErrorCode MatBinBCSRCreateEmptyLike_Private(Mat A, PetscInt m, PetscInt n, PetscInt rbs, PetscInt cbs,
                                                 Mat *C)
{
  PetscBool mpi;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  PetscCall(MatCreate(PetscObjectComm((PetscObject)A), C));
  PetscCall(MatSetSizes(*C, m, n, PETSC_DETERMINE, PETSC_DETERMINE));
  PetscCall(MatSetBlockSizes(*C, rbs, cbs));
  PetscCall(MatSetType(*C, ((PetscObject)A)->type_name));
  if (mpi) PetscCall(MatMPIBinBCSRCopyConfig(A, *C));
  else {
    PetscInt            bw;
    MatBinBCSRPrecision prec;
    PetscBool           sym;
    PetscCall(MatBinBCSRGetBinWidth(A, &bw));
    PetscCall(MatBinBCSRGetPrecision(A, &prec));
    PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym));
    PetscCall(MatBinBCSRSetBinWidth(*C, bw));
    PetscCall(MatBinBCSRSetPrecision(*C, prec));
    PetscCall(MatBinBCSRSetSymmetricStorage(*C, sym));
  }
  PetscCall(MatSetUp(*C));
  PetscFunctionReturn(0);
}

/* Composed as "MatAXPYGetPreallocation_C": PETSc's MatAXPY_Basic (X of another type, a pattern not
   contained in Y's) fills the matrix this returns and puts it in Y's place; without it the result
   would be a binbcsr matrix with the default bin width, precision and storage. */
PetscErrorCode MatAXPYGetPreallocation_BinBCSR(Mat Y, Mat X, Mat *B)
{
  PetscFunctionBegin;
  (void)X;
  PetscCall(MatBinBCSRCreateEmptyLike_Private(Y, Y->rmap->n, Y->cmap->n, Y->rmap->bs, Y->cmap->bs, B));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatPermute_BinBCSR(Mat A, IS rowp, IS colp, Mat *B)
{
  MPI_Comm        comm = PetscObjectComm((PetscObject)A);
  PetscMPIInt     size;
  PetscBool       sym;
  IS              irow, call, icol;
  const PetscInt *inew_row, *inew_col;
  Mat             C;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym));
  if (sym) {
    PetscBool same = rowp == colp ? PETSC_TRUE : PETSC_FALSE;
    if (!same)
      PetscCall(ISEqualUnsorted(rowp, colp, &same)); /* ISEqual compares sets: every permutation would pass */
    PetscCheck(
      same, comm, PETSC_ERR_SUP,
      "MatPermute with symmetric storage (-mat_binbcsr_symmetric_storage) needs the same row and column permutation: P A Q^T is not symmetric");
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

  PetscCall(MatBinBCSRCreateEmptyLike_Private(A, A->rmap->n, A->cmap->n, A->rmap->bs, A->cmap->bs, &C));
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
