#include "sim/sim_driver.h"

#include "physics/vtk_writer.hpp"

#include <cstdio>
#include <cstring>

PetscErrorCode DriverOutputFromOptions(MPI_Comm comm, DriverOutput *out)
{
  PetscFunctionBegin;
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-steps", &out->steps, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-progress_every", &out->progress_every, nullptr));
  PetscCall(
    PetscOptionsGetString(nullptr, nullptr, "-vtk", out->vtk_prefix, sizeof out->vtk_prefix, &out->vtk));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-vtk_every", &out->vtk_every, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-dump_matrix", out->dump_path, sizeof out->dump_path,
                                  &out->dump));
  PetscCheck(out->steps >= 0 && out->progress_every >= 1 && out->vtk_every >= 1, comm,
             PETSC_ERR_ARG_OUTOFRANGE, "-steps must be >= 0, -progress_every and -vtk_every >= 1");
  int rank;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (out->vtk && !rank) physics::make_prefix_folder(out->vtk_prefix); // a prefix in a new folder
  PetscFunctionReturn(0);
}

PetscErrorCode DriverWriteFrame(MPI_Comm comm, DriverOutput *out, PetscInt step, double time,
                                const std::function<bool(const std::string &path)> &write)
{
  int rank;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (!out->vtk || rank != 0 || step % out->vtk_every != 0) PetscFunctionReturn(0);
  char path[PETSC_MAX_PATH_LEN + 32];
  std::snprintf(path, sizeof path, "%s_%05d.vtu", out->vtk_prefix, (int)step);
  PetscCheck(write(path), PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot write %s", path);
  const char *base = std::strrchr(path, '/');
  out->frames.push_back({base ? base + 1 : path, time});
  PetscCheck(physics::write_pvd(std::string(out->vtk_prefix) + ".pvd", out->frames), PETSC_COMM_SELF,
             PETSC_ERR_FILE_OPEN, "cannot write %s.pvd", out->vtk_prefix);
  PetscFunctionReturn(0);
}

void DriverAddSolverSummary(SummaryLine &s, const ReplicatedSolver &rs, const StepCosts &costs)
{
  const double step_ms_total = costs.total_ms(), per = costs.steps.empty() ? 0.0 : 1.0 / costs.steps.size();
  s.add("ms_per_step", step_ms_total * per);
  s.add("solve_ms", rs.solve_ms * per);
  s.add("setvalues_ms", rs.setvalues_ms * per);
  // Everything but the PETSc calls (replicated on every rank): assembly, prediction, updates.
  s.add("physics_ms", (step_ms_total - rs.solve_ms - rs.setvalues_ms) * per);
  s.add("cg_its", rs.solves ? (double)rs.iterations / rs.solves : 0.0);
  s.add("diverged_solves", rs.diverged_solves);
  s.add("timer", std::string(rs.cpu_timer ? "cpu" : "wall"));
  costs.add_late(s);
}
