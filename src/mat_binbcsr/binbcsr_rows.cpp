/* Row-by-row copy shared by the seq and mpi conversions: the path for any source that has
   MatGetRow but no faster route into the destination's storage. */
#include "binbcsr_impl.h"

PetscErrorCode MatBinBCSRInsertRows_Private(Mat src, Mat dst)
{
  PetscInt rstart, rend;

  PetscFunctionBegin;
  PetscCall(MatGetOwnershipRange(src, &rstart, &rend));
  for (PetscInt r = rstart; r < rend; r++) {
    PetscInt           nz;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(src, r, &nz, &cols, &vals));
    PetscCall(MatSetValues(dst, 1, &r, nz, cols, vals, INSERT_VALUES));
    PetscCall(MatRestoreRow(src, r, &nz, &cols, &vals));
  }
  PetscCall(MatAssemblyBegin(dst, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(dst, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}
