/* PETSc binary matrix files (header: class id, rows, columns, nonzeros; then row lengths, column
   indices, values), read by rows with PetscViewerBinaryReadAll so that one reader serves one rank
   (seq) and many (mpi) with the same checks and the same treatment of repeated entries. */
#include "binbcsr_load.h"

#include <petsc/private/matimpl.h>

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace {

/* -matload_block_size bs or rbs,cbs, as PETSc's own loaders honour it. */
PetscErrorCode LoadBlockSizes(Mat A)
{
  PetscInt  bs[2] = {0, 0}, n = 2;
  PetscBool set;

  PetscFunctionBegin;
  PetscCall(PetscOptionsGetIntArray(((PetscObject)A)->options, nullptr, "-matload_block_size", bs, &n, &set));
  if (!set) PetscFunctionReturn(0);
  if (n == 1) bs[1] = bs[0];
  PetscCheck(bs[0] > 0 && bs[1] > 0, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_OUTOFRANGE,
             "-matload_block_size must be positive");
  PetscCall(MatSetBlockSizes(A, bs[0], bs[1]));
  PetscFunctionReturn(0);
}

/* A check made by each rank on its own rows, agreed on by all: *row is the lowest global row any rank
   flagged (-1: none) and *what the value that rank attached to it (a length or a column). */
PetscErrorCode Agree(MPI_Comm comm, PetscInt64 my_row, PetscInt64 my_what, PetscInt64 *row, PetscInt64 *what)
{
  int64_t v = my_row < 0 ? INT64_MAX : my_row, w;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Allreduce(&v, row, 1, MPI_INT64_T, MPI_MIN, comm));
  w = (v == *row && my_row >= 0) ? my_what : INT64_MAX;
  PetscCallMPI(MPI_Allreduce(&w, what, 1, MPI_INT64_T, MPI_MIN, comm));
  if (*row == INT64_MAX) *row = -1;
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode MatBinBCSRReadBinaryRows_Private(Mat A, PetscViewer viewer, std::vector<PetscInt> &rowptr,
                                                std::vector<PetscInt> &cols, std::vector<PetscScalar> &vals)
{
  MPI_Comm   comm = PetscObjectComm((PetscObject)A);
  PetscInt   header[4], M, N, nz, m, bs, cbs, rstart;
  PetscInt64 bad_row, bad_what, local_nz = 0, total_nz;

  PetscFunctionBegin;
  PetscCall(PetscViewerSetUp(viewer));
  PetscCall(PetscViewerBinaryRead(viewer, header, 4, nullptr, PETSC_INT));
  PetscCheck(header[0] == MAT_FILE_CLASSID, comm, PETSC_ERR_FILE_UNEXPECTED,
             "Not a matrix object in the file (class id %" PetscInt_FMT ")", header[0]);
  M  = header[1];
  N  = header[2];
  nz = header[3];
  PetscCheck(M >= 0 && N >= 0, comm, PETSC_ERR_FILE_UNEXPECTED,
             "Matrix sizes in the file are negative: %" PetscInt_FMT " x %" PetscInt_FMT, M, N);
  PetscCheck(nz >= 0, comm, PETSC_ERR_FILE_UNEXPECTED,
             "Matrix stored in a special format in the file (nonzeros %" PetscInt_FMT "), cannot load as %s",
             nz, ((PetscObject)A)->type_name);

  PetscCall(LoadBlockSizes(A));
  if (A->rmap->N < 0) A->rmap->N = M;
  if (A->cmap->N < 0) A->cmap->N = N;
  bs  = PetscAbs(A->rmap->bs);
  cbs = PetscAbs(A->cmap->bs);
  PetscCheck(M % bs == 0 && N % cbs == 0, comm, PETSC_ERR_ARG_SIZ,
             "Matrix in the file is %" PetscInt_FMT " x %" PetscInt_FMT
             ", not a multiple of the block size %" PetscInt_FMT,
             M, N, bs);
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCheck(A->rmap->N == M && A->cmap->N == N, comm, PETSC_ERR_FILE_UNEXPECTED,
             "Matrix in the file is %" PetscInt_FMT " x %" PetscInt_FMT
             ", the matrix to load into %" PetscInt_FMT " x %" PetscInt_FMT,
             M, N, A->rmap->N, A->cmap->N);
  m      = A->rmap->n;
  rstart = A->rmap->rstart;
  PetscCheck(m % bs == 0 && A->cmap->n % cbs == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Local size %" PetscInt_FMT " x %" PetscInt_FMT
             " is not a multiple of the block size %" PetscInt_FMT,
             m, A->cmap->n, bs);

  /* row lengths: each in [0, N], adding up to nz over all ranks */
  rowptr.assign(m + 1, 0);
  PetscCall(PetscViewerBinaryReadAll(viewer, rowptr.data() + 1, m, PETSC_DECIDE, M, PETSC_INT));
  {
    PetscInt64 first = -1, len = 0;
    for (PetscInt i = 0; i < m && first < 0; i++)
      if (rowptr[i + 1] < 0 || rowptr[i + 1] > N || rowptr[i] > nz - rowptr[i + 1])
        first = rstart + i, len = rowptr[i + 1];
      else rowptr[i + 1] += rowptr[i];
    PetscCall(Agree(comm, first, len, &bad_row, &bad_what));
    PetscCheck(bad_row < 0, comm, PETSC_ERR_FILE_UNEXPECTED,
               "Row %" PetscInt64_FMT " in the file has %" PetscInt64_FMT " entries (columns: %" PetscInt_FMT
               ", nonzeros: %" PetscInt_FMT ")",
               bad_row, bad_what, N, nz);
  }
  local_nz = rowptr[m];
  PetscCallMPI(MPI_Allreduce(&local_nz, &total_nz, 1, MPI_INT64_T, MPI_SUM, comm));
  PetscCheck(total_nz == nz, comm, PETSC_ERR_FILE_UNEXPECTED,
             "Inconsistent matrix data in the file: nonzeros %" PetscInt_FMT
             ", sum of row lengths %" PetscInt64_FMT,
             nz, total_nz);

  cols.resize(rowptr[m]);
  vals.resize(rowptr[m]);
  PetscCall(PetscViewerBinaryReadAll(viewer, cols.data(), rowptr[m], PETSC_DECIDE, nz, PETSC_INT));
  PetscCall(PetscViewerBinaryReadAll(viewer, vals.data(), rowptr[m], PETSC_DECIDE, nz, PETSC_SCALAR));
  {
    PetscInt64 first = -1, col = 0;
    for (PetscInt i = 0; i < m && first < 0; i++)
      for (PetscInt k = rowptr[i]; k < rowptr[i + 1]; k++)
        if (cols[k] < 0 || cols[k] >= N) {
          first = rstart + i, col = cols[k];
          break;
        }
    PetscCall(Agree(comm, first, col, &bad_row, &bad_what));
    PetscCheck(bad_row < 0, comm, PETSC_ERR_FILE_UNEXPECTED,
               "Column index %" PetscInt64_FMT " of row %" PetscInt64_FMT
               " in the file out of range [0, %" PetscInt_FMT ")",
               bad_what, bad_row, N);
  }
  if (A->erroriffailure) {
    PetscInt64 first = -1;
    for (PetscInt i = 0; i < m && first < 0; i++)
      for (PetscInt k = rowptr[i]; k < rowptr[i + 1]; k++)
        if (PetscIsInfOrNanScalar(vals[k])) {
          first = rstart + i;
          break;
        }
    PetscCall(Agree(comm, first, 0, &bad_row, &bad_what));
    PetscCheck(bad_row < 0, comm, PETSC_ERR_FP,
               "Row %" PetscInt64_FMT
               " in the file holds a value that is not finite (MatSetErrorIfFailure is set)",
               bad_row);
  }

  /* each row sorted by column, repeated columns summed (kept in file order, so the sum's rounding is seqaij's) */
  {
    std::vector<PetscInt>    order, c2;
    std::vector<PetscScalar> v2;
    PetscInt                 out = 0;
    c2.reserve(cols.size());
    v2.reserve(vals.size());
    for (PetscInt i = 0; i < m; i++) {
      order.resize(rowptr[i + 1] - rowptr[i]);
      std::iota(order.begin(), order.end(), rowptr[i]);
      std::stable_sort(order.begin(), order.end(), [&](PetscInt p, PetscInt q) { return cols[p] < cols[q]; });
      for (PetscInt p : order) {
        if (!c2.empty() && (PetscInt)c2.size() > out && c2.back() == cols[p]) v2.back() += vals[p];
        else c2.push_back(cols[p]), v2.push_back(vals[p]);
      }
      rowptr[i] = out;
      out       = (PetscInt)c2.size();
    }
    rowptr[m] = out;
    cols.swap(c2);
    vals.swap(v2);
  }
  PetscFunctionReturn(0);
}
