// A FEM-like symmetric positive definite matrix with 3x3 blocks: a 27-point block stencil on an
// nx x ny x nz node grid, 3 unknowns per node (node (i,j,k) is block row i + nx*(j + ny*k)).
//
// Values are deterministic and the matrix is symmetric and strictly diagonally dominant, hence SPD:
//   off-diagonal block for the neighbour at offset d:  B = -w (I + 1/2 u u^T),  u = |d|/|d|
//     (componentwise absolute value: all off-diagonal entries <= 0),
//     w = (c_p + c_q)/2 / |d|^2  with a per-node coefficient c in [1, 1.5] (so rows differ),
//   diagonal block:  diagonal, entry a = (sum of |off-diagonal entries| of scalar row a) + shift c_p,
//                    i.e. just strictly diagonally dominant.
// Interior rows have 27 blocks (243 scalars), faces 18, edges 12, corners 8, as in an assembled
// trilinear hexahedral FE mesh. The condition number grows with the grid (like a stiffness
// matrix: ~ n^2) and is capped by about 1/shift.
#pragma once
#include <petscmat.h>

#include <vector>

struct StencilGrid {
  PetscInt  nx = 10, ny = 10, nz = 10;
  PetscReal shift = 1e-2; // diagonal margin relative to the coupling: smaller = worse conditioned
  PetscInt  nodes() const { return nx * ny * nz; }
};

// The blocks of one block row (node): *ncols block column indices in increasing order, and
// vals[27*9] holding the blocks side by side as a 3 x (3*ncols) row-major array
// (the layout MatSetValuesBlocked takes).
void StencilBlockRow(const StencilGrid &grid, PetscInt node, PetscInt *ncols, PetscInt cols[27],
                     PetscScalar vals[27 * 9]);

// Creates and assembles the matrix on comm (rows distributed by PETSc's default layout).
// type == nullptr: the type comes from the options database (-[prefix]mat_type, default aij),
// otherwise any MatType (aij, baij, sbaij, sell, binbcsr, ... and their seq/mpi forms).
// Preallocated exactly through MatXAIJSetPreallocation (+ the SELL setters), block size 3,
// marked symmetric and SPD. For SBAIJ types only the upper triangle is inserted.
PetscErrorCode CreateStencilMatrix(MPI_Comm comm, const StencilGrid &grid, MatType type, const char *prefix,
                                   Mat *A);

// Reads -stencil_n N (all three) or -stencil_nx/-stencil_ny/-stencil_nz and -stencil_shift.
PetscErrorCode StencilGridFromOptions(const char *prefix, StencilGrid *grid);

// The cube stencils of a benchmark that times several: -stencil_sizes N,M,... (at most max_sizes;
// 0: none; negative sizes refused), or the one of -stencil_n N, else the defaults. -stencil_n with
// -stencil_sizes, and -stencil_nx/-stencil_ny/-stencil_nz/-stencil_shift (one grid's options), are
// errors naming `program`: they would otherwise go unread.
PetscErrorCode StencilSizesFromOptions(MPI_Comm comm, const char *program,
                                       const std::vector<PetscInt> &defaults, PetscInt max_sizes,
                                       std::vector<PetscInt> *sizes);
