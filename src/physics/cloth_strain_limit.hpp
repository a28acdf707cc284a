// Strain limiting of the stretch springs (Provot 1995, "Deformation constraints in a mass-spring model to
// describe rigid cloth behavior"): after a step, a stretch spring longer than (1 + max_strain) times its
// rest length has its ends pulled together, in inverse proportion to their masses (a pinned end does not
// move), sweep after sweep until every stretch spring is within the bound or the sweeps run out; the
// velocities take the change of position over the step, so the next step starts from the limited state.
// Woven cloth stretches a few percent and then locks; a mass-spring cloth pinned at two points instead
// concentrates its whole weight on the springs at the pins. The sweeps read and write the full state in a
// fixed order, so processes that hold the same replicated state stay identical. With the sphere collider on,
// each sweep ends by projecting particles out of it again, and particles left on it lose their velocity
// into it: the collider wins over the springs. The sweeps are Gauss-Seidel on the springs, and like
// Gauss-Seidel they move an excess spread over a large region (where a falling cloth lands on the
// sphere and stops) one spring at a time: StrainLimit::omega over-relaxes them.
#pragma once
#include "physics/cloth_model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace physics {

struct StrainLimit {
  double max_strain = 0;   // 0: off; else the largest relative elongation a stretch spring keeps
  int    max_sweeps = 200; // Gauss-Seidel sweeps over the stretch springs at most (they stop when within)
  // Over-relaxation of each correction, in [1, 2): a spring over its bound is shortened omega times its
  // excess, to below the bound (never below half its rest length). 1 is Provot's projection; where a
  // large region is over the bound (the cloth landing on the sphere) the sweeps pass the excess on to
  // the region's edge in far fewer sweeps with omega near 2, as SOR does for linear systems.
  double omega = 1;
};

struct StrainLimitReport {
  int    sweeps    = 0;     // sweeps made
  int    corrected = 0;     // spring corrections made, over all sweeps
  double max_ratio = 0;     // largest length / rest length after the last sweep
  bool   capped    = false; // the sweeps ran out while the last one still corrected springs
};

std::string validate_strain_limit(const StrainLimit &limit);

// One stretch spring as the sweeps read it: a visit reads a, b and trigger, a correction the rest.
struct LimitedSpring {
  int    a = 0, b = 0;
  double rest_length = 0;
  double lmax        = 0; // the bound on its length, (1 + max_strain) rest_length
  double trigger     = 0; // squared length above which it is corrected: (lmax (1 + slack))^2
  double wa = 0, wb = 0;  // inverse masses, 0 for a pinned end
  double w = 0;           // wa + wb
};

// What the limiting of one cloth needs besides its state, made once: the stretch springs that can move
// (both ends pinned: left out) with their inverse masses, the stretch springs each particle ends, and
// the work space of the sweeps, so that a step's limiting allocates and gathers nothing. Made from the
// cloth's springs, masses and pins, which must not change after (as for make_cloth_system); the bounds
// follow the StrainLimit of each call.
struct StrainLimiter {
  int                        particles = 0; // of the cloth it was made for
  size_t                     springs   = 0; // all springs of that cloth (a check it is the same cloth)
  std::vector<LimitedSpring> stretch;       // in the cloth's order
  std::vector<int>           stretch_all;   // every stretch spring (index), pinned or not, for max_ratio
  // the stretch springs particle p ends, as bits of the sweeps' visiting sets (bit k of word k / 64 for
  // spring k of `stretch`): mark_bits[e] to OR into word mark_word[e], e in first[p] .. first[p + 1)
  std::vector<int>           first, mark_word;
  std::vector<std::uint64_t> mark_bits;
  double                     bounds_for = 0; // the max_strain the springs' lmax and trigger hold
  // work space
  std::vector<Eigen::Vector3d> before;
  std::vector<std::uint64_t>   visit, next;
  std::vector<int>             moved, projected, candidates, moved_in;
};

StrainLimiter make_strain_limiter(const Cloth &cloth);

// Limits the stretch springs of `cloth` after a step of length dt (velocities corrected by dx / dt).
StrainLimitReport limit_strain(Cloth &cloth, const StrainLimit &limit, double dt);

// The same with a limiter made for this cloth earlier (remade if it was made for a cloth of another
// size): the same corrections in the same order, bit for bit.
StrainLimitReport limit_strain(Cloth &cloth, StrainLimiter &limiter, const StrainLimit &limit, double dt);

} // namespace physics
