/* Row-by-row copy shared by the seq and mpi conversions: the path for any source that has
   MatGetRow but no faster route into the destination's storage. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

#include <vector>

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

/* Preallocates dst (any AIJ-answering type, already sized and typed) exactly from src's rows and
   copies them. */
PetscErrorCode MatBinBCSRPreallocateAndFill_Private(Mat src, Mat dst)
{
  PetscInt  rstart, rend;
  PetscBool issbaij;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)src, &issbaij, MATSEQSBAIJ, MATMPISBAIJ, ""));
  PetscCheck(!issbaij, PetscObjectComm((PetscObject)src), PETSC_ERR_SUP,
             "Cannot convert from SBAIJ: its rows hold only the upper triangle");
  PetscCall(PetscLayoutSetUp(dst->rmap));
  PetscCall(PetscLayoutSetUp(dst->cmap));
  PetscCall(MatGetOwnershipRange(src, &rstart, &rend));
  const PetscInt        cstart = dst->cmap->rstart, cend = dst->cmap->rend;
  std::vector<PetscInt> dnnz(rend - rstart, 0), onnz(rend - rstart, 0);
  for (PetscInt r = rstart; r < rend; r++) {
    PetscInt        nz;
    const PetscInt *cols;
    PetscCall(MatGetRow(src, r, &nz, &cols, nullptr));
    for (PetscInt k = 0; k < nz; k++) (cols[k] >= cstart && cols[k] < cend ? dnnz : onnz)[r - rstart]++;
    PetscCall(MatRestoreRow(src, r, &nz, &cols, nullptr));
  }
  PetscCall(MatSeqAIJSetPreallocation(dst, 0, dnnz.data()));
  PetscCall(MatMPIAIJSetPreallocation(dst, 0, dnnz.data(), 0, onnz.data()));
  PetscCall(MatBinBCSRInsertRows_Private(src, dst));
  PetscFunctionReturn(0);
}
