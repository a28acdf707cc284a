// Strain limiting of the stretch springs (Provot 1995, "Deformation constraints in a mass-spring model to
// describe rigid cloth behavior"): after a step, a stretch spring longer than (1 + max_strain) times its
// rest length has its ends pulled together, in inverse proportion to their masses (a pinned end does not
// move), sweep after sweep until every stretch spring is within the bound or the sweeps run out; the
// velocities take the change of position over the step, so the next step starts from the limited state.
// Woven cloth stretches a few percent and then locks; a mass-spring cloth pinned at two points instead
// concentrates its whole weight on the springs at the pins. The sweeps read and write the full state in a
// fixed order, so processes that hold the same replicated state stay identical. With the sphere collider on,
// each sweep ends by projecting particles out of it again, and particles left on it lose their velocity
// into it: the collider wins over the springs.
#pragma once
#include "physics/cloth_model.hpp"

#include <string>

namespace physics {

struct StrainLimit {
  double max_strain = 0;   // 0: off; else the largest relative elongation a stretch spring keeps
  int    max_sweeps = 200; // Gauss-Seidel sweeps over the stretch springs at most (they stop when within)
};

struct StrainLimitReport {
  int    sweeps    = 0; // sweeps made
  int    corrected = 0; // spring corrections made, over all sweeps
  double max_ratio = 0; // largest length / rest length after the last sweep
};

std::string validate_strain_limit(const StrainLimit &limit);

// Limits the stretch springs of `cloth` after a step of length dt (velocities corrected by dx / dt).
StrainLimitReport limit_strain(Cloth &cloth, const StrainLimit &limit, double dt);

} // namespace physics
