// The bytes model of sparse matrix formats for bandwidth figures (spmv_bench): what one MatMult must
// move at least, the matrix's stored arrays read once (values, column indices, row or bin offsets,
// padding included) + x read once + y written once, with no cache reuse of x beyond that and no halo.
//   aij:     nnz (8 + 4) + 4 (rows + 1)
//   baij:    blocks (8 bs^2 + 4) + 4 (block rows + 1)
//   sbaij:   upper blocks incl. diagonal (8 bs^2 + 4) + 4 (block rows + 1)
//   sell:    padded slots (8 + 4) + 4 (slices + 1), slices of 8 rows padded to their longest row
//   binbcsr: slots (s bs^2 + 4) + 4 (bins + 1), s = 8 (double) or 4 (single); slots = sum over bins
//            of bin_width x the bin's longest (block) row
//   binbcsr symmetric storage: the slots the matrix reports (MatGetInfo), plus 8 N more for y
//            (zeroed first, then read and written by the scatter)
//   + 8 N (x) + 8 N (y)
#pragma once
#include <petscmat.h>
#include <string>
#include <vector>

// Shape of a matrix, measured once on its aij form (row lengths in scalars; block rows for padding).
struct MatrixStats {
  PetscInt              rows = 0, bs = 1;
  double                nnz = 0, upper_blocks = 0, blocks = 0, sell_slots = 0;
  PetscInt              max_row = 0, min_row = 0;
  double                avg_row = 0;
  std::vector<PetscInt> block_row_len; // local block rows, in blocks (for binbcsr padding)
};

// One pass over the rows of aij (any type with MatGetRow; collective): scalar row lengths, SELL
// slots, block row lengths, upper blocks.
PetscErrorCode MeasureStats(Mat aij, MatrixStats *st);

// Bytes one MatMult moves by the model above for the format `type` ("aij", "baij", "sbaij", "sell",
// "binbcsr"; single and sym for binbcsr's storage, bin_width its bins, A the matrix itself, read only
// for symmetric storage's slots), and its padding overhead in percent of the stored blocks (-1 where
// the format has none). 0 for a type the model does not know. Collective on comm.
double FormatModelBytes(const std::string &type, bool single, bool sym, PetscInt bin_width, Mat A,
                        const MatrixStats &st, MPI_Comm comm, double *padding);
