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
  if (!(limit.omega >= 1 && limit.omega < 2)) return "strain limiting's over-relaxation must be in [1, 2)";
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

} // namespace

StrainLimiter make_strain_limiter(const Cloth &cloth)
{
  StrainLimiter l;
  const int     np = cloth.particle_count();
  l.particles      = np;
  l.springs        = cloth.springs.size();
  for (size_t k = 0; k < cloth.springs.size(); ++k) {
    const Spring &sp = cloth.springs[k];
    if (sp.kind != SpringKind::Stretch) continue;
    l.stretch_all.push_back((int)k);
    const double wa = cloth.fixed[sp.a] ? 0.0 : 1.0 / cloth.mass[sp.a],
                 wb = cloth.fixed[sp.b] ? 0.0 : 1.0 / cloth.mass[sp.b];
    if (wa + wb == 0) continue; // both ends pinned: nothing can move
    LimitedSpring ls;
    ls.a = sp.a, ls.b = sp.b, ls.rest_length = sp.rest_length, ls.wa = wa, ls.wb = wb, ls.w = wa + wb;
    l.stretch.push_back(ls);
  }
  // the springs of each particle in increasing order, those in one word of bits merged: a grid
  // particle's four springs fall into two words, so marking them is two independent ORs
  const int                     count = (int)l.stretch.size();
  std::vector<std::vector<int>> incident(np);
  for (int k = 0; k < count; ++k)
    incident[l.stretch[k].a].push_back(k), incident[l.stretch[k].b].push_back(k);
  l.first.assign(np + 1, 0);
  for (int p = 0; p < np; ++p) {
    l.first[p] = (int)l.mark_word.size();
    for (int k : incident[p]) {
      const std::uint64_t bit = std::uint64_t(1) << (k & 63);
      if ((int)l.mark_word.size() > l.first[p] && l.mark_word.back() == k >> 6) l.mark_bits.back() |= bit;
      else l.mark_word.push_back(k >> 6), l.mark_bits.push_back(bit);
    }
  }
  l.first[np]        = (int)l.mark_word.size();
  const size_t words = ((size_t)count + 63) / 64;
  l.visit.assign(words, 0);
  l.next.assign(words, 0);
  l.moved_in.assign(np, -1);
  l.before.resize(np);
  return l;
}

StrainLimitReport limit_strain(Cloth &cloth, const StrainLimit &limit, double dt)
{
  if (limit.max_strain <= 0) return StrainLimitReport();
  StrainLimiter limiter = make_strain_limiter(cloth);
  return limit_strain(cloth, limiter, limit, dt);
}

StrainLimitReport limit_strain(Cloth &cloth, StrainLimiter &limiter, const StrainLimit &limit, double dt)
{
  StrainLimitReport report;
  if (limit.max_strain <= 0) return report;
  const int np = cloth.particle_count();
  if (limiter.particles != np || limiter.springs != cloth.springs.size())
    limiter = make_strain_limiter(cloth);
  std::vector<LimitedSpring> &stretch = limiter.stretch;
  const double                omega   = limit.omega;
  if (limiter.bounds_for != limit.max_strain) {
    const double bound = 1 + limit.max_strain;
    // a sweep stops the limiting once no spring exceeds the bound by more than this (relative): the
    // corrections of one sweep disturb the neighbours a little, exact satisfaction would take forever
    const double slack = 1e-3 * limit.max_strain;
    for (LimitedSpring &sp : stretch) {
      const double lmax = bound * sp.rest_length, trigger = lmax * (1 + slack);
      sp.lmax = lmax, sp.trigger = trigger * trigger;
    }
    limiter.bounds_for = limit.max_strain;
  }
  std::vector<Eigen::Vector3d> &before = limiter.before;
  std::copy(cloth.position.begin(), cloth.position.end(), before.begin());
  // A spring can be over the bound when a sweep reaches it only if one of its ends moved since the
  // sweep before visited it: one that was within the bound then and kept both ends is still within,
  // one that was over was corrected and moved its ends. So a sweep visits, in the order of a sweep
  // over all springs, the springs with an end moved in the last sweep or earlier in this one (a bit
  // per spring, set as ends move), and makes the same corrections as the sweep over all of them: the
  // cloth's stretch spends most of its sweeps on the few springs at the pins and on the sphere.
  const int                         count = (int)stretch.size();
  const std::vector<int>           &first = limiter.first, &mark_word = limiter.mark_word;
  const std::vector<std::uint64_t> &mark_bits = limiter.mark_bits;
  const size_t                      words     = ((size_t)count + 63) / 64;
  std::vector<std::uint64_t>       &visit = limiter.visit, &next = limiter.next;
  std::fill(visit.begin(), visit.end(), ~std::uint64_t(0));
  if (count % 64) visit[words - 1] = (std::uint64_t(1) << (count % 64)) - 1;
  const auto mark = [&](std::vector<std::uint64_t> &bits, int p) {
    for (int e = first[p]; e < first[p + 1]; ++e) bits[mark_word[e]] |= mark_bits[e];
  };
  // `moved` lists each particle a correction moved in this sweep once (moved_in[p] == sweep): marking
  // its springs once is enough, since marks stay set for the rest of the sweep (a particle of the
  // pulled corner is moved by most of its springs' corrections, several times a sweep). Likewise a
  // particle can be inside the sphere after a sweep only if that sweep moved it, or if the projection
  // before put it there (the projected point can round to just inside): the projection looks at those
  // only, each once, after the first sweep.
  std::vector<int> &moved = limiter.moved, &projected = limiter.projected, &candidates = limiter.candidates,
                   &moved_in = limiter.moved_in;
  std::fill(moved_in.begin(), moved_in.end(), -1);
  projected.clear();
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
        const double l = d.norm();
        // omega times the excess (with omega = 1: the excess, exactly); over-relaxed, never below half
        // the rest length: a spring stretched past omega / (omega - 1) lmax would be turned inside out
        const double          shorten = std::min(omega * (l - sp.lmax), l - 0.5 * sp.rest_length);
        const Eigen::Vector3d corr    = shorten / (l * sp.w) * d;
        cloth.position[sp.a] += sp.wa * corr;
        cloth.position[sp.b] -= sp.wb * corr;
        for (int p : {sp.a, sp.b})
          if (moved_in[p] != sweep) moved_in[p] = sweep, moved.push_back(p), mark(visit, p);
        over = true;
        report.corrected++;
      }
    }
    // the collider wins over the springs: a sweep must not pull particles back into the sphere
    if (cloth.sphere.enabled) {
      candidates = moved;
      for (int p : projected)
        if (moved_in[p] != sweep) candidates.push_back(p);
      projected.clear();
      project_out_of_sphere(cloth, sweep > 0 ? &candidates : nullptr, projected);
      for (int p : projected)
        if (moved_in[p] != sweep) moved.push_back(p); // each once: projected lists a particle once
    }
    report.sweeps = sweep + 1;
    if (!over) break;
    report.capped = sweep + 1 == limit.max_sweeps;
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
  report.max_ratio = max_stretch_ratio(cloth, limiter.stretch_all);
  return report;
}

} // namespace physics
