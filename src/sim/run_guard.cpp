#include "sim/run_guard.h"

#include <cstdio>

namespace {

// -NAME VALUE overrides *bound; a negative value turns the check off (NaN).
PetscErrorCode OverrideBound(MPI_Comm comm, const char *name, double *bound)
{
  PetscReal v;
  PetscBool set;
  PetscFunctionBegin;
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, name, &v, &set));
  // NaN would turn the check off as a negative value does, without saying so
  PetscCheck(!set || !PetscIsNanReal(v), comm, PETSC_ERR_ARG_OUTOFRANGE,
             "%s nan: give a bound, or a negative number to turn the check off", name);
  if (set) *bound = v < 0 ? NAN : (double)v;
  PetscFunctionReturn(0);
}

PetscErrorCode GetChoice(MPI_Comm comm, const char *name, const char *a, const char *b, bool *is_a)
{
  char      buf[32] = "";
  PetscBool set;
  PetscFunctionBegin;
  PetscCall(PetscOptionsGetString(nullptr, nullptr, name, buf, sizeof buf, &set));
  if (!set) PetscFunctionReturn(0);
  const std::string v = buf;
  PetscCheck(v == a || v == b, comm, PETSC_ERR_ARG_WRONG, "%s must be %s or %s, got %s", name, a, b, buf);
  *is_a = v == a;
  PetscFunctionReturn(0);
}

// The failed solve's reason, with what failed inside it where the driver knows (StepHealth::solver_detail).
std::string Reason(const StepHealth &h)
{
  std::string r = KSPConvergedReasons[h.solver_reason];
  if (!h.solver_detail.empty()) r += ", " + h.solver_detail;
  return r;
}

} // namespace

PetscErrorCode RunGuardFromOptions(MPI_Comm comm, const HealthBounds &scene, RunGuard *g)
{
  PetscFunctionBegin;
  g->bounds = scene;
  PetscCall(GetChoice(comm, "-on_solver_failure", "stop", "continue", &g->stop_on_solver_failure));
  PetscCall(GetChoice(comm, "-on_unstable", "stop", "warn", &g->stop_on_unstable));
  PetscCall(OverrideBound(comm, "-health_energy_growth", &g->bounds.energy_growth));
  PetscCall(OverrideBound(comm, "-health_inverted_fraction", &g->bounds.inverted_fraction));
  PetscCall(OverrideBound(comm, "-health_joint_error", &g->bounds.joint_error));
  PetscCall(OverrideBound(comm, "-health_max_stretch", &g->bounds.max_stretch));
  PetscCall(OverrideBound(comm, "-health_energy_runaway", &g->energy_runaway));
  PetscCheck(!(g->energy_runaway < 1), comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-health_energy_runaway %g: a multiple >= 1 of the energy growth allowed, or negative (never)",
             g->energy_runaway);
  PetscFunctionReturn(0);
}

void RunGuardStart(RunGuard *g, double energy0, double inverted_fraction0)
{
  g->energy0   = energy0;
  g->inverted0 = std::isfinite(inverted_fraction0) ? inverted_fraction0 : 0.0;
}

PetscErrorCode RunGuardCheckStep(MPI_Comm comm, RunGuard *g, long long step, const StepHealth &h, bool *stop)
{
  char msg[256];
  PetscFunctionBegin;
  *stop = false;
  if (!h.finite) { // whatever the options: nothing after this step would mean anything
    g->status    = "nonfinite";
    g->exit_code = 3;
    std::snprintf(msg, sizeof msg, "nonfinite_state@step%lld", step);
    g->ended = msg;
    PetscCall(PetscPrintf(comm, "error: step %lld left a nonfinite state (NaN or Inf)%s; stopping\n", step,
                          h.solver_reason < 0 ? (" after the solver's " + Reason(h)).c_str() : ""));
    *stop = true;
    PetscFunctionReturn(0);
  }
  if (h.solver_reason < 0) {
    if (!g->solver_failures) g->first_failure = h.solver_reason;
    ++g->solver_failures;
    g->status = "solver_failed";
    if (g->stop_on_solver_failure) {
      g->exit_code = 2;
      std::snprintf(msg, sizeof msg, "solver_failure@step%lld", step);
      g->ended = msg;
      PetscCall(PetscPrintf(
        comm,
        "error: the linear solve of step %lld failed (%s); stopping (-on_solver_failure continue integrates on)\n",
        step, Reason(h).c_str()));
      *stop = true;
      PetscFunctionReturn(0);
    }
  }
  // the health check: the first bound broken, with its figures
  const HealthBounds &b     = g->bounds;
  msg[0]                    = 0;
  const bool energy_checked = std::isfinite(b.energy_growth) && std::isfinite(b.energy_scale) &&
                              b.energy_scale > 0 && std::isfinite(h.energy) && std::isfinite(g->energy0);
  const double growth = energy_checked ? h.energy - g->energy0 : 0.0;
  if (energy_checked && growth > b.energy_growth * b.energy_scale)
    std::snprintf(msg, sizeof msg, "energy grew by %.4g J (from %.4g), more than %.3g x the scene's %.4g J",
                  growth, g->energy0, b.energy_growth, b.energy_scale);
  else if (std::isfinite(b.inverted_fraction) && std::isfinite(h.inverted_fraction) &&
           h.inverted_fraction > g->inverted0 + b.inverted_fraction)
    std::snprintf(msg, sizeof msg, "%.3g%% of the elements are inverted (%.3g%% at the start)",
                  100 * h.inverted_fraction, 100 * g->inverted0);
  else if (std::isfinite(b.max_stretch) && std::isfinite(h.max_stretch) && h.max_stretch > b.max_stretch)
    std::snprintf(msg, sizeof msg, "a spring is stretched to %.4g x its rest length (bound %.3g)",
                  h.max_stretch, b.max_stretch);
  else if (std::isfinite(b.joint_error) &&
           h.joint_error > b.joint_error) // an infinite gap too; NaN: no figure
    std::snprintf(msg, sizeof msg, "a joint is %.4g m open after the step (bound %.3g m)", h.joint_error,
                  b.joint_error);
  if (msg[0]) {
    ++g->unstable_steps;
    if (g->status == "ok") g->status = "unstable";
    if (g->stop_on_unstable) {
      g->exit_code = 4;
      PetscCall(
        PetscPrintf(comm, "error: unstable at step %lld: %s; stopping (-on_unstable stop)\n", step, msg));
      std::snprintf(msg, sizeof msg, "unstable@step%lld", step);
      g->ended = msg;
      *stop    = true;
    } else if (energy_checked && std::isfinite(g->energy_runaway) &&
               growth > g->energy_runaway * b.energy_growth * b.energy_scale) {
      // blown up: integrating on would only print figures that mean nothing
      g->exit_code = 4;
      PetscCall(
        PetscPrintf(comm,
                    "error: step %lld ran away: energy grew by %.4g J (from %.4g), more than %.3g x the "
                    "%.4g J the scene allows; stopping (-health_energy_runaway -1 integrates on)\n",
                    step, growth, g->energy0, g->energy_runaway, b.energy_growth * b.energy_scale));
      std::snprintf(msg, sizeof msg, "runaway@step%lld", step);
      g->ended = msg;
      *stop    = true;
    } else if (g->unstable_steps == 1) {
      PetscCall(PetscPrintf(
        comm, "warning: unstable at step %lld: %s (-on_unstable stop ends the run there)\n", step, msg));
    }
  }
  PetscFunctionReturn(0);
}

void RunGuardAddSummary(SummaryLine &s, const RunGuard &g)
{
  s.add("solver_failures", g.solver_failures);
  s.add("unstable_steps", g.unstable_steps);
  s.add("ended", g.ended);
  s.add("status", g.status);
}
