// The drivers' rule for ending a run (src/sim/run_guard.h): a broken health bound warns, a solve that
// failed or a nonfinite state stops, and energy grown beyond -health_energy_runaway times the bound
// stops a warned run too.
#include <catch2/catch.hpp>

#include "sim/run_guard.h"

#include <cmath>
#include <map>
#include <string>

namespace {

// A scene whose energy scale is 10 J with growth allowed up to half of it: 5 J.
HealthBounds Scene()
{
  HealthBounds b;
  b.energy_scale      = 10;
  b.energy_growth     = 0.5;
  b.inverted_fraction = 0;
  return b;
}

// A guard for Scene() read from the options `opts` (set for the call only).
RunGuard Guard(const std::map<std::string, std::string> &opts = {}, PetscErrorCode *err = nullptr)
{
  RunGuard g;
  for (const auto &kv : opts) PetscOptionsSetValue(nullptr, kv.first.c_str(), kv.second.c_str());
  const PetscErrorCode e = RunGuardFromOptions(PETSC_COMM_SELF, Scene(), &g);
  for (const auto &kv : opts) PetscOptionsClearValue(nullptr, kv.first.c_str());
  if (err) *err = e;
  RunGuardStart(&g, 0.0, 0.0);
  return g;
}

// One step with energy E (and the inverted fraction `inverted`): whether the guard stops the run.
bool Step(RunGuard &g, long long step, double E, double inverted = 0)
{
  StepHealth h;
  h.solver_reason     = KSP_CONVERGED_RTOL;
  h.energy            = E;
  h.inverted_fraction = inverted;
  bool stop           = false;
  REQUIRE(RunGuardCheckStep(PETSC_COMM_SELF, &g, step, h, &stop) == 0);
  return stop;
}

} // namespace

TEST_CASE("run guard: a warned run stops once its energy has run away", "[run_guard]")
{
  RunGuard g = Guard();
  CHECK(g.energy_runaway == 100);
  CHECK_FALSE(Step(g, 1, 4.0)); // within the 5 J allowed
  CHECK(g.status == "ok");
  CHECK_FALSE(Step(g, 2, 6.0)); // over the bound: unstable, warned, integrates on
  CHECK(g.status == "unstable");
  CHECK(g.unstable_steps == 1);
  CHECK_FALSE(Step(g, 3, 499.0)); // 99.8 x the allowed growth: still a warning
  CHECK(g.ended == "completed");
  CHECK(g.exit_code == 0);
  CHECK(Step(g, 4, 501.0)); // beyond 100 x 5 J: the run ends here
  CHECK(g.ended == "runaway@step4");
  CHECK(g.status == "unstable");
  CHECK(g.exit_code == 4);
  CHECK(g.unstable_steps == 3);
}

TEST_CASE("run guard: -health_energy_runaway sets the factor or turns the stop off", "[run_guard]")
{
  SECTION("a factor of 10")
  {
    RunGuard g = Guard({{"-health_energy_runaway", "10"}});
    CHECK_FALSE(Step(g, 1, 49.0));
    CHECK(Step(g, 2, 51.0));
    CHECK(g.ended == "runaway@step2");
  }
  SECTION("negative: never")
  {
    RunGuard g = Guard({{"-health_energy_runaway", "-1"}});
    CHECK(std::isnan(g.energy_runaway));
    CHECK_FALSE(Step(g, 1, 1e300));
    CHECK(g.status == "unstable");
    CHECK(g.ended == "completed");
    CHECK(g.exit_code == 0);
  }
  SECTION("below 1 and NaN are refused")
  {
    PetscErrorCode err = 0;
    Guard({{"-health_energy_runaway", "0.5"}}, &err);
    CHECK(err == PETSC_ERR_ARG_OUTOFRANGE);
    Guard({{"-health_energy_runaway", "nan"}}, &err);
    CHECK(err == PETSC_ERR_ARG_OUTOFRANGE);
  }
  SECTION("with the energy check off there is no runaway either")
  {
    RunGuard g = Guard({{"-health_energy_growth", "-1"}});
    CHECK_FALSE(Step(g, 1, 1e300));
    CHECK(g.status == "ok");
  }
}

TEST_CASE("run guard: -on_unstable stop ends the run at the first bound broken", "[run_guard]")
{
  RunGuard g = Guard({{"-on_unstable", "stop"}});
  CHECK(Step(g, 1, 1e6)); // far beyond the runaway bound, but the first bound broken says it
  CHECK(g.ended == "unstable@step1");
  CHECK(g.exit_code == 4);
}

TEST_CASE("run guard: inverted elements warn, whatever the energy figure's absence", "[run_guard]")
{
  RunGuard g = Guard();
  CHECK_FALSE(Step(g, 1, NAN, 0.01)); // no energy measured: no runaway, the inversion warns
  CHECK(g.status == "unstable");
  CHECK(g.ended == "completed");
}
