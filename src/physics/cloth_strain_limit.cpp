#include "physics/cloth_strain_limit.hpp"

#include <algorithm>
#include <cstdint>
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

// Projects the particles of `candidates` (each once; all particles when null) that are inside the
// sphere onto it, and appends the ones it moved to `moved`.
void project_out_of_sphere(Cloth &cloth, const std::vector<int> *candidates, std::vector<int> &moved)
{
  const double r2      = cloth.sphere.radius * cloth.sphere.radius;
  const auto   project = [&](int p) {
    if (cloth.fixed[p]) return;
    const Eigen::Vector3d d = cloth.position[p] - cloth.sphere.centre;
    if (!(d.squaredNorm() < r2)) return; // most particles are off the sphere: no square root for them
    const double dist = d.norm();
    if (dist < cloth.sphere.radius && dist > 0) {
      cloth.position[p] = cloth.sphere.centre + cloth.sphere.radius / dist * d;
      moved.push_back(p);
    }
  };
  if (!candidates)
    for (int p = 0; p < cloth.particle_count(); ++p) project(p);
  else
    for (int p : *candidates) project(p);
}

// One stretch spring as the sweeps need it, gathered once per call: what a visit reads is what the
// limiting costs (a sweep visits thousands of springs, most of them within the bound).
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
  // A spring can be over the bound when a sweep reaches it only if one of its ends moved since the
  // sweep before visited it: one that was within the bound then and kept both ends is still within,
  // one that was over was corrected and moved its ends. So a sweep visits, in the order of a sweep
  // over all springs, the springs with an end moved in the last sweep or earlier in this one (a bit
  // per spring, set as ends move), and makes the same corrections as the sweep over all of them: the
  // cloth's stretch spends most of its sweeps on the few springs at the pins and on the sphere.
  const int        count = (int)stretch.size();
  std::vector<int> first(np + 1, 0), incident(2 * (size_t)count);
  for (const LimitedSpring &sp : stretch) first[sp.a + 1]++, first[sp.b + 1]++;
  for (int p = 0; p < np; ++p) first[p + 1] += first[p];
  {
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (int k = 0; k < count; ++k) incident[fill[stretch[k].a]++] = k, incident[fill[stretch[k].b]++] = k;
  }
  const size_t               words = ((size_t)count + 63) / 64;
  std::vector<std::uint64_t> visit(words, ~std::uint64_t(0)), next(words, 0);
  if (count % 64) visit[words - 1] = (std::uint64_t(1) << (count % 64)) - 1;
  const auto mark = [&](std::vector<std::uint64_t> &bits, int p) {
    for (int e = first[p]; e < first[p + 1]; ++e)
      bits[incident[e] >> 6] |= std::uint64_t(1) << (incident[e] & 63);
  };
  // Likewise a particle can be inside the sphere after a sweep only if that sweep moved it, or if the
  // projection before put it there (the projected point can round to just inside): the projection
  // looks at those only, each once, after the first sweep.
  std::vector<int> moved, projected, candidates, stamp(np, -1);
  for (int sweep = 0; sweep < limit.max_sweeps; ++sweep) {
    bool       over = false;
    const bool down = sweep % 2; // alternate the direction so that no corner is favoured
    moved.clear();
    for (size_t wi = 0; wi < words; ++wi) {
      const size_t  w      = down ? words - 1 - wi : wi;
      std::uint64_t passed = 0; // the bits of word w this sweep has reached
      for (;;) {
        // the springs still ahead in this word, including any a correction just marked
        const std::uint64_t ahead = visit[w] & ~passed;
        if (!ahead) break;
        const int           bit  = down ? 63 - __builtin_clzll(ahead) : __builtin_ctzll(ahead);
        const std::uint64_t mask = std::uint64_t(1) << bit;
        passed |= down ? ~(mask - 1) : (mask << 1) - 1; // this bit and all before it in the sweep's order
        const LimitedSpring &sp = stretch[64 * w + bit];
        Eigen::Vector3d      d  = cloth.position[sp.b] - cloth.position[sp.a];
        if (!(d.squaredNorm() > sp.trigger)) continue;
        const double          l    = d.norm();
        const Eigen::Vector3d corr = (l - sp.lmax) / (l * (sp.wa + sp.wb)) * d;
        cloth.position[sp.a] += sp.wa * corr;
        cloth.position[sp.b] -= sp.wb * corr;
        for (int p : {sp.a, sp.b}) moved.push_back(p), mark(visit, p);
        over = true;
        report.corrected++;
      }
    }
    // the collider wins over the springs: a sweep must not pull particles back into the sphere
    if (cloth.sphere.enabled) {
      candidates.clear();
      for (const std::vector<int> *list : {&moved, &projected})
        for (int p : *list)
          if (stamp[p] != sweep) stamp[p] = sweep, candidates.push_back(p);
      projected.clear();
      project_out_of_sphere(cloth, sweep > 0 ? &candidates : nullptr, projected);
      moved.insert(moved.end(), projected.begin(), projected.end());
    }
    report.sweeps = sweep + 1;
    if (!over) break;
    std::fill(next.begin(), next.end(), 0);
    for (int p : moved) mark(next, p);
    visit.swap(next);
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
