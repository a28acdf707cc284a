/* MatGetRowIJ for MATSEQBINBCSR: the compressed-row structure that partitioners and orderings read
   (PCASMCreateSubdomains partitions the diagonal block with it when asked for several blocks per
   rank). The bin layout has no CSR arrays to hand out, so they are made from a temporary seqaij
   (point rows) or seqbaij (block rows, when asked for a block-compressed structure) copy, copied
   into arrays of our own and freed by MatRestoreRowIJ. Set-up time only: one conversion per call. */
#include "binbcsr.h"

PetscErrorCode MatGetRowIJ_SeqBinBCSR(Mat A, PetscInt shift, PetscBool symmetric, PetscBool blockcompressed,
                                      PetscInt *n, const PetscInt *ia[], const PetscInt *ja[],
                                      PetscBool *done)
{
  const PetscBool blocked = (blockcompressed && A->rmap->bs > 1) ? PETSC_TRUE : PETSC_FALSE;
  Mat             T;
  PetscInt        tn, *cia, *cja;
  const PetscInt *tia, *tja;
  PetscBool       tdone;

  PetscFunctionBegin;
  *n    = blocked ? A->rmap->n / A->rmap->bs : A->rmap->n;
  *done = PETSC_TRUE;
  if (!ia) PetscFunctionReturn(0);
  PetscCall(MatConvert(A, blocked ? MATSEQBAIJ : MATSEQAIJ, MAT_INITIAL_MATRIX, &T));
  PetscCall(MatGetRowIJ(T, shift, symmetric, blocked, &tn, &tia, &tja, &tdone));
  PetscCheck(tdone && tn == *n, PETSC_COMM_SELF, PETSC_ERR_PLIB, "MatGetRowIJ of the %s copy failed",
             blocked ? MATSEQBAIJ : MATSEQAIJ);
  const PetscInt nnz = tia[tn] - shift;
  PetscCall(PetscMalloc1(tn + 1, &cia));
  PetscCall(PetscMalloc1(nnz, &cja));
  PetscCall(PetscArraycpy(cia, tia, tn + 1));
  PetscCall(PetscArraycpy(cja, tja, nnz));
  PetscCall(MatRestoreRowIJ(T, shift, symmetric, blocked, &tn, &tia, &tja, &tdone));
  PetscCall(MatDestroy(&T));
  *ia = cia;
  if (ja) *ja = cja;
  else PetscCall(PetscFree(cja));
  PetscFunctionReturn(0);
}

PetscErrorCode MatRestoreRowIJ_SeqBinBCSR(Mat A, PetscInt shift, PetscBool symmetric,
                                          PetscBool blockcompressed, PetscInt *n, const PetscInt *ia[],
                                          const PetscInt *ja[], PetscBool *done)
{
  PetscFunctionBegin;
  (void)A;
  (void)shift;
  (void)symmetric;
  (void)blockcompressed;
  (void)n;
  if (ia) PetscCall(PetscFree(*ia));
  if (ja) PetscCall(PetscFree(*ja));
  if (done) *done = PETSC_TRUE;
  PetscFunctionReturn(0);
}
