// Implicit Euler step of a cloth (Baraff & Witkin 1998): with K = -df/dx and D = -df/dv assembled from
// every spring (cloth_springs.hpp),
//   (M + h D + h^2 K) dv = h (f - h K v),   v += dv,   x += h v,
// then particles inside the sphere collider are projected to its surface and lose their inward normal
// velocity; then, if asked, the stretch springs are strain-limited (cloth_strain_limit.hpp). Pinned particles keep dv = 0: their rows and columns hold only M, so the matrix stays SPD.
// The 3x3-block pattern (one diagonal block per particle, one or two blocks per spring) is built once; values
// are refilled in place every step.
#pragma once
#include "physics/block_solver.hpp"
#include "physics/cloth_model.hpp"
#include "physics/cloth_strain_limit.hpp"

#include <functional>
#include <vector>

namespace physics {

struct ClothParams {
  double      dt      = 1.0 / 60.0;
  bool        choi_ko = true; // false keeps the exact (possibly indefinite) Jacobian of compressed springs
  StrainLimit strain_limit;   // off by default: applied after the position update and the sphere
  // A clock in seconds (the driver's wall or CPU timer) to time the strain limiting with; null: untimed.
  double (*clock)() = nullptr;
};

// The blocks one process assembles. On one process: every row and both triangles. With replicated state
// on several processes (src/sim/replicated_solver.h) each one assembles only the rows it owns,
// so it visits only the springs that touch them, and lists only the off-diagonal blocks its matrix type
// stores (one per spring with upper-triangle storage), which is all the COO refill then reads.
struct ClothSystem {
  int              n_particles = 0;
  std::vector<int> block_row,
    block_col; // the COO list: own particles' diagonal blocks, then the kept spring blocks
  std::vector<int> diagonal_block;  // per particle: its diagonal block, -1 when its row is not assembled here
  std::vector<int> springs;         // springs with at least one end in an assembled row
  std::vector<int> stretch_springs; // those of them along grid edges (for the stretch check)
  std::vector<int> block_ab, block_ba; // per listed spring: block of (a, b) and of (b, a), -1 when not listed
  std::vector<double> block_values, rhs, dv; // rhs: 3 per particle, meaningful in assembled rows only
  StrainLimiter       strain_limiter;        // over every stretch spring: each process limits the whole state
};
struct ClothStepReport {
  int  iterations = 0;
  bool converged  = true;
  bool breakdown  = false;
  int  contacts   = 0; // particles projected out of the sphere
  // the largest stretch ratio: over every stretch spring where the strain limit ran, else over those
  // this process assembles (all of them on one process); the driver takes the maximum over processes
  double max_stretch   = 0;
  int    strain_sweeps = 0; // strain-limiting sweeps made (0 when off)
  // the limiting used all its sweeps and the last one still corrected springs: the bound may not hold
  bool   strain_capped  = false;
  double strain_seconds = 0; // the limiting's time, by ClothParams::clock
};

// Every row, both triangles.
ClothSystem make_cloth_system(const Cloth &cloth);

// The rows of particles with own[p] != 0; of their off-diagonal blocks, those with keep(row, col) true
// (physics numbering). Throws std::invalid_argument if own has the wrong size.
ClothSystem make_cloth_system(const Cloth &cloth, const std::vector<char> &own,
                              const std::function<bool(int row, int col)> &keep);

std::string validate_params(const ClothParams &params);

// Fills block_values and rhs for the cloth's current state.
void assemble_cloth_system(const Cloth &cloth, const ClothParams &params, ClothSystem &sys);

// Net force on every particle (gravity, springs, damping), zero on pinned particles.
void cloth_forces(const Cloth &cloth, std::vector<Eigen::Vector3d> &forces);

ClothStepReport cloth_step(Cloth &cloth, ClothSystem &sys, const ClothParams &params,
                           const BlockLinearSolver &solver);

} // namespace physics
