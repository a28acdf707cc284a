// pc_setup_bench: what a PC that works on submatrices or a factor costs to set up on binbcsr against
// aij, first and after a refill of the values (what a simulation pays every step).
//
// The matrix: the 27-point block stencil (src/sim/stencil.h), -stencil_n N nodes a side.
// For each -formats entry and each -pcs entry: KSPSetUp once (the first set-up), then -refills times
// "scale the values (MatScale, the matrix's state changes) + PCSetUp" (the MAT_REUSE_MATRIX path),
// timed with a barrier around; prints the minimum over -repeats batches in ms.
//
//   mpiexec -n 2 build/examples/pc_setup_bench -stencil_n 20 -pcs asm,gasm,redundant,fieldsplit,mumps,hypre
static char help[] = "PC set-up time, first and after a refill, binbcsr against aij.\n";

#include "sim/bench_util.h"
#include "sim/stencil.h"

#include <petscbinbcsr.h>
#include <petscksp.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace {

// PC options for each name of -pcs.
std::vector<std::pair<std::string, std::string>> pc_options(const std::string &pc)
{
  if (pc == "asm") return {{"-pc_type", "asm"}, {"-pc_asm_overlap", "1"}, {"-sub_pc_type", "icc"}};
  if (pc == "gasm") return {{"-pc_type", "gasm"}, {"-sub_pc_type", "icc"}};
  // the copy's own solver is left out (Jacobi): what is timed is getting the copy
  if (pc == "redundant") return {{"-pc_type", "redundant"}, {"-redundant_pc_type", "jacobi"}};
  if (pc == "fieldsplit")
    return {
      {"-pc_type", "fieldsplit"}, {"-pc_fieldsplit_block_size", "3"}, {"-fieldsplit_pc_type", "jacobi"}};
  if (pc == "mumps") return {{"-pc_type", "cholesky"}, {"-pc_factor_mat_solver_type", "mumps"}};
  if (pc == "hypre") return {{"-pc_type", "hypre"}};
  return {{"-pc_type", pc}};
}

PetscErrorCode time_setups(Mat A, const std::string &pc, PetscInt refills, double *first_ms,
                           double *refill_ms)
{
  KSP ksp;
  PC  p;
  PetscFunctionBeginUser;
  const auto opts = pc_options(pc);
  for (auto &[k, v] : opts) PetscCall(PetscOptionsSetValue(nullptr, k.c_str(), v.c_str()));
  PetscCall(KSPCreate(PetscObjectComm((PetscObject)A), &ksp));
  PetscCall(KSPSetOperators(ksp, A, A));
  PetscCall(KSPSetType(ksp, KSPCG));
  PetscCall(KSPSetFromOptions(ksp));
  PetscCall(KSPGetPC(ksp, &p));
  PetscCallMPI(MPI_Barrier(PetscObjectComm((PetscObject)A)));
  double t0 = MPI_Wtime();
  PetscCall(KSPSetUp(ksp)); /* inner KSPs (ASM blocks, the redundant copy) read their options here */
  PetscCallMPI(MPI_Barrier(PetscObjectComm((PetscObject)A)));
  *first_ms = 1e3 * (MPI_Wtime() - t0);
  for (auto &[k, v] : opts) PetscCall(PetscOptionsClearValue(nullptr, k.c_str()));
  t0 = MPI_Wtime();
  for (PetscInt r = 0; r < refills; ++r) {
    PetscCall(MatScale(A, r % 2 ? 1.0 / 1.01 : 1.01)); // new values, same pattern
    PetscCall(PCSetUp(p));
  }
  PetscCallMPI(MPI_Barrier(PetscObjectComm((PetscObject)A)));
  *refill_ms = 1e3 * (MPI_Wtime() - t0) / refills;
  PetscCall(KSPDestroy(&ksp));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  StencilGrid grid;
  PetscInt    refills = 5, repeats = 3;
  char        formats[256] = "aij,binbcsr", pcs[256] = "asm,gasm,redundant,fieldsplit,mumps,hypre";

  PetscCall(PetscInitialize(&argc, &argv, nullptr, help));
  PetscCall(PetscBinBCSRRegisterAll());
  grid.nx = grid.ny = grid.nz = 20;
  PetscCall(StencilGridFromOptions(nullptr, &grid));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-refills", &refills, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &repeats, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-formats", formats, sizeof formats, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-pcs", pcs, sizeof pcs, nullptr));
  /* -repeats 0 printed the unset minimum (1e300, 300 digits); the refill column is a time per refill */
  PetscCheck(repeats >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-repeats must be >= 1, not %" PetscInt_FMT, repeats);
  PetscCheck(refills >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-refills must be >= 1, not %" PetscInt_FMT, refills);
  std::vector<std::string> pc_list, format_list;
  PetscCall(SplitOptionList(PETSC_COMM_WORLD, "-pcs", pcs, &pc_list));
  PetscCall(SplitOptionList(PETSC_COMM_WORLD, "-formats", formats, &format_list));
  PetscMPIInt size;
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                        "27-point block stencil %" PetscInt_FMT "^3 nodes (%" PetscInt_FMT
                        " rows), %d ranks; min over %" PetscInt_FMT " repeats\n",
                        grid.nx, 3 * grid.nodes(), size, repeats));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%-12s %-10s %14s %20s\n", "pc", "format", "first (ms)",
                        "after refill (ms)"));
  for (const std::string &pc : pc_list) {
    for (const std::string &fmt : format_list) {
      Mat    A;
      double first = 1e300, refill = 1e300;
      PetscCall(CreateStencilMatrix(PETSC_COMM_WORLD, grid, fmt.c_str(), nullptr, &A));
      for (PetscInt r = 0; r < repeats; ++r) {
        double f, g;
        PetscCall(time_setups(A, pc, refills, &f, &g));
        first  = std::min(first, f);
        refill = std::min(refill, g);
      }
      PetscCall(MatDestroy(&A));
      PetscCall(
        PetscPrintf(PETSC_COMM_WORLD, "%-12s %-10s %14.2f %20.2f\n", pc.c_str(), fmt.c_str(), first, refill));
    }
  }
  PetscCall(PetscFinalize());
  return 0;
}
