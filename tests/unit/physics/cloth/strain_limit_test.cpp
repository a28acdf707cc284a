// Strain limiting (cloth_strain_limit.hpp): the stretch springs of a cloth pinned at two corners and
// dropped stay within the bound, the limit is a no-op on a cloth within it, bad settings are refused.
#include "physics/cloth_model.hpp"
#include "physics/cloth_step.hpp"
#include "physics/cloth_strain_limit.hpp"
#include "sparse_solver.hpp"

#include <catch2/catch.hpp>
#include <cmath>

using namespace physics;

namespace {

// The scene's cloth (two pinned corners, the seed's springs) at a resolution a unit test can afford:
// largest stretch over `steps` steps of 1/60 s.
double worst_stretch(int n, double max_strain, int steps, bool sphere)
{
  ClothOptions opt;
  opt.n                = n;
  Cloth cloth          = make_cloth(opt);
  cloth.sphere.enabled = sphere;
  cloth.sphere.centre  = Eigen::Vector3d(0, -0.5, 0);
  ClothSystem sys      = make_cloth_system(cloth);
  auto        ref      = sparse_solver_for(sys);
  auto        lin      = ref.adapter();
  ClothParams params;
  params.strain_limit.max_strain = max_strain;
  double worst                   = 0;
  for (int s = 0; s < steps; ++s) {
    const ClothStepReport r = cloth_step(cloth, sys, params, lin);
    REQUIRE(r.converged);
    worst = std::max(worst, max_stretch_ratio(cloth));
  }
  return worst;
}

} // namespace

TEST_CASE("strain limiting keeps a corner-pinned cloth within a few percent of its rest lengths",
          "[cloth][strain]")
{
  // without it the pinned corners carry the cloth's weight on a few springs and stretch far
  const double free = worst_stretch(24, 0, 40, true);
  CHECK(free > 1.2);
  for (double s : {0.03, 0.1}) {
    INFO("strain limit " << s);
    const double limited = worst_stretch(24, s, 40, true);
    // each sweep ends with the sphere's projection, which may lengthen a spring again a little: the
    // bound holds to a fifth of the limit (measured: 1.086 s at s = 0.1)
    CHECK(limited <= 1 + 1.2 * s);
  }
}

TEST_CASE("strain limiting leaves a cloth within the bound alone", "[cloth][strain]")
{
  ClothOptions opt;
  opt.n             = 6;
  Cloth       cloth = make_cloth(opt);
  const auto  x0    = cloth.position;
  StrainLimit limit;
  limit.max_strain          = 0.05;
  const StrainLimitReport r = limit_strain(cloth, limit, 0.01);
  CHECK(r.corrected == 0);
  CHECK(r.sweeps == 1);
  CHECK(r.max_ratio == Approx(1.0));
  for (size_t p = 0; p < x0.size(); ++p) CHECK((cloth.position[p] - x0[p]).norm() == 0.0);
}

TEST_CASE("strain limiting moves the free end of an overstretched spring and its velocity", "[cloth][strain]")
{
  Cloth c;
  c.position = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0)};
  c.velocity.assign(2, Eigen::Vector3d::Zero());
  c.mass    = {1.0, 1.0};
  c.fixed   = {1, 0};
  c.springs = {Spring{0, 1, 1.0, 100.0, SpringKind::Stretch}};
  StrainLimit limit;
  limit.max_strain          = 0.1;
  const StrainLimitReport r = limit_strain(c, limit, 0.5);
  CHECK(c.position[0].norm() == 0.0);             // pinned
  CHECK(c.position[1].x() == Approx(1.1));        // pulled back to the bound
  CHECK(c.velocity[1].x() == Approx(-0.9 / 0.5)); // the change of position over the step
  CHECK(r.max_ratio == Approx(1.1));
}

TEST_CASE("bad strain limits are refused", "[cloth][strain]")
{
  ClothParams p;
  p.strain_limit.max_strain = -0.1;
  CHECK(validate_params(p).find("strain limit") != std::string::npos);
  p.strain_limit.max_strain = std::nan("");
  CHECK(!validate_params(p).empty());
  p.strain_limit.max_strain = 0.1;
  p.strain_limit.max_sweeps = 0;
  CHECK(validate_params(p).find("sweep") != std::string::npos);
}
