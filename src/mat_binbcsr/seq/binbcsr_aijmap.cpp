/* Value maps between a MATSEQBINBCSR matrix and a seqaij matrix over the same point pattern, so that
   values move by one gather or scatter instead of MatSetValues row by row: the AIJ shadow's refill
   (binbcsr -> seqaij) and the refill of submatrices extracted from it (seqaij -> binbcsr) on every
   MAT_REUSE_MATRIX (binbcsr_submat.cpp). Built once per pattern. */
#include "binbcsr.h"

/* For each stored entry p of T (CSR order): the value index in B of the same (row, column); under
   symmetric storage an entry below the block diagonal reads its transposed place, coded -2 - index;
   -1 where B has no such entry. */
PetscErrorCode MatSeqBinBCSRAIJValueMap(Mat B, Mat T, std::vector<PetscInt> &map)
{
  Mat_SeqBinBCSR *b  = (Mat_SeqBinBCSR *)B->data;
  const PetscInt  bs = b->bs, bs2 = b->bs2, bw = b->bw;
  const PetscInt *ia, *ja;
  PetscInt        n;
  PetscBool       done;

  PetscFunctionBegin;
  PetscCheck(b->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "Value map of an unassembled MATSEQBINBCSR matrix");
  PetscCall(MatGetRowIJ(T, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  PetscCheck(done && n == B->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Value map: %" PetscInt_FMT " rows against %" PetscInt_FMT, n, B->rmap->n);
  map.resize(ia[n]);
  for (PetscInt r = 0; r < n; r++) {
    const PetscInt br = r / bs, i = r % bs;
    for (PetscInt p = ia[r]; p < ia[r + 1]; p++) {
      const PetscInt bc = ja[p] / bs, j = ja[p] % bs;
      if (b->sym && bc < br) {
        const PetscInt s = MatSeqBinBCSRFindSlot(b, bc, br);
        map[p]           = s < 0 ? -1 : -2 - BinBCSRValueIndex(s, j * bs + i, bw, bs2);
      } else {
        const PetscInt s = MatSeqBinBCSRFindSlot(b, br, bc);
        map[p]           = s < 0 ? -1 : BinBCSRValueIndex(s, i * bs + j, bw, bs2);
      }
    }
  }
  PetscCall(MatRestoreRowIJ(T, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  PetscFunctionReturn(0);
}

/* T's values from B (entries B does not store become 0). */
PetscErrorCode MatSeqBinBCSRAIJGather(Mat B, const std::vector<PetscInt> &map, Mat T)
{
  const Mat_SeqBinBCSR *b = (const Mat_SeqBinBCSR *)B->data;
  PetscScalar          *t;

  PetscFunctionBegin;
  PetscCall(MatSeqAIJGetArrayWrite(T, &t));
  const PetscInt n = (PetscInt)map.size();
  for (PetscInt p = 0; p < n; p++) {
    const PetscInt v = map[p];
    t[p]             = v == -1 ? 0.0 : BinBCSRGetValue(b, v >= 0 ? v : -2 - v);
  }
  PetscCall(MatSeqAIJRestoreArrayWrite(T, &t));
  PetscCall(PetscObjectStateIncrease((PetscObject)T));
  PetscFunctionReturn(0);
}

/* B's values from T: every value of B zeroed, then T's entries that B stores (not the transposed
   ones of symmetric storage) written. */
PetscErrorCode MatSeqBinBCSRAIJScatter(Mat T, const std::vector<PetscInt> &map, Mat B)
{
  Mat_SeqBinBCSR    *b = (Mat_SeqBinBCSR *)B->data;
  const PetscScalar *t;

  PetscFunctionBegin;
  PetscCall(MatZeroEntries(B));
  PetscCall(MatSeqAIJGetArrayRead(T, &t));
  const PetscInt n = (PetscInt)map.size();
  for (PetscInt p = 0; p < n; p++)
    if (map[p] >= 0) BinBCSRSetValue(b, map[p], t[p]);
  PetscCall(MatSeqAIJRestoreArrayRead(T, &t));
  PetscCall(PetscObjectStateIncrease((PetscObject)B));
  PetscFunctionReturn(0);
}
