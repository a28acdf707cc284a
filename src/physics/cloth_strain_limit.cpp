#include "physics/cloth_strain_limit.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace physics {

std::string validate_strain_limit(const StrainLimit &limit)
{
  if (!(limit.max_strain >= 0) || !std::isfinite(limit.max_strain))
    return "strain limit must be non-negative and finite (0: off)";
  if (limit.max_sweeps < 1) return "strain limiting needs at least one sweep";
  return "";
}

namespace {

void project_out_of_sphere(Cloth &cloth)
{
  const double r2 = cloth.sphere.radius * cloth.sphere.radius;
  for (int p = 0; p < cloth.particle_count(); ++p) {
    if (cloth.fixed[p]) continue;
    const Eigen::Vector3d d = cloth.position[p] - cloth.sphere.centre;
    if (!(d.squaredNorm() < r2)) continue; // most particles are off the sphere: no square root for them
    const double dist = d.norm();
    if (dist < cloth.sphere.radius && dist > 0)
      cloth.position[p] = cloth.sphere.centre + cloth.sphere.radius / dist * d;
  }
}

// One stretch spring as the sweeps need it, gathered once per call: the sweeps visit every spring
// every time (most are within the bound), so what a visit reads is what the limiting costs.
struct LimitedSpring {
  int    a, b;
  double lmax;    // the bound on its length
  double trigger; // squared length above which it is corrected: (lmax (1 + slack))^2
  double wa, wb;  // inverse masses, 0 for a pinned end
};

} // namespace

StrainLimitReport limit_strain(Cloth &cloth, const StrainLimit &limit, double dt)
{
  StrainLimitReport report;
  if (limit.max_strain <= 0) return report;
  const int                          np     = cloth.particle_count();
  const std::vector<Eigen::Vector3d> before = cloth.position;
  const double                       bound  = 1 + limit.max_strain;
  // a sweep stops the limiting once no spring exceeds the bound by more than this (relative): the
  // corrections of one sweep disturb the neighbours a little, exact satisfaction would take forever
  const double               slack = 1e-3 * limit.max_strain;
  std::vector<LimitedSpring> stretch;
  for (const Spring &sp : cloth.springs) {
    if (sp.kind != SpringKind::Stretch) continue;
    const double wa = cloth.fixed[sp.a] ? 0.0 : 1.0 / cloth.mass[sp.a],
                 wb = cloth.fixed[sp.b] ? 0.0 : 1.0 / cloth.mass[sp.b];
    if (wa + wb == 0) continue; // both ends pinned: nothing can move
    const double lmax = bound * sp.rest_length, trigger = lmax * (1 + slack);
    stretch.push_back({sp.a, sp.b, lmax, trigger * trigger, wa, wb});
  }
  for (int sweep = 0; sweep < limit.max_sweeps; ++sweep) {
    bool         over  = false;
    const size_t count = stretch.size();
    // alternate the direction so that no corner is favoured
    for (size_t q = 0; q < count; ++q) {
      const LimitedSpring &sp = stretch[sweep % 2 ? count - 1 - q : q];
      Eigen::Vector3d      d  = cloth.position[sp.b] - cloth.position[sp.a];
      if (!(d.squaredNorm() > sp.trigger)) continue;
      const double          l    = d.norm();
      const Eigen::Vector3d corr = (l - sp.lmax) / (l * (sp.wa + sp.wb)) * d;
      cloth.position[sp.a] += sp.wa * corr;
      cloth.position[sp.b] -= sp.wb * corr;
      over = true;
      report.corrected++;
    }
    // the collider wins over the springs: a sweep must not pull particles back into the sphere
    if (cloth.sphere.enabled) project_out_of_sphere(cloth);
    report.sweeps = sweep + 1;
    if (!over) break;
  }
  for (int p = 0; p < np; ++p) {
    if (cloth.fixed[p]) continue;
    cloth.velocity[p] += (cloth.position[p] - before[p]) / dt;
    if (!cloth.sphere.enabled) continue;
    // on the sphere: no velocity into it (as the collider's own projection leaves it)
    const Eigen::Vector3d d    = cloth.position[p] - cloth.sphere.centre;
    const double          dist = d.norm();
    if (dist > 0 && dist <= cloth.sphere.radius * (1 + 1e-12)) {
      const double vn = cloth.velocity[p].dot(d) / dist;
      if (vn < 0) cloth.velocity[p] -= vn / dist * d;
    }
  }
  for (const Spring &sp : cloth.springs)
    if (sp.kind == SpringKind::Stretch)
      report.max_ratio =
        std::max(report.max_ratio, (cloth.position[sp.b] - cloth.position[sp.a]).norm() / sp.rest_length);
  return report;
}

} // namespace physics
