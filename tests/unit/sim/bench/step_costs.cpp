// The drivers' late_* summary fields (src/sim/summary.h, StepCosts): means over the second half of the
// steps run, iterations per solve.
#include <catch2/catch.hpp>

#include "sim/summary.h"

#include <map>
#include <string>

namespace {

std::map<std::string, double> Late(const StepCosts &costs)
{
  SummaryLine s;
  costs.add_late(s);
  std::map<std::string, double> out;
  for (const auto &kv : s.fields) out[kv.first] = std::stod(kv.second);
  return out;
}

} // namespace

TEST_CASE("late_* fields: the second half of the steps", "[bench][summary]")
{
  StepCosts costs;
  SECTION("an even count: the last half")
  {
    for (double ms : {400.0, 100.0, 30.0, 20.0}) costs.add(ms, ms == 400.0 ? 32 : 10, 1);
    costs.steps[3].iterations = 14;
    const auto late           = Late(costs);
    CHECK(late.at("late_ms_per_step") == Approx(25.0));
    CHECK(late.at("late_cg_its") == Approx(12.0));
  }
  SECTION("an odd count: the middle step belongs to the late half")
  {
    for (double ms : {300.0, 50.0, 40.0}) costs.add(ms, 20, 1);
    costs.steps[1].iterations = 10;
    costs.steps[2].iterations = 16;
    const auto late           = Late(costs);
    CHECK(late.at("late_ms_per_step") == Approx(45.0));
    CHECK(late.at("late_cg_its") == Approx(13.0));
  }
  SECTION("one step: that step")
  {
    costs.add(7.5, 3, 1);
    const auto late = Late(costs);
    CHECK(late.at("late_ms_per_step") == Approx(7.5));
    CHECK(late.at("late_cg_its") == Approx(3.0));
  }
  SECTION("iterations per solve, steps with several solves or none")
  {
    costs.add(1, 100, 1);
    costs.add(1, 100, 1);
    costs.add(1, 12, 3); // 4 per solve
    costs.add(1, 0, 0);  // a step that solved nothing (no contact, no constraint)
    CHECK(Late(costs).at("late_cg_its") == Approx(4.0));
  }
  SECTION("no steps (a run stopped before its first): zeros, not NaN")
  {
    const auto late = Late(costs);
    CHECK(late.at("late_ms_per_step") == 0.0);
    CHECK(late.at("late_cg_its") == 0.0);
  }
}
