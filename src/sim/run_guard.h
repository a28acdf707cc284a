// How a simulation driver's run ends, and why, shared by fem, cloth and articulated: after every step
// the driver hands RunGuardCheckStep what it saw (the step's solver outcome, whether the state is
// finite, its health figures) and stops when told to.
//
//   - A solve that ended with a negative KSPConvergedReason stops the run (status=solver_failed) with
//     a one-line message and exit code 2; -on_solver_failure continue keeps integrating (studies of
//     solver settings), counting the failures, and the run then ends with status=solver_failed, exit 0.
//   - A nonfinite state always stops the run (status=nonfinite, exit code 3).
//   - The health check: energy growth beyond a bound the scene states (relative to the scene's energy
//     scale), more inverted elements than at the start (fem), a spring stretched beyond a bound
//     (cloth), a joint left open by more than a bound (articulated). A step that fails it turns
//     status into `unstable` with a one-line warning (the first time); -on_unstable stop also stops
//     the run there (exit code 4). The bounds can be set with -health_energy_growth,
//     -health_inverted_fraction, -health_max_stretch, -health_joint_error (a negative value turns
//     that check off).
//   - A run that blows up stops whatever -on_unstable says: energy grown beyond -health_energy_runaway
//     (default 100) times the growth the scene allows ends it (ended=runaway@stepN, status=unstable, exit
//     code 4). A warned run integrates on only while its figures still mean something: integrating on,
//     the thesis's fixed 30 Jacobi iterations on linear_38k end 200 steps at 1e59 J with half the
//     elements inverted (docs/run_health.md).
//
// The summary line gets status= (ok, unstable, solver_failed, nonfinite), ended= (completed or what
// stopped the run, at which step) and the counts.
#pragma once
#include "sim/summary.h"

#include <petscksp.h>

#include <cmath>
#include <string>

// What a scene states as healthy (NaN: the check does not apply to this driver).
struct HealthBounds {
  double energy_scale      = NAN; // J: the scene's natural energy (weight x size, initial energy)
  double energy_growth     = NAN; // largest E - E0 allowed, as a multiple of energy_scale
  double inverted_fraction = NAN; // largest rise of the inverted element fraction over the initial one
  double max_stretch       = NAN; // largest length / rest length of a spring
  double joint_error       = NAN; // m: largest gap a joint may keep at the end of a step
};

// What a driver saw in one step (NaN: not measured).
struct StepHealth {
  KSPConvergedReason solver_reason =
    KSP_CONVERGED_ITERATING; // negative: the step's result rests on a failed solve
  std::string solver_detail; // with the failure: what in the solver failed (pc_failure.h), or empty
  bool        finite            = true;
  double      energy            = NAN;
  double      inverted_fraction = NAN;
  double      max_stretch       = NAN;
  double      joint_error       = NAN;
};

struct RunGuard {
  HealthBounds bounds;
  bool         stop_on_solver_failure = true, stop_on_unstable = false;
  // growth of the energy, in multiples of the bound's (energy_growth x energy_scale), that stops a warned
  // run (NaN: never)
  double             energy_runaway = 100;
  double             energy0 = NAN, inverted0 = 0;
  std::string        status = "ok", ended = "completed";
  long long          solver_failures = 0, unstable_steps = 0;
  KSPConvergedReason first_failure = KSP_CONVERGED_ITERATING;
  int                exit_code     = 0;
};

// Reads -on_solver_failure, -on_unstable, -health_energy_runaway and the -health_* overrides of the
// scene's bounds.
PetscErrorCode RunGuardFromOptions(MPI_Comm comm, const HealthBounds &scene, RunGuard *g);

// The state before the first step: E0 and the initial inverted fraction (NaN: not measured).
void RunGuardStart(RunGuard *g, double energy0, double inverted_fraction0);

// Checks one step (every rank passes the same figures); *stop tells the driver to end the run now.
// Prints the one-line message or warning on rank 0.
PetscErrorCode RunGuardCheckStep(MPI_Comm comm, RunGuard *g, long long step, const StepHealth &h, bool *stop);

// status=, ended=, solver_failures=, unstable_steps=.
void RunGuardAddSummary(SummaryLine &s, const RunGuard &g);
