// Galerkin products Ac = W^T A W for 3x3-block matrices whose interpolation repeats one scalar weight per
// block (W (x) I3: every component interpolated alike), on one rank, as SeqBAIJ. The pattern and, for every
// product term, which source block goes with which weight into which block of Ac are worked out once;
// a refill is then one pass over the terms (PETSc's MatPtAP works scalar by scalar on AIJ, and on a
// binbcsr operator through an AIJ copy of it refreshed every time).
#pragma once
#include <petscmat.h>
#include <utility>
#include <vector>

struct BlockWeight {
  PetscInt coarse;
  double   w;
};

struct BlockGalerkin {
  Mat Ac = nullptr; // SeqBAIJ, block size 3
  struct Term {
    PetscInt src; // source block; ~src (negative): read it transposed
    PetscInt dst; // block of Ac (index into its value array / 9)
    double   w;
  };
  std::vector<Term>     terms; // sorted by dst
  std::vector<PetscInt> start; // terms of Ac's block b: [start[b], start[b + 1])
  // symmetric products: (block below the diagonal, the block above it whose transpose it is)
  std::vector<std::pair<PetscInt, PetscInt>> mirror;
};

// The source: nblocks 3x3 blocks (row[k], col[k]) in fine node numbering, 9 values each, row-major when
// row_major (a COO list), else column-major (PETSc's BAIJ). mirrored: every block off the diagonal also
// stands for its transpose at (col, row) (upper-triangle storage). weights[i]: fine node i's row of W.
// symmetric: the source matrix is symmetric (mirrored, or each block listed with its transpose), so Ac is
// too: only its blocks on and above the diagonal are summed and the others copied from them transposed
// (about half the terms; the blocks off the diagonal are then exact transposes of each other).
// mirror_block (optional, one flag per block): with mirrored, only the blocks flagged stand for their
// transposes.
PetscErrorCode BlockGalerkinCreate(const std::vector<PetscInt> &row, const std::vector<PetscInt> &col,
                                   bool row_major, bool mirrored, bool symmetric,
                                   const std::vector<std::vector<BlockWeight>> &weights, PetscInt n_coarse,
                                   BlockGalerkin *g, const std::vector<char> *mirror_block = nullptr);
// The source blocks of a SeqBAIJ matrix (block size 3), in its value array's order, for BlockGalerkinCreate.
PetscErrorCode BlockGalerkinBlocksOf(Mat A, std::vector<PetscInt> *row, std::vector<PetscInt> *col);
// Ac = W^T A W for new source values (9 per block, the layout given at creation).
PetscErrorCode BlockGalerkinRefill(BlockGalerkin *g, const PetscScalar *values);
PetscErrorCode BlockGalerkinDestroy(BlockGalerkin *g);
