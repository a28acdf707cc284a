/*
   MATSEQBINBCSR and PETSc binary files. The file holds a scalar CSR matrix (header: class id, rows,
   columns, nonzeros; then row lengths, column indices, values), the format every PETSc matrix type
   reads and writes, so files round-trip with seqaij and seqbaij. The block size comes from
   MatSetBlockSize before the load or from -matload_block_size (also found in the file's .info); a
   block row stores the union of its point rows' block columns as full blocks. The reading and its
   checks are binbcsr_load.cpp's, shared with the parallel loader.
*/
#include "binbcsr_ops.h"
#include "../common/binbcsr_load.h"

#include <algorithm>
#include <vector>

namespace {

PetscErrorCode ViewBinary(Mat A, PetscViewer viewer)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bs = a->bs, m = A->rmap->n;
  PetscInt        header[4], *rowlens, *cols, nz, cnt = 0;
  PetscScalar    *vals;
  FILE           *info;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatView to a binary file needs an assembled matrix");
  if (a->sym) { /* both triangles, as seqaij writes them */
    Mat B;
    PetscCall(MatConvert(A, MATSEQAIJ, MAT_INITIAL_MATRIX, &B));
    PetscCall(MatView(B, viewer));
    PetscCall(MatDestroy(&B)); /* seqaij writes -matload_block_size into the .info itself */
    PetscFunctionReturn(0);
  }
  PetscCall(PetscViewerSetUp(viewer));
  nz        = a->nz * a->bs2;
  header[0] = MAT_FILE_CLASSID;
  header[1] = A->rmap->N;
  header[2] = A->cmap->N;
  header[3] = nz;
  PetscCall(PetscViewerBinaryWrite(viewer, header, 4, PETSC_INT));
  PetscCall(PetscMalloc1(m, &rowlens));
  for (PetscInt i = 0; i < m; i++) rowlens[i] = a->row_nz[i / bs] * bs;
  PetscCall(PetscViewerBinaryWrite(viewer, rowlens, m, PETSC_INT));
  PetscCall(PetscFree(rowlens));
  /* point rows in order; the explicit zeros inside stored blocks are written, as seqbaij does */
  PetscCall(PetscMalloc2(nz, &cols, nz, &vals));
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt r = i / bs, ii = i % bs;
    for (PetscInt k = 0; k < a->row_nz[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k);
      for (PetscInt j = 0; j < bs; j++) {
        cols[cnt] = a->col[s] * bs + j;
        vals[cnt] = BinBCSRGetValue(a, BinBCSRValueIndex(s, ii * bs + j, a->bw, a->bs2));
        cnt++;
      }
    }
  }
  PetscCall(PetscViewerBinaryWrite(viewer, cols, nz, PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(viewer, vals, nz, PETSC_SCALAR));
  PetscCall(PetscFree2(cols, vals));
  /* the block size for the next MatLoad, in the .info file PETSc's loaders read */
  PetscCall(PetscViewerBinaryGetInfoPointer(viewer, &info));
  if (info) PetscCall(PetscFPrintf(PETSC_COMM_SELF, info, "-matload_block_size %" PetscInt_FMT "\n", bs));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode MatView_SeqBinBCSR_Other(Mat A, PetscViewer viewer)
{
  PetscBool isbinary;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERBINARY, &isbinary));
  if (isbinary) {
    PetscCall(ViewBinary(A, viewer));
  } else {
    Mat B;
    PetscCall(MatConvert(A, MATSEQAIJ, MAT_INITIAL_MATRIX, &B));
    PetscCall(MatView(B, viewer));
    PetscCall(MatDestroy(&B));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatLoad_SeqBinBCSR(Mat A, PetscViewer viewer)
{
  PetscBool                isbinary;
  PetscInt                 m, bs, mbs;
  std::vector<PetscInt>    rowptr, cols, bi, bj, row;
  std::vector<PetscScalar> vals;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERBINARY, &isbinary));
  PetscCheck(isbinary, PetscObjectComm((PetscObject)viewer), PETSC_ERR_SUP,
             "MATSEQBINBCSR loads from binary viewers only, not %s", ((PetscObject)viewer)->type_name);
  /* everything read is checked before the matrix is touched; repeated entries come back summed */
  PetscCall(MatBinBCSRReadBinaryRows_Private(A, viewer, rowptr, cols, vals));
  m   = A->rmap->n;
  bs  = PetscAbs(A->rmap->bs);
  mbs = m / bs;

  /* block pattern: the union of the block columns of each block row's point rows */
  bi.assign(mbs + 1, 0);
  for (PetscInt r = 0; r < mbs; r++) {
    row.assign(cols.begin() + rowptr[r * bs], cols.begin() + rowptr[(r + 1) * bs]);
    for (auto &c : row) c /= bs;
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    bj.insert(bj.end(), row.begin(), row.end());
    bi[r + 1] = (PetscInt)bj.size();
  }
  PetscCall(MatSeqBinBCSRBuildLayout(A, bi.data(), bj.data()));
  A->preallocated = PETSC_TRUE;
  {
    Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
    for (PetscInt i = 0; i < m; i++)
      for (PetscInt k = rowptr[i]; k < rowptr[i + 1]; k++) {
        if (a->sym && cols[k] / bs < i / bs) continue; /* symmetric storage: the lower triangle is implied */
        const PetscInt s = MatSeqBinBCSRFindSlot(a, i / bs, cols[k] / bs);
        BinBCSRSetValue(a, BinBCSRValueIndex(s, (i % bs) * bs + cols[k] % bs, a->bw, a->bs2),
                        vals[k]); /* one entry per (row, column) */
      }
  }
  PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}
