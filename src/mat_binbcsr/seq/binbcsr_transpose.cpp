/*
   MATSEQBINBCSR transpose. The matrices this format is for are symmetric, so MatTranspose mostly
   serves generic code (PETSc's tests, MatAXPY with a transposed operand): it builds the transposed
   block pattern, a new bin layout for it (same bin width and precision), and moves every block,
   transposed, into its slot.
*/
#include "binbcsr_ops.h"

#include <vector>

PetscErrorCode MatTranspose_SeqBinBCSR(Mat A, MatReuse reuse, Mat *B)
{
  Mat_SeqBinBCSR       *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt        bs = a->bs, bs2 = a->bs2;
  std::vector<PetscInt> bi(a->nbs + 1, 0), bj(a->nz), fill;
  Mat                   C;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatTranspose needs an assembled MATSEQBINBCSR matrix");
  if (a->sym) { /* symmetric storage: A^T = A */
    if (reuse == MAT_INITIAL_MATRIX) PetscCall(MatDuplicate(A, MAT_COPY_VALUES, B));
    else if (reuse == MAT_REUSE_MATRIX && *B != A) PetscCall(MatCopy(A, *B, SAME_NONZERO_PATTERN));
    PetscFunctionReturn(0);
  }
  /* transposed pattern: block row c of A^T lists the block rows r of A holding column c, in order */
  for (PetscInt r = 0; r < a->mbs; r++)
    for (PetscInt k = 0; k < a->row_nz[r]; k++) bi[a->col[BinBCSRSlot(a, r, k)] + 1]++;
  for (PetscInt c = 0; c < a->nbs; c++) bi[c + 1] += bi[c];
  fill.assign(bi.begin(), bi.end() - 1);
  for (PetscInt r = 0; r < a->mbs; r++)
    for (PetscInt k = 0; k < a->row_nz[r]; k++) bj[fill[a->col[BinBCSRSlot(a, r, k)]]++] = r;

  PetscCall(MatSeqBinBCSRCreateWithPattern(A, PETSC_TRUE, bi.data(), bj.data(), &C));
  {
    Mat_SeqBinBCSR *c = (Mat_SeqBinBCSR *)C->data;
    for (PetscInt r = 0; r < a->mbs; r++)
      for (PetscInt k = 0; k < a->row_nz[r]; k++) {
        const PetscInt s = BinBCSRSlot(a, r, k), st = MatSeqBinBCSRFindSlot(c, a->col[s], r);
        for (PetscInt i = 0; i < bs; i++)
          for (PetscInt j = 0; j < bs; j++)
            BinBCSRSetValue(c, BinBCSRValueIndex(st, j * bs + i, c->bw, bs2),
                            BinBCSRGetValue(a, BinBCSRValueIndex(s, i * bs + j, a->bw, bs2)));
      }
  }
  PetscCall(MatAssemblyBegin(C, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(C, MAT_FINAL_ASSEMBLY));

  if (reuse == MAT_INITIAL_MATRIX) {
    *B = C;
  } else if (reuse == MAT_INPLACE_MATRIX || *B == A) {
    PetscCall(MatHeaderReplace(A, &C));
  } else {
    /* MAT_REUSE_MATRIX: values into the caller's matrix, which keeps its identity (and what PETSc
       composed on it to recognise it as this transpose) */
    PetscCall(MatCopy(C, *B, SAME_NONZERO_PATTERN));
    PetscCall(MatDestroy(&C));
  }
  PetscFunctionReturn(0);
}
