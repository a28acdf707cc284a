#include "sim/replicated_solver.h"
#include "sim/summary.h"

#include "physics/partition.hpp"
#include "physics/row_order.hpp"

#include <cstring>
#include <numeric>

PetscErrorCode ReplicatedSolverNumber(MPI_Comm comm, PetscInt n_blocks, const std::vector<int> &block_row,
                                      const std::vector<int> &block_col, ReplicatedSolver *rs)
{
  PetscFunctionBegin;
  rs->comm     = comm;
  rs->n_blocks = n_blocks;
  PetscCallMPI(MPI_Comm_size(comm, &rs->size));
  PetscCallMPI(MPI_Comm_rank(comm, &rs->rank));
  // Only bin-padded formats gain from grouping, and only under point preconditioners: incomplete
  // factorisations (on any type, binbcsr's included) rely on the physics order (IC(0) of a chain in its
  // own order is exact, in a shuffled one it is not).
  char mat_type[64] = "", pc_type[64] = "", sub_pc_type[64] = "";
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-mat_type", mat_type, sizeof mat_type, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-pc_type", pc_type, sizeof pc_type, nullptr));
  PetscCall(
    PetscOptionsGetString(nullptr, nullptr, "-sub_pc_type", sub_pc_type, sizeof sub_pc_type, nullptr));
  const bool point_pc = !pc_type[0] || !std::strcmp(pc_type, "jacobi") || !std::strcmp(pc_type, "pbjacobi") ||
                        !std::strcmp(pc_type, "none") ||
                        (!std::strcmp(pc_type, "bjacobi") &&
                         (!std::strcmp(sub_pc_type, "jacobi") || !std::strcmp(sub_pc_type, "pbjacobi")));
  PetscInt window = point_pc && (std::strstr(mat_type, "binbcsr") || std::strstr(mat_type, "sell")) ? 256 : 0;
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-rows_group_window", &window, nullptr));
  PetscCheck(window >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-rows_group_window must be >= 0 (0 = off), got %" PetscInt_FMT, window);
  const char *partitions[] = {"metis", "contiguous"};
  PetscInt    parts        = rs->contiguous_parts ? 1 : 0;
  PetscCall(PetscOptionsGetEList(nullptr, nullptr, "-rows_partition", partitions, 2, &parts, nullptr));
  std::vector<std::pair<int, int>> edges;
  for (size_t k = 0; k < block_row.size(); ++k)
    if (block_row[k] < block_col[k]) edges.push_back({block_row[k], block_col[k]});
  try {
    const physics::AdjacencyGraph g = physics::graph_from_edges((int)n_blocks, edges);
    physics::Renumbering          r;
    if (rs->size > 1 && parts == 1) { // equal contiguous ranges of the physics order
      r.new_of_old.resize(n_blocks);
      std::iota(r.new_of_old.begin(), r.new_of_old.end(), 0);
      r.old_of_new = r.new_of_old;
      for (int p = 0; p <= rs->size; ++p) r.part_offsets.push_back((int)((long long)n_blocks * p / rs->size));
    } else if (rs->size > 1) {
      r = physics::partition_graph(g, rs->size);
    } else {
      r.new_of_old.resize(n_blocks);
      std::iota(r.new_of_old.begin(), r.new_of_old.end(), 0);
      r.old_of_new   = r.new_of_old;
      r.part_offsets = {0, (int)n_blocks};
    }
    if (window > 0) r = physics::group_by_degree(g, r, (int)window);
    rs->new_of_old  = r.new_of_old;
    rs->row_offsets = r.part_offsets;
  } catch (const std::exception &e) {
    SETERRQ(comm, PETSC_ERR_LIB, "numbering the block rows failed: %s", e.what());
  }
  for (PetscInt i = 0; i < n_blocks && !rs->renumbered; ++i) rs->renumbered = rs->new_of_old[i] != i;
  rs->old_of_new.resize(n_blocks);
  for (PetscInt i = 0; i < n_blocks; ++i) rs->old_of_new[rs->new_of_old[i]] = (int)i;
  {
    PetscBool mirrored;
    PetscCall(BlockSystemStoredTriangle(comm, &rs->upper_only, &rs->offrank_full, nullptr, &mirrored));
    if (mirrored)
      rs->upper_only   = PETSC_TRUE,
      rs->offrank_full = PETSC_FALSE; // the Mat fills the lower triangle from the upper one, across ranks too
  }
  PetscFunctionReturn(0);
}

bool ReplicatedSolverOwnsRow(const ReplicatedSolver *rs, int row)
{
  const int r = rs->new_of_old[row];
  return r >= rs->row_offsets[rs->rank] && r < rs->row_offsets[rs->rank + 1];
}

bool ReplicatedSolverStoresBlock(const ReplicatedSolver *rs, int row, int col)
{
  if (!rs->upper_only || rs->new_of_old[row] <= rs->new_of_old[col]) return true;
  return rs->offrank_full && !ReplicatedSolverOwnsRow(rs, col);
}

PetscErrorCode ReplicatedSolverSetLocalPattern(ReplicatedSolver *rs, const std::vector<int> &block_row,
                                               const std::vector<int> &block_col)
{
  PetscFunctionBegin;
  const int begin = rs->row_offsets[rs->rank], end = rs->row_offsets[rs->rank + 1];
  PetscCheck(block_row.size() == block_col.size(), PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "COO block lists differ in length: %zu rows, %zu columns", block_row.size(), block_col.size());
  std::vector<PetscInt> rows(block_row.size()), cols(block_col.size());
  for (size_t k = 0; k < block_row.size(); ++k) {
    PetscCheck(
      block_row[k] >= 0 && block_row[k] < rs->n_blocks && block_col[k] >= 0 && block_col[k] < rs->n_blocks,
      PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "COO block %zu is (%d, %d), outside [0, %" PetscInt_FMT ")",
      k, block_row[k], block_col[k], rs->n_blocks);
    rows[k] = rs->new_of_old[block_row[k]];
    cols[k] = rs->new_of_old[block_col[k]];
    PetscCheck(rows[k] >= begin && rows[k] < end, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "COO block %zu is in row %d, which rank %d does not own", k, block_row[k], rs->rank);
  }
  PetscCall(BlockSystemCreate(rs->comm, rs->n_blocks, end - begin, rows, cols, &rs->sys));
  rs->rhs_local.resize(3 * (end - begin));
  rs->sol_local.assign(3 * (end - begin), 0.0);
  rs->sol_all.resize(3 * rs->n_blocks);
  rs->counts.clear(), rs->displs.clear();
  for (int p = 0; p < rs->size; ++p) {
    rs->counts.push_back(3 * (rs->row_offsets[p + 1] - rs->row_offsets[p]));
    rs->displs.push_back(3 * rs->row_offsets[p]);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode ReplicatedSolverCreate(MPI_Comm comm, PetscInt n_blocks, const std::vector<int> &block_row,
                                      const std::vector<int> &block_col, ReplicatedSolver *rs)
{
  PetscFunctionBegin;
  PetscCall(ReplicatedSolverNumber(comm, n_blocks, block_row, block_col, rs));
  if (rs->size == 1)
    PetscCall(
      ReplicatedSolverSetLocalPattern(rs, block_row, block_col)); // identical order: values need no copy
  else {
    std::vector<int> rows, cols;
    for (size_t k = 0; k < block_row.size(); ++k) {
      if (!ReplicatedSolverOwnsRow(rs, block_row[k])) continue;
      rs->local_blocks.push_back(k);
      rows.push_back(block_row[k]);
      cols.push_back(block_col[k]);
    }
    PetscCall(ReplicatedSolverSetLocalPattern(rs, rows, cols));
    rs->copy_local = true;
    rs->local_values.resize(9 * rs->local_blocks.size());
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode SetMatrix(ReplicatedSolver *rs, const std::vector<double> &values)
{
  PetscFunctionBegin;
  const auto   now = rs->cpu_timer ? ProcessCpuTime : WallTime;
  const double t0  = now();
  if (rs->copy_local) {
    for (size_t i = 0; i < rs->local_blocks.size(); ++i)
      for (int k = 0; k < 9; ++k) rs->local_values[9 * i + k] = values[9 * rs->local_blocks[i] + k];
    PetscCall(BlockSystemSetValues(&rs->sys, rs->local_values.data()));
  } else {
    PetscCheck(values.size() == 9 * (size_t)rs->sys.n_coo_blocks, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
               "%zu block values for %" PetscInt_FMT " COO blocks", values.size(), rs->sys.n_coo_blocks);
    PetscCall(BlockSystemSetValues(&rs->sys, values.data()));
  }
  rs->setvalues_ms += 1e3 * (now() - t0);
  PetscFunctionReturn(0);
}

static PetscErrorCode Solve(ReplicatedSolver *rs, const std::vector<double> &rhs, std::vector<double> &sol)
{
  PetscBool nonzero_guess;

  PetscFunctionBegin;
  const auto now = rs->cpu_timer ? ProcessCpuTime : WallTime;
  double     t0 = 0, t1 = 0;
  const int  begin = rs->row_offsets[rs->rank], end = rs->row_offsets[rs->rank + 1];
  PetscCall(KSPGetInitialGuessNonzero(rs->sys.ksp, &nonzero_guess));
  if (sol.size() != (size_t)(3 * rs->n_blocks)) sol.assign(3 * rs->n_blocks, 0.0);
  if (rs->size == 1 && !rs->renumbered) {
    t0 = now();
    PetscCall(BlockSystemSolve(&rs->sys, rhs.data(), sol.data(), &rs->last));
    t1 = now();
  } else {
    for (int i = begin; i < end; ++i)
      for (int k = 0; k < 3; ++k) {
        rs->rhs_local[3 * (i - begin) + k] = rhs[3 * rs->old_of_new[i] + k];
        if (nonzero_guess) rs->sol_local[3 * (i - begin) + k] = sol[3 * rs->old_of_new[i] + k];
      }
    t0 = now();
    PetscCall(BlockSystemSolve(&rs->sys, rs->rhs_local.data(), rs->sol_local.data(), &rs->last));
    t1 = now();
    if (rs->size == 1) {
      for (PetscInt i = 0; i < rs->n_blocks; ++i)
        for (int k = 0; k < 3; ++k) sol[3 * rs->old_of_new[i] + k] = rs->sol_local[3 * i + k];
    } else {
      PetscCallMPI(MPI_Allgatherv(rs->sol_local.data(), 3 * (end - begin), MPIU_SCALAR, rs->sol_all.data(),
                                  rs->counts.data(), rs->displs.data(), MPIU_SCALAR, rs->comm));
      for (PetscInt i = 0; i < rs->n_blocks; ++i)
        for (int k = 0; k < 3; ++k) sol[3 * i + k] = rs->sol_all[3 * rs->new_of_old[i] + k];
    }
  }
  rs->solves++;
  rs->iterations += rs->last.iterations;
  rs->solve_ms += 1e3 * (t1 - t0);
  if (rs->last.reason < 0) {
    rs->worst_reason = rs->last.reason;
    rs->worst_detail = rs->last.pc_failure;
    rs->diverged_solves++;
  }
  PetscFunctionReturn(0);
}

physics::BlockLinearSolver ReplicatedSolverAdapter(ReplicatedSolver *rs)
{
  physics::BlockLinearSolver s;
  if (rs->size > 1) // SetMatrix passes on only this rank's rows
    for (int i = rs->row_offsets[rs->rank]; i < rs->row_offsets[rs->rank + 1]; ++i)
      s.needed_rows.push_back(rs->old_of_new[i]);
  s.set_matrix = [rs](const std::vector<double> &values) {
    if (!rs->error) rs->error = SetMatrix(rs, values);
  };
  s.solve = [rs](const std::vector<double> &rhs, std::vector<double> &sol) {
    physics::LinearSolveResult r;
    if (!rs->error) rs->error = Solve(rs, rhs, sol);
    if (rs->error) {
      sol.assign(3 * rs->n_blocks, 0.0);
      r.converged = false;
      return r;
    }
    r.iterations = (int)rs->last.iterations;
    r.converged  = rs->last.reason > 0;
    // Breakdown or indefiniteness of CG on J M^-1 J^T is how a singular (loop) matrix shows up; running
    // out of iterations is not (fixed-iteration runs end that way on purpose).
    r.breakdown =
      rs->last.reason == KSP_DIVERGED_BREAKDOWN || rs->last.reason == KSP_DIVERGED_BREAKDOWN_BICG ||
      rs->last.reason == KSP_DIVERGED_INDEFINITE_PC || rs->last.reason == KSP_DIVERGED_INDEFINITE_MAT ||
      rs->last.reason == KSP_DIVERGED_NANORINF || rs->last.reason == KSP_DIVERGED_DTOL;
    return r;
  };
  return s;
}

PetscErrorCode ReplicatedSolverDestroy(ReplicatedSolver *rs)
{
  PetscFunctionBegin;
  PetscCall(BlockSystemDestroy(&rs->sys));
  PetscFunctionReturn(0);
}
