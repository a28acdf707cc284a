// Warm-started impulse solves (ArticulatedParams::warm_start) with an iterative solver that uses the
// incoming solution as its initial guess, as the PETSc drivers do.
#include "cg_solver.hpp"
#include "physics/articulated_scenes.hpp"
#include "physics/articulated_step.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

using namespace physics;

namespace {

struct Run {
  double worst_error = 0, max_speed = 0;
  long   iterations = 0;
  bool   converged  = true;
};

Run run_chain(double angle, bool warm, int steps)
{
  ChainOptions opt;
  opt.links = 20, opt.angle = angle;
  ArticulatedScene  scene = make_chain(opt);
  ArticulatedParams params;
  params.dt           = 1.0 / 60;
  params.warm_start   = warm;
  ArticulatedSolver s = make_articulated_solver(scene, params);
  CgBlockSolver     cg;
  cg.pattern = &s.pattern, cg.rtol = 1e-8;
  auto lin = cg.adapter();
  Run  out;
  for (int n = 0; n < steps; ++n) {
    const ArticulatedStepReport r = articulated_step(scene, s, params, lin);
    out.converged &= r.converged;
    out.worst_error = std::max(out.worst_error, r.joint_error);
  }
  for (const RigidBody &b : scene.bodies) out.max_speed = std::max(out.max_speed, b.velocity.norm());
  out.iterations = cg.total_iterations;
  return out;
}

} // namespace

TEST_CASE("warm-started CG: rigid rod keeps its period 2 pi sqrt(I_O/(m g d))", "[articulated][warm]")
{
  ChainOptions opt;
  opt.links = 1, opt.link_length = 1.0, opt.link_width = 0.05, opt.angle = 0.05;
  ArticulatedScene  scene = make_chain(opt);
  ArticulatedParams params;
  params.dt           = 1e-3;
  params.warm_start   = true;
  ArticulatedSolver s = make_articulated_solver(scene, params);
  CgBlockSolver     cg;
  cg.pattern               = &s.pattern;
  auto                lin  = cg.adapter();
  double              prev = scene.bodies[0].position.x();
  std::vector<double> crossings;
  for (int n = 0; n < 5000; ++n) {
    REQUIRE(articulated_step(scene, s, params, lin).converged);
    const double cur = scene.bodies[0].position.x();
    if (prev < 0 && cur >= 0) crossings.push_back((n + prev / (prev - cur)) * params.dt);
    prev = cur;
  }
  REQUIRE(crossings.size() >= 2);
  const double T = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  const double m = opt.mass_first, l = opt.link_length, w = opt.link_width, d = l / 2;
  const double I_O = m * (l * l + w * w) / 12 + m * d * d;
  CHECK(std::abs(T / (2 * M_PI * std::sqrt(I_O / (m * 9.81 * d))) - 1) < 0.005);
}

TEST_CASE("warm start: a chain hanging at rest stays at rest with far fewer CG iterations",
          "[articulated][warm]")
{
  const Run cold = run_chain(0.0, false, 120);
  const Run warm = run_chain(0.0, true, 120);
  std::printf("20-link chain at rest, CG to 1e-8, 120 steps: %ld iterations cold, %ld warm\n",
              cold.iterations, warm.iterations);
  CHECK(cold.converged);
  CHECK(warm.converged);
  CHECK(warm.worst_error < 1e-6);
  CHECK(warm.max_speed < 1e-6);
  CHECK(warm.iterations < 0.5 * cold.iterations);
}

TEST_CASE("warm start on a swinging chain: still converged every step", "[articulated][warm]")
{
  const Run warm = run_chain(0.8, true, 200);
  CHECK(warm.converged);
  CHECK(warm.worst_error < 1e-6);
}
