/*
   MATSEQBINBCSR and PETSc binary files. The file holds a scalar CSR matrix (header: class id, rows,
   columns, nonzeros; then row lengths, column indices, values), the format every PETSc matrix type
   reads and writes, so files round-trip with seqaij and seqbaij. The block size comes from
   MatSetBlockSize before the load or from -matload_block_size (also found in the file's .info); a
   block row stores the union of its point rows' block columns as full blocks. Everything read is
   validated before the matrix changes.
*/
#include "binbcsr_ops.h"

#include <algorithm>
#include <vector>

namespace
{

/* -matload_block_size bs or rbs,cbs, as PETSc's own loaders honour it. */
PetscErrorCode LoadBlockSizes(Mat A)
{
  PetscInt  bs[2] = {0, 0}, n = 2;
  PetscBool set;

  PetscFunctionBegin;
  PetscCall(PetscOptionsGetIntArray(((PetscObject)A)->options, nullptr, "-matload_block_size", bs, &n, &set));
  if (!set) PetscFunctionReturn(0);
  if (n == 1) bs[1] = bs[0];
  PetscCheck(bs[0] > 0 && bs[1] > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-matload_block_size must be positive");
  PetscCall(MatSetBlockSizes(A, bs[0], bs[1]));
  PetscFunctionReturn(0);
}

PetscErrorCode ViewBinary(Mat A, PetscViewer viewer)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bs = a->bs, m = A->rmap->n;
  PetscInt        header[4], *rowlens, *cols, nz, cnt = 0;
  PetscScalar    *vals;
  FILE           *info;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatView to a binary file needs an assembled matrix");
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
  PetscBool             isbinary;
  PetscInt              header[4], M, N, nz, m, n, bs, mbs;
  std::vector<PetscInt> rowptr, cols, bi, bj, row;
  std::vector<PetscScalar> vals;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERBINARY, &isbinary));
  PetscCheck(isbinary, PetscObjectComm((PetscObject)viewer), PETSC_ERR_SUP, "MATSEQBINBCSR loads from binary viewers only, not %s", ((PetscObject)viewer)->type_name);
  PetscCall(PetscViewerSetUp(viewer));
  PetscCall(PetscViewerBinaryRead(viewer, header, 4, nullptr, PETSC_INT));
  PetscCheck(header[0] == MAT_FILE_CLASSID, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Not a matrix object in the file (class id %" PetscInt_FMT ")", header[0]);
  M  = header[1];
  N  = header[2];
  nz = header[3];
  PetscCheck(M >= 0 && N >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Matrix sizes in the file are negative: %" PetscInt_FMT " x %" PetscInt_FMT, M, N);
  PetscCheck(nz >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Matrix stored in a special format in the file (nonzeros %" PetscInt_FMT "), cannot load as MATSEQBINBCSR", nz);

  PetscCall(LoadBlockSizes(A));
  if (A->rmap->n < 0) A->rmap->n = M;
  if (A->cmap->n < 0) A->cmap->n = N;
  if (A->rmap->N < 0) A->rmap->N = M;
  if (A->cmap->N < 0) A->cmap->N = N;
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCheck(A->rmap->N == M && A->cmap->N == N, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Matrix in the file is %" PetscInt_FMT " x %" PetscInt_FMT ", the matrix to load into %" PetscInt_FMT " x %" PetscInt_FMT, M, N, A->rmap->N, A->cmap->N);
  m  = A->rmap->n;
  n  = A->cmap->n;
  bs = PetscAbs(A->rmap->bs);
  PetscCheck(m % bs == 0 && n % bs == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Matrix in the file is %" PetscInt_FMT " x %" PetscInt_FMT ", not a multiple of the block size %" PetscInt_FMT, M, N, bs);
  mbs = m / bs;

  /* row lengths, column indices, values: all checked before the matrix is touched */
  rowptr.assign(m + 1, 0);
  PetscCall(PetscViewerBinaryRead(viewer, rowptr.data() + 1, m, nullptr, PETSC_INT));
  for (PetscInt i = 0; i < m; i++) {
    PetscCheck(rowptr[i + 1] >= 0 && rowptr[i + 1] <= N, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Row %" PetscInt_FMT " in the file has %" PetscInt_FMT " entries (columns: %" PetscInt_FMT ")", i, rowptr[i + 1], N);
    PetscCheck(rowptr[i] <= nz - rowptr[i + 1], PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Row lengths in the file add up to more than its %" PetscInt_FMT " nonzeros", nz);
    rowptr[i + 1] += rowptr[i];
  }
  PetscCheck(rowptr[m] == nz, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Inconsistent matrix data in the file: nonzeros %" PetscInt_FMT ", sum of row lengths %" PetscInt_FMT, nz, rowptr[m]);
  cols.resize(nz);
  vals.resize(nz);
  PetscCall(PetscViewerBinaryRead(viewer, cols.data(), nz, nullptr, PETSC_INT));
  for (PetscInt k = 0; k < nz; k++) PetscCheck(cols[k] >= 0 && cols[k] < N, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "Column index %" PetscInt_FMT " in the file out of range [0, %" PetscInt_FMT ")", cols[k], N);
  PetscCall(PetscViewerBinaryRead(viewer, vals.data(), nz, nullptr, PETSC_SCALAR));
  if (A->erroriffailure)
    for (PetscInt k = 0; k < nz; k++) PetscCheck(!PetscIsInfOrNanScalar(vals[k]), PETSC_COMM_SELF, PETSC_ERR_FP, "Value %" PetscInt_FMT " in the file is not finite (MatSetErrorIfFailure is set)", k);

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
        BinBCSRSetValue(a, BinBCSRValueIndex(s, (i % bs) * bs + cols[k] % bs, a->bw, a->bs2), vals[k]); /* a repeated entry: the last one wins, as with INSERT_VALUES */
      }
  }
  PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}
