// What the time-stepping programs on a ReplicatedSolver (articulated, cloth) share: the output options
// (-steps, -progress_every, -vtk PREFIX, -vtk_every, -dump_matrix FILE), writing a frame plus the .pvd
// collection, and the solver part of the summary line.
#pragma once
#include "sim/replicated_solver.h"
#include "sim/summary.h"

#include <functional>
#include <string>
#include <utility>
#include <vector>

struct DriverOutput {
  PetscInt  steps = 100, progress_every = 1, vtk_every = 1;
  PetscBool vtk = PETSC_FALSE, dump = PETSC_FALSE;
  char      vtk_prefix[PETSC_MAX_PATH_LEN] = "", dump_path[PETSC_MAX_PATH_LEN] = "";
  std::vector<std::pair<std::string, double>> frames; // written so far: file name, time
};

// Reads the options above (defaults: the struct's) and checks them.
PetscErrorCode DriverOutputFromOptions(MPI_Comm comm, DriverOutput *out);

// On rank 0, every vtk_every steps: writes PREFIX_<step>.vtu with `write` (false = failure) and rewrites
// PREFIX.pvd. No-op without -vtk.
PetscErrorCode DriverWriteFrame(MPI_Comm comm, DriverOutput *out, PetscInt step, double time,
                                const std::function<bool(const std::string &path)> &write);

// Timing and solver fields of the summary from the steps run: ms_per_step, solve_ms, setvalues_ms,
// physics_ms (the rest), cg_its (per solve), diverged_solves, timer (wall or cpu, rs.cpu_timer),
// late_ms_per_step and late_cg_its.
void DriverAddSolverSummary(SummaryLine &s, const ReplicatedSolver &rs, const StepCosts &costs);
