// One time step of an articulated scene with impulse-based ball joints (Bender & Schmitt 2006, Weinstein,
// Teran & Fedkiw 2006), every impulse solve going through J M^-1 J^T lambda = rhs:
//   1. A = J M^-1 J^T at the current orientations (pattern fixed, values refilled).
//   2. Velocity post-stabilisation of the previous step: solve A mu = -J v once and apply (J v = 0).
//   3. Free velocity update (gravity, implicit gyroscopic term).
//   4. Prediction/correction: predict connector positions after dt with the current velocities, C(x~);
//      if max |C| >= joint_tol, solve A lambda = -C(x~)/dt, apply the impulses, predict again.
//   5. Advance positions with the corrected velocities: the joint error after the step is the last
//      predicted one.
// Kinematic loops can make A singular. A solver breakdown (CG: indefinite or zero curvature) marks the
// scene singular; from then on A + eps * diag(A) is used (Tikhonov regularisation, eps =
// regularisation), which keeps A SPD and the prediction/correction loop still drives C to zero wherever
// the joints are consistent.
#pragma once
#include "physics/block_solver.hpp"
#include "physics/joint_matrix.hpp"

#include <functional>

namespace physics {

struct ArticulatedParams {
  double dt                     = 1.0 / 60.0;
  double joint_tol              = 1e-6; // metres
  int    max_corrections        = 20;
  int    max_halvings           = 8;    // backtracking steps when a correction makes the error grow
  double regularisation         = 1e-6; // relative to the diagonal, used once A is found singular
  bool   velocity_stabilisation = true;
  bool   regularise_from_start  = false;
  bool   refresh_matrix = true; // refill A at the predicted orientations for every correction after the first
  // Initial guesses from the previous step: its stabilisation impulses for the stabilisation solve, the sum
  // of its correction impulses for the first correction, zero for later corrections. Only used if the
  // linear solver takes the incoming solution as its initial guess (the PETSc drivers then set
  // KSPSetInitialGuessNonzero). Off by default: it pays when the structure hangs nearly at rest (the same
  // impulses hold it up every step) and costs iterations when it swings (see docs/articulated.md).
  bool warm_start = false;
};

struct ArticulatedStepReport {
  int    corrections       = 0;     // impulse solves in the prediction/correction loop
  int    linear_solves     = 0;     // all solves, stabilisation included
  int    linear_iterations = 0;     // summed over the solves
  double velocity_error    = 0;     // max |J v| before stabilisation
  double joint_error       = 0;     // max |C| after the step
  bool   converged         = false; // joint_error < joint_tol
  bool   singular_detected = false; // this step found A singular and switched to regularisation
  bool   stalled           = false; // a correction could not reduce the error
  int    halvings          = 0;     // impulses halved back by the line search (each costs a prediction)
  // failed solves the step recovered from by solving again: the breakdown that switched it to the
  // regularised matrix, and warm starts that broke down (a guess far worse than zero: DIVERGED_DTOL at
  // iteration 0) and were solved again from zero
  int recovered_solves = 0;
};

// How the work of a step is split over processes that each hold the whole scene (the PETSc drivers with
// several ranks, src/sim/replicated_solver.h). A process advances only its active bodies (those of
// its own joints) and evaluates joint errors only for its own joints; a joint's impulse (the solve returns
// all of them) is applied to every active end, in joint order, so a body active on two processes gets the
// same state on both, bit for bit. Bodies that are not active keep stale values. max_over_processes turns
// the process's max |C| into the global one (an all-reduce), so that every process takes the same
// decisions (another correction, a halving). Each body is counted (for energies and output) by exactly one
// process. Empty lists and masks: one process does everything.
struct ArticulatedWorkSplit {
  std::vector<int>              own_joints;                // increasing
  std::vector<int>              active_bodies;             // increasing
  std::vector<int>              impulse_joints;            // joints with an active end, increasing
  std::vector<char>             body_active, body_counted; // per body
  std::function<double(double)> max_over_processes;
};

// The split for process `process` when joint j belongs to process joint_process[j]: the active bodies are
// those of its joints, a body is counted by the process of its lowest-numbered joint, and bodies without
// joints are active and counted on process 0. Throws std::invalid_argument on a wrong-sized list.
ArticulatedWorkSplit split_articulated_work(const ArticulatedScene &scene,
                                            const std::vector<int> &joint_process, int process);

struct ArticulatedSolver {
  JointMatrixPattern   pattern;
  ArticulatedWorkSplit split;       // never made (no body flags): this process does the whole scene
  ArticulatedWorkSplit whole_scene; // the lists for that case, built at the first step
  std::vector<double>  block_values;
  bool                 regularised = false;
  // Warm start: the previous step's stabilisation impulses and summed correction impulses (3 per joint).
  std::vector<double> last_stabilisation, last_correction;
  // Scratch, sized at the first step and reused: no allocation per step after it.
  std::vector<double>          rhs, impulses, errors, correction_sum;
  std::vector<Eigen::Matrix3d> rotation, inverse_inertia; // per body, start-of-step (or predicted) frame
  std::vector<char>            fill_groups;               // bodies whose blocks the solver needs (empty: all)
  std::vector<Eigen::Matrix3d> inverse_inertia_body;      // per body, body frame: inertias are fixed, so
                                                          // inverted once (at the first step)
  std::vector<Eigen::Vector3d>    arm_a, arm_b;           // per joint, world arms of its two ends
  std::vector<Eigen::Vector3d>    predicted_position;     // per body, after dt with the current velocities
  std::vector<Eigen::Quaterniond> predicted_orientation;
};

ArticulatedSolver make_articulated_solver(const ArticulatedScene &scene, const ArticulatedParams &params);

// Empty string if the parameters are usable, otherwise what is wrong.
std::string validate_params(const ArticulatedParams &params);

ArticulatedStepReport articulated_step(ArticulatedScene &scene, ArticulatedSolver &solver,
                                       const ArticulatedParams &params,
                                       const BlockLinearSolver &linear_solver);

} // namespace physics
