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
Cloth corner_pinned_cloth(int n, bool sphere, double sphere_y)
{
  ClothOptions opt;
  opt.n                = n;
  Cloth cloth          = make_cloth(opt);
  cloth.sphere.enabled = sphere;
  cloth.sphere.centre  = Eigen::Vector3d(0, sphere_y, 0);
  return cloth;
}

double worst_stretch(int n, double max_strain, int steps, bool sphere)
{
  Cloth       cloth = corner_pinned_cloth(n, sphere, -0.5);
  ClothSystem sys   = make_cloth_system(cloth);
  auto        ref   = sparse_solver_for(sys);
  auto        lin   = ref.adapter();
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

// A zigzag chain of 30 particles pinned at its first, every spring 20% over its rest length: the excess
// has to leave through the free end, which Gauss-Seidel sweeps do a spring at a time.
Cloth stretched_chain()
{
  const int n = 30;
  Cloth     c;
  for (int p = 0; p < n; ++p) c.position.emplace_back(1.2 * p, 0.3 * (p % 2), 0);
  c.velocity.assign(n, Eigen::Vector3d::Zero());
  c.mass.assign(n, 1.0);
  c.fixed.assign(n, 0);
  c.fixed[0] = 1;
  for (int p = 0; p + 1 < n; ++p)
    c.springs.push_back(
      Spring{p, p + 1, (c.position[p + 1] - c.position[p]).norm() / 1.2, 1.0, SpringKind::Stretch});
  return c;
}

// The limiting as its definition reads: every sweep visits every stretch spring (alternating the
// direction) and ends by projecting every particle out of the sphere; then the velocities take the
// change. limit_strain visits only the springs and particles that can change, and must make exactly
// the same corrections.
int reference_limit(Cloth &cloth, double max_strain, int max_sweeps, double dt, double omega = 1)
{
  const std::vector<Eigen::Vector3d> before = cloth.position;
  std::vector<const Spring *>        stretch;
  for (const Spring &sp : cloth.springs)
    if (sp.kind == SpringKind::Stretch) stretch.push_back(&sp);
  const double bound = 1 + max_strain, slack = 1e-3 * max_strain;
  int          sweeps = 0;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    bool         over = false;
    const size_t n    = stretch.size();
    for (size_t q = 0; q < n; ++q) {
      const Spring   &sp = *stretch[sweep % 2 ? n - 1 - q : q];
      Eigen::Vector3d d  = cloth.position[sp.b] - cloth.position[sp.a];
      const double    l = d.norm(), lmax = bound * sp.rest_length;
      if (!(d.squaredNorm() > (lmax * (1 + slack)) * (lmax * (1 + slack)))) continue;
      const double wa = cloth.fixed[sp.a] ? 0.0 : 1.0 / cloth.mass[sp.a],
                   wb = cloth.fixed[sp.b] ? 0.0 : 1.0 / cloth.mass[sp.b];
      if (wa + wb == 0) continue;
      const double          shorten = std::min(omega * (l - lmax), l - 0.5 * sp.rest_length);
      const Eigen::Vector3d corr    = shorten / (l * (wa + wb)) * d;
      cloth.position[sp.a] += wa * corr;
      cloth.position[sp.b] -= wb * corr;
      over = true;
    }
    for (int p = 0; p < cloth.particle_count(); ++p) {
      if (cloth.fixed[p] || !cloth.sphere.enabled) continue;
      const Eigen::Vector3d d    = cloth.position[p] - cloth.sphere.centre;
      const double          dist = d.norm();
      if (dist < cloth.sphere.radius && dist > 0)
        cloth.position[p] = cloth.sphere.centre + cloth.sphere.radius / dist * d;
    }
    sweeps = sweep + 1;
    if (!over) break;
  }
  for (int p = 0; p < cloth.particle_count(); ++p) {
    if (cloth.fixed[p]) continue;
    cloth.velocity[p] += (cloth.position[p] - before[p]) / dt;
    if (!cloth.sphere.enabled) continue;
    const Eigen::Vector3d d    = cloth.position[p] - cloth.sphere.centre;
    const double          dist = d.norm();
    if (dist > 0 && dist <= cloth.sphere.radius * (1 + 1e-12)) {
      const double vn = cloth.velocity[p].dot(d) / dist;
      if (vn < 0) cloth.velocity[p] -= vn / dist * d;
    }
  }
  return sweeps;
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

TEST_CASE("over-relaxed strain limiting brings a stretched chain within the bound in fewer sweeps",
          "[cloth][strain]")
{
  const auto sweeps_to_bound = [](double omega, double &max_ratio, double &shortest) {
    Cloth       c = stretched_chain();
    StrainLimit limit;
    limit.max_strain = 0.05, limit.max_sweeps = 5000, limit.omega = omega;
    const StrainLimitReport r = limit_strain(c, limit, 0.01);
    max_ratio                 = r.max_ratio;
    shortest                  = 1e300;
    for (const Spring &sp : c.springs)
      shortest = std::min(shortest, (c.position[sp.b] - c.position[sp.a]).norm() / sp.rest_length);
    return r.sweeps;
  };
  double    ratio1, ratio19, shortest1, shortest19;
  const int plain = sweeps_to_bound(1.0, ratio1, shortest1), sor = sweeps_to_bound(1.9, ratio19, shortest19);
  INFO("sweeps " << plain << " (omega 1), " << sor << " (omega 1.9); shortest " << shortest1 << ", "
                 << shortest19);
  CHECK(plain < 5000);
  CHECK(sor * 4 < plain);
  for (double r : {ratio1, ratio19}) CHECK(r <= 1.05 * (1 + 1e-4));
  CHECK(shortest1 >= 1.0 - 1e-12); // plain: a corrected spring ends at its bound, above its rest length
  CHECK(shortest19 >= 0.5);        // over-relaxed: below the bound, never below half the rest length
}

TEST_CASE("strain limiting says when its sweeps ran out before the bound", "[cloth][strain]")
{
  // the stretched chain, limited with too few sweeps and with enough
  const auto limited = [](int max_sweeps) {
    Cloth       c = stretched_chain();
    StrainLimit limit;
    limit.max_strain = 0.05, limit.max_sweeps = max_sweeps;
    return limit_strain(c, limit, 0.01);
  };
  const StrainLimitReport few = limited(3), enough = limited(5000);
  CHECK(few.sweeps == 3);
  CHECK(few.capped);
  CHECK(few.max_ratio > 1.05 * (1 + 1e-3)); // the bound not met: what capped reports
  CHECK(enough.sweeps < 5000);
  CHECK(!enough.capped);
  CHECK(enough.max_ratio <= 1.05 * (1 + 1e-4));
  // one sweep allowed and nothing to correct: that sweep was the last, but nothing ran out
  ClothOptions opt;
  opt.n            = 6;
  Cloth       rest = make_cloth(opt);
  StrainLimit one;
  one.max_strain = 0.05, one.max_sweeps = 1;
  const StrainLimitReport calm = limit_strain(rest, one, 0.01);
  CHECK(calm.sweeps == 1);
  CHECK(!calm.capped);
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
  p.strain_limit.max_sweeps = 10;
  for (double omega : {0.9, 2.0, std::nan("")}) {
    p.strain_limit.omega = omega;
    CHECK(validate_params(p).find("over-relaxation") != std::string::npos);
  }
}

TEST_CASE("strain limiting makes the corrections of full sweeps over every spring", "[cloth][strain]")
{
  const double omega = GENERATE(1.0, 1.9);
  INFO("omega " << omega);
  // a cloth that hangs from its pins onto the sphere: many sweeps per step (up to the cap), the
  // sphere's projection fighting the springs, so the visited sets change from sweep to sweep
  Cloth        cloth = corner_pinned_cloth(24, true, -0.3);
  ClothSystem  sys   = make_cloth_system(cloth);
  auto         ref   = sparse_solver_for(sys);
  auto         lin   = ref.adapter();
  ClothParams  free_params; // the step without the limit, then each limiter on its own copy
  const double dt = free_params.dt, max_strain = 0.03;
  StrainLimit  limit;
  limit.max_strain = max_strain;
  limit.max_sweeps = omega == 1 ? 60 : 12; // over-relaxed sweeps reach the bound sooner: cap them sooner
  limit.omega      = omega;
  int capped       = 0;
  for (int s = 0; s < 40; ++s) {
    REQUIRE(cloth_step(cloth, sys, free_params, lin).converged);
    Cloth                   expected = cloth;
    const int               sweeps   = reference_limit(expected, max_strain, limit.max_sweeps, dt, omega);
    const StrainLimitReport got      = limit_strain(cloth, limit, dt);
    INFO("step " << s);
    CHECK(got.sweeps == sweeps);
    capped += sweeps == limit.max_sweeps;
    size_t differ = 0;
    for (int p = 0; p < cloth.particle_count(); ++p)
      differ += cloth.position[p] != expected.position[p] || cloth.velocity[p] != expected.velocity[p];
    REQUIRE(differ == 0); // the same arithmetic in the same order: bit for bit
  }
  CHECK(capped > 0); // the case the visiting sets are for
}

TEST_CASE("a strain limiter made once limits step after step as limit_strain does", "[cloth][strain]")
{
  // the limiter keeps its springs, bounds and work space between calls: each call must still make the
  // corrections of a fresh limit_strain, also when the strain limit changes between calls
  Cloth         cloth = corner_pinned_cloth(24, true, -0.3);
  ClothSystem   sys   = make_cloth_system(cloth);
  auto          ref   = sparse_solver_for(sys);
  auto          lin   = ref.adapter();
  ClothParams   free_params;
  StrainLimiter limiter = make_strain_limiter(cloth);
  StrainLimiter unmade; // made for no cloth: remade on its first call
  Cloth         other = cloth;
  for (int s = 0; s < 30; ++s) {
    REQUIRE(cloth_step(cloth, sys, free_params, lin).converged);
    other.position = cloth.position, other.velocity = cloth.velocity;
    StrainLimit limit;
    limit.max_strain                 = s < 15 ? 0.03 : 0.05;
    limit.max_sweeps                 = 60;
    Cloth                   fresh    = cloth;
    const StrainLimitReport expected = limit_strain(fresh, limit, free_params.dt);
    const StrainLimitReport got      = limit_strain(cloth, limiter, limit, free_params.dt);
    const StrainLimitReport remade   = limit_strain(other, unmade, limit, free_params.dt);
    INFO("step " << s);
    CHECK(got.sweeps == expected.sweeps);
    CHECK(got.corrected == expected.corrected);
    CHECK(got.max_ratio == expected.max_ratio);
    CHECK(remade.corrected == expected.corrected);
    size_t differ = 0;
    for (int p = 0; p < cloth.particle_count(); ++p)
      differ += cloth.position[p] != fresh.position[p] || cloth.velocity[p] != fresh.velocity[p] ||
                other.position[p] != fresh.position[p];
    REQUIRE(differ == 0);
  }
  CHECK(unmade.particles == cloth.particle_count());
}
