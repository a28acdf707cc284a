// Implicit Euler step of a cloth (Baraff & Witkin 1998): with K = -df/dx and D = -df/dv assembled from
// every spring (cloth_springs.hpp),
//   (M + h D + h^2 K) dv = h (f - h K v),   v += dv,   x += h v,
// then particles inside the sphere collider are projected to its surface and lose their inward normal
// velocity. Pinned particles keep dv = 0: their rows and columns hold only M, so the matrix stays SPD.
// The 3x3-block pattern (one diagonal block per particle, two blocks per spring) is built once; values
// are refilled in place every step.
#pragma once
#include "physics/block_solver.hpp"
#include "physics/cloth_model.hpp"

#include <vector>

namespace physics {

struct ClothParams {
  double dt      = 1.0 / 60.0;
  bool   choi_ko = true; // false keeps the exact (possibly indefinite) Jacobian of compressed springs
};

struct ClothSystem {
  int                 n_particles = 0;
  std::vector<int>    block_row, block_col; // blocks 0..n-1: diagonal; then (a,b), (b,a) per spring
  std::vector<double> block_values, rhs, dv;
};

struct ClothStepReport {
  int    iterations = 0;
  bool   converged  = true;
  bool   breakdown  = false;
  int    contacts   = 0; // particles projected out of the sphere
  double max_stretch = 0;
};

ClothSystem make_cloth_system(const Cloth &cloth);

std::string validate_params(const ClothParams &params);

// Fills block_values and rhs for the cloth's current state.
void assemble_cloth_system(const Cloth &cloth, const ClothParams &params, ClothSystem &sys);

// Net force on every particle (gravity, springs, damping), zero on pinned particles.
void cloth_forces(const Cloth &cloth, std::vector<Eigen::Vector3d> &forces);

ClothStepReport cloth_step(Cloth &cloth, ClothSystem &sys, const ClothParams &params, const BlockLinearSolver &solver);

} // namespace physics
