// Runs a physics::BlockLinearSolver on a BlockSystem when every rank holds the whole physics state (the
// articulated and cloth drivers): the physics assembles all block values and right-hand sides, the solve is
// distributed. With P > 1 ranks the block rows are partitioned with METIS (physics/partition.hpp) over the
// pattern's graph and renumbered so each rank owns a contiguous range; each rank hands its own rows' blocks
// to the BlockSystem and the solution is gathered back to every rank (MPI_Allgatherv), in physics order.
// On any number of ranks the rows are then sorted by length inside windows of -rows_group_window rows
// (physics/row_order.hpp; default 256 for -mat_type binbcsr or sell, else 0 = off), so that the bins hold
// rows of similar length and carry little padding; the physics never sees the new numbering (right-hand sides and solutions are
// permuted here, the COO values keep their order).
// -rows_partition metis|contiguous: how the rows are split between the ranks, METIS (the default) or
// equal contiguous ranges of the physics order, for a physics order that is already local (the cloth's
// row-major particle grid: strips of whole grid rows, what its grid multigrid coarsens and sweeps best;
// the caller sets contiguous_parts before ReplicatedSolverNumber to make that its default).
// The solution vector passed to the solve is the initial guess when the KSP uses one
// (KSPSetInitialGuessNonzero / -ksp_initial_guess_nonzero).
//
// Two ways to hand over the values:
// - ReplicatedSolverCreate with the whole COO list: every rank assembles every block and set_matrix
//   copies out its own rows' (articulated).
// - ReplicatedSolverNumber, then ReplicatedSolverSetLocalPattern with only the blocks of this rank's rows
//   that its Mat type stores (ReplicatedSolverOwnsRow, ReplicatedSolverStoresBlock): the physics computes
//   just those and set_matrix passes its values straight to the COO refill (cloth).
#pragma once
#include "sim/sim_system.h"
#include "physics/block_solver.hpp"

#include <vector>

struct ReplicatedSolver {
  BlockSystem      sys;
  MPI_Comm         comm = MPI_COMM_NULL;
  int              size = 1, rank = 0;
  PetscInt         n_blocks = 0;           // block rows
  std::vector<int> new_of_old, old_of_new; // physics block row -> solver block row and back
  bool             renumbered = false;     // new_of_old is not the identity
  bool contiguous_parts = false;    // ReplicatedSolverNumber's default split: contiguous ranges (else METIS)
  std::vector<int>    row_offsets;  // block rows per rank, size + 1 entries
  std::vector<size_t> local_blocks; // indices into the physics COO list, this rank's rows
  bool                copy_local = false; // set_matrix gets the whole list and copies out local_blocks
  PetscBool           upper_only = PETSC_FALSE,
            offrank_full         = PETSC_FALSE; // what the Mat type stores (BlockSystemStoredTriangle)
  std::vector<PetscScalar> local_values, rhs_local, sol_local, sol_all;
  std::vector<int>         counts, displs; // scalars per rank for the gather
  bool                     cpu_timer =
    false; // solve_ms and setvalues_ms in process CPU time instead of wall time (a shared machine)
  // Totals since creation (or the last reset by the caller).
  long long          solves = 0, iterations = 0;
  double             solve_ms = 0, setvalues_ms = 0;
  SolveStats         last;
  KSPConvergedReason worst_reason = KSP_CONVERGED_ITERATING; // most recent negative reason, if any
  std::string        worst_detail;                           // its SolveStats::pc_failure
  long long          diverged_solves = 0;
  PetscErrorCode     error = 0; // first PETSc error inside a callback (the physics API has no error codes)
};

// block_row/block_col: the physics COO list of 3x3 blocks (both triangles, physics numbering).
PetscErrorCode ReplicatedSolverCreate(MPI_Comm comm, PetscInt n_blocks, const std::vector<int> &block_row,
                                      const std::vector<int> &block_col, ReplicatedSolver *rs);
// The numbering only (partition and row grouping) from the pattern's graph (both triangles, physics
// numbering); the matrix comes with ReplicatedSolverSetLocalPattern.
PetscErrorCode ReplicatedSolverNumber(MPI_Comm comm, PetscInt n_blocks, const std::vector<int> &block_row,
                                      const std::vector<int> &block_col, ReplicatedSolver *rs);
// Whether this rank owns block row `row` (physics numbering).
bool ReplicatedSolverOwnsRow(const ReplicatedSolver *rs, int row);
// Whether the Mat type keeps block (row, col) of one of this rank's rows (physics numbering): with
// upper-triangle storage, not the blocks below the diagonal of the solver's numbering, except those
// coupling two ranks where the type keeps them (binbcsr).
bool ReplicatedSolverStoresBlock(const ReplicatedSolver *rs, int row, int col);
// This rank's COO list (rows it owns, physics numbering); set_matrix then takes values in this order.
PetscErrorCode ReplicatedSolverSetLocalPattern(ReplicatedSolver *rs, const std::vector<int> &block_row,
                                               const std::vector<int> &block_col);
// The callbacks for the physics step; check rs->error after each step.
physics::BlockLinearSolver ReplicatedSolverAdapter(ReplicatedSolver *rs);
PetscErrorCode             ReplicatedSolverDestroy(ReplicatedSolver *rs);
