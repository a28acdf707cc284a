// The bytes model of sparse matrix formats (format_bytes.h).
#include "sim/format_bytes.h"

#include <algorithm>
#include <cmath>

// One pass over the aij rows: scalar row lengths, SELL slots, block row lengths, upper blocks.
PetscErrorCode MeasureStats(Mat aij, MatrixStats *st)
{
  PetscInt rstart, rend;
  MPI_Comm comm = PetscObjectComm((PetscObject)aij);

  PetscFunctionBegin;
  PetscCall(MatGetSize(aij, &st->rows, nullptr));
  PetscCall(MatGetBlockSize(aij, &st->bs));
  PetscCall(MatGetOwnershipRange(aij, &rstart, &rend));
  const PetscInt        bs   = st->bs;
  PetscInt              maxr = 0, minr = PETSC_MAX_INT, slice_max = 0;
  double                nnz = 0, sell = 0, blocks = 0, upper = 0;
  std::vector<PetscInt> bcols;
  st->block_row_len.clear();
  for (PetscInt r = rstart; r < rend; ++r) {
    PetscInt        ncols;
    const PetscInt *cols;
    PetscCall(MatGetRow(aij, r, &ncols, &cols, nullptr));
    maxr = std::max(maxr, ncols);
    minr = std::min(minr, ncols);
    nnz += ncols;
    slice_max = std::max(slice_max, ncols);
    if ((r - rstart) % 8 == 7 || r == rend - 1) {
      sell += 8.0 * slice_max;
      slice_max = 0;
    }
    for (PetscInt c = 0; c < ncols; ++c) bcols.push_back(cols[c] / bs);
    PetscCall(MatRestoreRow(aij, r, &ncols, &cols, nullptr));
    if ((r - rstart) % bs == bs - 1) {
      std::sort(bcols.begin(), bcols.end());
      bcols.erase(std::unique(bcols.begin(), bcols.end()), bcols.end());
      const PetscInt brow = r / bs;
      st->block_row_len.push_back((PetscInt)bcols.size());
      blocks += (double)bcols.size();
      for (PetscInt c : bcols) upper += (c >= brow);
      bcols.clear();
    }
  }
  double sums[4] = {nnz, sell, blocks, upper};
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &maxr, 1, MPIU_INT, MPI_MAX, comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &minr, 1, MPIU_INT, MPI_MIN, comm));
  st->nnz          = sums[0];
  st->sell_slots   = sums[1];
  st->blocks       = sums[2];
  st->upper_blocks = sums[3];
  st->max_row      = maxr;
  st->min_row      = minr;
  st->avg_row      = sums[0] / (double)st->rows;
  PetscFunctionReturn(0);
}

// Stored blocks (slots) of BIN-(B)CSR: bins of bin_width local block rows, each padded to its longest
// row, the last bin completed with phantom lanes (as src/mat_binbcsr/seq/binbcsr.h lays them out).
static double BinnedBlocks(const MatrixStats &st, PetscInt bin_width, MPI_Comm comm, double *bins)
{
  double         slots = 0, nb = 0;
  const PetscInt n = (PetscInt)st.block_row_len.size();
  for (PetscInt start = 0; start < n; start += bin_width) {
    const PetscInt end     = std::min(n, start + bin_width);
    PetscInt       longest = 0;
    for (PetscInt r = start; r < end; ++r) longest = std::max(longest, st.block_row_len[r]);
    slots += (double)longest * (double)bin_width; // the last bin is completed with phantom lanes
    nb += 1;
  }
  double s[2] = {slots, nb};
  MPI_Allreduce(MPI_IN_PLACE, s, 2, MPI_DOUBLE, MPI_SUM, comm);
  *bins = s[1];
  return s[0];
}

double FormatModelBytes(const std::string &type, bool single, bool sym, PetscInt bin_width, Mat A,
                        const MatrixStats &st, MPI_Comm comm, double *padding)
{
  const double bs = (double)st.bs, nbrows = (double)st.rows / bs, vec = 16.0 * st.rows;
  *padding = -1;
  if (type == "aij") return st.nnz * 12 + 4 * (st.rows + 1) + vec;
  if (type == "baij") return st.blocks * (8 * bs * bs + 4) + 4 * (nbrows + 1) + vec;
  if (type == "sbaij") return st.upper_blocks * (8 * bs * bs + 4) + 4 * (nbrows + 1) + vec;
  if (type == "sell") return st.sell_slots * 12 + 4 * (std::ceil(st.rows / 8.0) + 1) + vec;
  if (type == "binbcsr" && sym) {
    MatInfo info;
    if (MatGetInfo(A, MAT_GLOBAL_SUM, &info)) return 0;
    const double slots = info.nz_allocated / (bs * bs),
                 bins  = std::ceil(nbrows / std::max<PetscInt>(1, bin_width));
    *padding           = 100.0 * (slots - st.upper_blocks) / st.upper_blocks;
    return slots * ((single ? 4 : 8) * bs * bs + 4) + 4 * (bins + 1) + vec + 8.0 * st.rows;
  }
  if (type == "binbcsr") {
    double       bins;
    const double slots = BinnedBlocks(st, std::max<PetscInt>(1, bin_width), comm, &bins);
    *padding           = 100.0 * (slots - st.blocks) / st.blocks;
    return slots * ((single ? 4 : 8) * bs * bs + 4) + 4 * (bins + 1) + vec;
  }
  return 0;
}
