/* MatGetRowIJ for MATMPIBINBCSR, as MPIAIJ answers it: the compressed-row structure of this rank's rows
   with global column numbers (MPIAIJ hands out that of MatMPIAIJGetLocalMat). It is built from the
   merged rows (MatGetRow: symmetric storage gives whole rows) into a seqaij m x N matrix composed on the
   matrix until MatRestoreRowIJ, whose own MatGetRowIJ answers every option (shift, symmetric,
   inode-compressed) as for MPIAIJ's local matrix. Local work only: callers need not be collective. */
#include "mpibinbcsr.h"

#include <vector>

static const char rowij_key[] = "MatGetRowIJ_MPIBinBCSR";

PetscErrorCode MatGetRowIJ_MPIBinBCSR(Mat A, PetscInt shift, PetscBool symmetric, PetscBool inodecompressed,
                                      PetscInt *m, const PetscInt *ia[], const PetscInt *ja[],
                                      PetscBool *done)
{
  const PetscInt        rstart = A->rmap->rstart, n = A->rmap->n;
  std::vector<PetscInt> ii(n + 1, 0), jj;
  Mat                   L;

  PetscFunctionBegin;
  PetscCheck(A->assembled, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatGetRowIJ needs an assembled matrix");
  for (PetscInt r = 0; r < n; r++) {
    PetscInt        nz;
    const PetscInt *cols;
    PetscCall(MatGetRow(A, rstart + r, &nz, &cols, nullptr));
    jj.insert(jj.end(), cols, cols + nz);
    PetscCall(MatRestoreRow(A, rstart + r, &nz, &cols, nullptr));
    ii[r + 1] = (PetscInt)jj.size();
  }
  PetscCall(MatCreate(PETSC_COMM_SELF, &L));
  PetscCall(MatSetSizes(L, n, A->cmap->N, n, A->cmap->N));
  PetscCall(MatSetType(L, MATSEQAIJ));
  PetscCall(MatSeqAIJSetPreallocationCSR(L, ii.data(), jj.data(), nullptr));
  PetscCall(PetscObjectCompose((PetscObject)A, rowij_key, (PetscObject)L));
  PetscCall(MatGetRowIJ(L, shift, symmetric, inodecompressed, m, ia, ja, done));
  PetscCall(MatDestroy(&L));
  PetscFunctionReturn(0);
}

PetscErrorCode MatRestoreRowIJ_MPIBinBCSR(Mat A, PetscInt shift, PetscBool symmetric,
                                          PetscBool inodecompressed, PetscInt *m, const PetscInt *ia[],
                                          const PetscInt *ja[], PetscBool *done)
{
  Mat L;

  PetscFunctionBegin;
  PetscCall(PetscObjectQuery((PetscObject)A, rowij_key, (PetscObject *)&L));
  PetscCheck(L, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatRestoreRowIJ without a MatGetRowIJ");
  PetscCall(MatRestoreRowIJ(L, shift, symmetric, inodecompressed, m, ia, ja, done));
  PetscCall(PetscObjectCompose((PetscObject)A, rowij_key, nullptr));
  PetscFunctionReturn(0);
}
