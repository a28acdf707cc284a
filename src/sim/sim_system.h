// The PETSc layer shared by every simulation driver (FEM, rigid bodies, cloth): one symmetric linear
// system of 3x3 blocks whose sparsity pattern is fixed when the scene is built and whose values are
// refilled in place every step.
//
//   BlockSystem sys;
//   BlockSystemCreate(comm, n_global, n_local, coo_block_row, coo_block_col, &sys);   // once
//   loop: BlockSystemSetValues(&sys, block_values);                                  // 9 per COO block
//         BlockSystemSolve(&sys, rhs_local, sol_local, &stats);
//   BlockSystemDestroy(&sys);
//
// The pattern is given as a COO list of 3x3 blocks (global block indices; duplicates are summed, so
// every element can list its own blocks; a rank may list blocks of rows it does not own). The list
// is expanded once to 9 scalar COO entries per block, row-major, so the values a driver writes
// (block k at block_values[9k..9k+8], row-major) go to MatSetValuesCOO without any copy. Matrix
// types that implement COO natively (aij, binbcsr) take that path; others (baij, sell, ...) get one
// MatSetValuesBlocked per block after MatZeroEntries, which is correct and much faster than PETSc's
// scalar fallback.
//
// Options (all read here, so every driver accepts them): -mat_type aij|baij|sell|binbcsr|...,
// -ksp_type cg|pipecg|mcg|..., -pc_type (default jacobi), -ksp_max_it, -ksp_rtol, and every option
// of those types. A -mat_type that needs a GPU this PETSc was not built for (aijcusparse, ...) is a
// clear PETSC_ERR_SUP error.
#pragma once
#include "sim/smoother_copy.h"
#include <petscksp.h>
#include <string>
#include <vector>

struct BlockSystem {
  Mat       A   = nullptr; // block size 3, rows [row_begin, row_end) (scalar rows) on this rank
  KSP       ksp = nullptr;
  Vec       x = nullptr, b = nullptr;
  PetscInt  n_block_rows_global = 0, n_block_rows_local = 0;
  PetscInt  row_begin = 0, row_end = 0; // scalar row range owned by this rank
  PetscInt  n_coo_blocks = 0;           // blocks this rank contributes (length of the COO list)
  PetscInt  n_blocks     = 0;           // distinct blocks of the pattern over all ranks
  PetscBool native_coo   = PETSC_FALSE; // the type implements MatSetValuesCOO itself
  PetscBool upper_only =
    PETSC_FALSE; // blocks below the diagonal are ignored or mirrored from above (sbaij, binbcsr
                 // symmetric storage or COO mirror): the caller lists the upper triangle
  std::vector<PetscInt> coo_block_row, coo_block_col; // kept for the fallback path and for dumps
  const PetscScalar    *last_values = nullptr; // the caller's array from the last SetValues (for dumps)
  // The Mat takes float block values (BlockSystemSetValuesSingle): a binbcsr that stores single
  // precision, so values it rounds to float anyway are written and read at half the bytes.
  PetscBool          single_values      = PETSC_FALSE;
  const float       *last_values_single = nullptr; // as last_values, from the last SetValuesSingle
  PetscBool          values_set = PETSC_FALSE; // SetValues was called (a rank without blocks has no array)
  GAMGSmootherCopies gamg_copies;              // -gamg_smoother_precision single (smoother_copy.h)
  // -initial_guess_scaled: a nonzero initial guess x0 is replaced by a x0, a minimising ||b - a A x0||
  // (0 where x0 is no better than zero), at the cost of one product. r: its work vector.
  PetscBool guess_scaled = PETSC_FALSE;
  Vec       r            = nullptr;
  // -reuse_preconditioner_growth G (with -ksp_reuse_preconditioner): once a solve takes more than G
  // times the fewest iterations of a solve since the last set-up, the next solve sets the
  // preconditioner up again on the current matrix (0: never). A reused set-up goes stale as the
  // corotational matrix turns: GAMG's coarse space holds the rigid body modes of the shape it was built
  // on (docs/fem_timings.md). Such a set-up builds GAMG's interpolation again (from the near null space
  // or coordinates given since, BlockSystemSetRigidBodyModes) and keeps the KSP's initial guess history
  // (PETSc resets it at a solve that sets its preconditioner up).
  PetscReal reuse_growth = 0;
  PetscInt  fewest_its   = -1; // fewest iterations of a solve since the last set-up (-1: none yet)
  PetscBool rebuild_next = PETSC_FALSE;
  PetscInt  pc_rebuilds  = 0; // set-ups forced by reuse_growth
  // -gamg_refit_coarse_space (default on): such a set-up of a plain-aggregation GAMG refits
  // its prolongators to the rigid body modes of the last coordinates given (BlockSystemSetRigidBodyModes)
  // on the aggregates it has and redoes only the Galerkin products (gamg_coarse_space.h), instead of
  // building the hierarchy again. pc_refits: the set-ups done so.
  PetscBool              refit_coarse_space = PETSC_TRUE;
  std::vector<PetscReal> mode_coords; // this rank's node coordinates of the last rigid body modes
  PetscInt               pc_refits = 0;
};

struct SolveStats {
  PetscInt           iterations    = 0;
  PetscReal          guess_scale   = 1; // the factor -initial_guess_scaled put on the guess (1: none)
  PetscReal          residual_norm = 0; // as the KSP reports it (0 when the KSP computes none)
  KSPConvergedReason reason        = KSP_CONVERGED_ITERATING;
  double             ms            = 0; // wall-clock milliseconds of KSPSolve
  // what failed: the PC (KSP_DIVERGED_PC_FAILED, pc_failure.h), or KSPMCG stopped at its precision
  // floor (KSP_DIVERGED_BREAKDOWN); empty otherwise
  std::string pc_failure;
};

// n_block_rows_local may be PETSC_DECIDE. Call after PetscInitialize and plug-in registration.
PetscErrorCode BlockSystemCreate(MPI_Comm comm, PetscInt n_block_rows_global, PetscInt n_block_rows_local,
                                 const std::vector<PetscInt> &coo_block_row,
                                 const std::vector<PetscInt> &coo_block_col, BlockSystem *sys);

// What the Mat type the options select stores, known before any pattern is built, so a driver can
// list and compute only the blocks that are kept: *upper_only when blocks below the block diagonal are
// ignored (sbaij; binbcsr with -mat_binbcsr_symmetric_storage), and then *offrank_full when blocks that
// couple two ranks are kept in both triangles all the same (binbcsr stores its off-rank part in full).
// bin_width (may be null): the binbcsr bin width in block rows, 0 for other types.
// lower_mirrored (may be null): the Mat fills every block below the diagonal from the COO entries of
// its upper twin (binbcsr with -mat_binbcsr_coo_mirror), so the caller lists only blocks on or above
// the diagonal (also those coupling two ranks), whatever the Mat stores.
PetscErrorCode BlockSystemStoredTriangle(MPI_Comm comm, PetscBool *upper_only, PetscBool *offrank_full,
                                         PetscInt *bin_width = nullptr, PetscBool *lower_mirrored = nullptr);

// The rigid body modes (3 translations, 3 rotations) of this rank's nodes (coords_local: 3 per block
// row, in the rows' order) as the matrix's near null space, from which PCGAMG (and ML) build their
// coarse spaces for elasticity; other preconditioners ignore it. Once the KSP has its operators the
// coordinates also go to PCGAMG, which builds its next coarse space from them (collective): call it
// again with the current shape before a set-up.
PetscErrorCode BlockSystemSetRigidBodyModes(BlockSystem *sys, const PetscScalar *coords_local);

// block_values: 9 * n_coo_blocks values, block k row-major at [9k, 9k+9). Summed over duplicates,
// replacing the previous values. The array is remembered (not copied) for BlockSystemDumpMatrix: keep
// it alive until the next call or the dump.
PetscErrorCode BlockSystemSetValues(BlockSystem *sys, const PetscScalar *block_values);
// The same with float values, where sys->single_values (MatBinBCSRSetValuesCOOSingle: the blocks
// rounded once to float where the caller wrote them; entries summed in double by the Mat).
PetscErrorCode BlockSystemSetValuesSingle(BlockSystem *sys, const float *block_values);

// Solves A sol = rhs for this rank's rows (3 * n_block_rows_local scalars each). sol_local is also
// the initial guess when the KSP was told -ksp_initial_guess_nonzero (scaled first with
// -initial_guess_scaled, see BlockSystem). A KSP that does not converge
// is not an error here: stats->reason says what happened; the caller decides.
PetscErrorCode BlockSystemSolve(BlockSystem *sys, const PetscScalar *rhs_local, PetscScalar *sol_local,
                                SolveStats *stats);

// Writes the current matrix in PETSc binary format (loadable as aij with MatLoad), whatever its type.
PetscErrorCode BlockSystemDumpMatrix(BlockSystem *sys, const char *path);

// Structural nonzeros (9 per distinct block of the pattern, over all ranks; padding not counted) and the Mat type's name.
PetscErrorCode BlockSystemGetInfo(BlockSystem *sys, PetscInt *nnz, const char **mat_type,
                                  const char **ksp_type);

PetscErrorCode BlockSystemDestroy(BlockSystem *sys);
