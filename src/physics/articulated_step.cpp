#include "physics/articulated_step.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace physics {

ArticulatedSolver make_articulated_solver(const ArticulatedScene &scene, const ArticulatedParams &params)
{
  ArticulatedSolver s;
  s.pattern     = build_joint_matrix_pattern(scene);
  s.regularised = params.regularise_from_start;
  return s;
}

ArticulatedWorkSplit split_articulated_work(const ArticulatedScene &scene,
                                            const std::vector<int> &joint_process, int process)
{
  if (joint_process.size() != scene.joints.size())
    throw std::invalid_argument("split_articulated_work: one process per joint needed");
  ArticulatedWorkSplit w;
  const size_t         nb = scene.bodies.size();
  std::vector<int>     first_joint_process(nb, -1);
  w.body_active.assign(nb, 0);
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint &jt = scene.joints[j];
    for (int b : {jt.body_a, jt.body_b}) {
      if (b == kWorld) continue;
      if (first_joint_process[b] < 0) first_joint_process[b] = joint_process[j];
      if (joint_process[j] == process) w.body_active[b] = 1;
    }
    if (joint_process[j] == process) w.own_joints.push_back((int)j);
  }
  w.body_counted.assign(nb, 0);
  for (size_t i = 0; i < nb; ++i) {
    if (first_joint_process[i] < 0) w.body_active[i] = process == 0; // no joints: process 0 moves it
    w.body_counted[i] = first_joint_process[i] < 0 ? process == 0 : first_joint_process[i] == process;
    if (w.body_active[i]) w.active_bodies.push_back((int)i);
  }
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint &jt = scene.joints[j];
    if ((jt.body_a != kWorld && w.body_active[jt.body_a]) ||
        (jt.body_b != kWorld && w.body_active[jt.body_b]))
      w.impulse_joints.push_back((int)j);
  }
  return w;
}

std::string validate_params(const ArticulatedParams &p)
{
  if (!(p.dt > 0) || !std::isfinite(p.dt)) return "time step must be positive and finite";
  if (!(p.joint_tol > 0)) return "joint tolerance must be positive";
  if (p.max_corrections < 1) return "at least one correction iteration is needed";
  if (p.max_halvings < 0) return "the number of halvings must be non-negative";
  if (!(p.regularisation >= 0)) return "regularisation must be non-negative";
  return "";
}

namespace {

void apply_joint_impulses(ArticulatedScene &scene, const ArticulatedSolver &s, const ArticulatedWorkSplit &w,
                          const std::vector<double> &impulses)
{
  const std::vector<char> &active = w.body_active;
  for (int j : w.impulse_joints) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d p(impulses[3 * j], impulses[3 * j + 1], impulses[3 * j + 2]);
    if (jt.body_a != kWorld && active[jt.body_a])
      apply_impulse(scene.bodies[jt.body_a], s.inverse_inertia[jt.body_a], s.arm_a[j], p);
    if (jt.body_b != kWorld && active[jt.body_b])
      apply_impulse(scene.bodies[jt.body_b], s.inverse_inertia[jt.body_b], s.arm_b[j], -p);
  }
}

double global_max(const ArticulatedWorkSplit &w, double local)
{
  return w.max_over_processes ? w.max_over_processes(local) : local;
}

// C(x~): joint errors at the positions the bodies would reach after dt with their current velocities.
// Returns max |C| over all processes.
double predicted_errors(const ArticulatedScene &scene, double dt, ArticulatedSolver &s,
                        const ArticulatedWorkSplit &w)
{
  for (int i : w.active_bodies) {
    const RigidBody &b         = scene.bodies[i];
    s.predicted_position[i]    = b.position + dt * b.velocity;
    s.predicted_orientation[i] = rotated(b.orientation, b.angular_velocity, dt);
  }
  auto at = [&](int body, const Eigen::Vector3d &anchor) -> Eigen::Vector3d {
    return body == kWorld
             ? anchor
             : Eigen::Vector3d(s.predicted_position[body] + s.predicted_orientation[body] * anchor);
  };
  double worst2 = 0;
  for (int j : w.own_joints) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d e  = at(jt.body_a, jt.anchor_a) - at(jt.body_b, jt.anchor_b);
    for (int k = 0; k < 3; ++k) s.errors[3 * j + k] = e[k];
    worst2 = std::max(worst2, e.squaredNorm());
  }
  return global_max(w, std::sqrt(worst2));
}

// Rotation, world inverse inertia and joint arms for the given orientations (the bodies' own when null),
// for the active bodies and the active ends of their joints.
void update_frames(const ArticulatedScene &scene, ArticulatedSolver &s, const ArticulatedWorkSplit &w,
                   const std::vector<Eigen::Quaterniond> *orientations)
{
  if (s.inverse_inertia_body.size() != scene.bodies.size()) {
    s.inverse_inertia_body.resize(scene.bodies.size());
    for (size_t i = 0; i < scene.bodies.size(); ++i)
      s.inverse_inertia_body[i] = scene.bodies[i].inertia_body.inverse();
  }
  for (int i : w.active_bodies) {
    const RigidBody &b   = scene.bodies[i];
    s.rotation[i]        = (orientations ? (*orientations)[i] : b.orientation).toRotationMatrix();
    s.inverse_inertia[i] = s.rotation[i] * s.inverse_inertia_body[i] * s.rotation[i].transpose();
  }
  const std::vector<char> &active = w.body_active;
  for (int j : w.impulse_joints) {
    const BallJoint &jt = scene.joints[j];
    if (jt.body_a == kWorld) s.arm_a[j].setZero();
    else if (active[jt.body_a]) s.arm_a[j] = s.rotation[jt.body_a] * jt.anchor_a;
    if (jt.body_b == kWorld) s.arm_b[j].setZero();
    else if (active[jt.body_b]) s.arm_b[j] = s.rotation[jt.body_b] * jt.anchor_b;
  }
}

// Relative connector velocities u_a - u_b (J v) with the current arms; returns max |J v| over all processes.
double velocity_errors(const ArticulatedScene &scene, ArticulatedSolver &s, const ArticulatedWorkSplit &w)
{
  auto velocity = [&](int body, const Eigen::Vector3d &arm) -> Eigen::Vector3d {
    if (body == kWorld) return Eigen::Vector3d::Zero();
    const RigidBody &b = scene.bodies[body];
    return b.velocity + b.angular_velocity.cross(arm);
  };
  double worst2 = 0;
  for (int j : w.own_joints) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d u  = velocity(jt.body_a, s.arm_a[j]) - velocity(jt.body_b, s.arm_b[j]);
    for (int k = 0; k < 3; ++k) s.errors[3 * j + k] = u[k];
    worst2 = std::max(worst2, u.squaredNorm());
  }
  return global_max(w, std::sqrt(worst2));
}

// The initial guess for a solve: `guess` if warm starting with one of the right size, otherwise zero.
// Returns whether the guess was taken.
bool set_initial_guess(const ArticulatedParams &params, const std::vector<double> &guess,
                       std::vector<double> &x)
{
  const bool warm = params.warm_start && guess.size() == x.size();
  if (warm) std::copy(guess.begin(), guess.end(), x.begin());
  else std::fill(x.begin(), x.end(), 0.0);
  return warm;
}

} // namespace

ArticulatedStepReport articulated_step(ArticulatedScene &scene, ArticulatedSolver &s,
                                       const ArticulatedParams &params,
                                       const BlockLinearSolver &linear_solver)
{
  ArticulatedStepReport report;
  const double          dt = params.dt;
  const size_t          nj = scene.joints.size();
  const size_t          nb = scene.bodies.size();

  if (nj == 0) {
    for (RigidBody &b : scene.bodies)
      apply_unconstrained_velocity_update(b, scene.gravity, dt), advance_positions(b, dt);
    report.converged = true;
    return report;
  }

  s.rotation.resize(nb), s.inverse_inertia.resize(nb), s.predicted_position.resize(nb),
    s.predicted_orientation.resize(nb);
  s.arm_a.resize(nj), s.arm_b.resize(nj);
  s.rhs.resize(3 * nj), s.impulses.resize(3 * nj), s.errors.resize(3 * nj);
  s.correction_sum.assign(3 * nj, 0.0);
  // A split that was made has a flag per body; a process whose share holds no body (more processes
  // than joints) still takes part in every max over the processes (it was taken for "no split" and
  // did the whole scene without them: the other processes waited in their reductions for good).
  const bool split = !s.split.body_active.empty();
  if (!split && s.whole_scene.body_active.size() != nb)
    s.whole_scene = split_articulated_work(scene, std::vector<int>(nj, 0), 0);
  const ArticulatedWorkSplit &w = split ? s.split : s.whole_scene;
  update_frames(scene, s, w, nullptr);

  // With the physics replicated over processes, each fills only the block rows its solver part takes.
  if (!linear_solver.needed_rows.empty() && s.fill_groups.size() != s.pattern.body_of_group.size())
    s.fill_groups = joint_groups_of_rows(s.pattern, linear_solver.needed_rows);
  auto refill = [&]() {
    fill_joint_matrix(scene, s.pattern, s.regularised ? params.regularisation : 0.0, s.inverse_inertia,
                      s.arm_a, s.arm_b, s.block_values,
                      linear_solver.needed_rows.empty() ? nullptr : &s.fill_groups);
    linear_solver.set_matrix(s.block_values);
  };
  auto switch_to_regularised = [&]() {
    s.regularised            = true;
    report.singular_detected = true;
    refill();
  };
  // A breakdown on the unregularised matrix means A is (numerically) singular: regularise and retry.
  // A warm start that breaks down is solved again from zero: the last step's impulses can be far worse
  // than no guess (a loop scene's corrections after the velocity stabilisation: a residual 6e4 times
  // |b|, which PETSc stops as DIVERGED_DTOL before its first iteration). Running out of iterations is
  // no such failure (fixed-iteration runs end that way on purpose) and is not solved twice.
  auto solve = [&](const std::vector<double> &guess) {
    const bool        warm = set_initial_guess(params, guess, s.impulses);
    LinearSolveResult r    = linear_solver.solve(s.rhs, s.impulses);
    report.linear_solves++, report.linear_iterations += r.iterations;
    if (r.breakdown && warm) {
      std::fill(s.impulses.begin(), s.impulses.end(), 0.0);
      r = linear_solver.solve(s.rhs, s.impulses);
      report.linear_solves++, report.linear_iterations += r.iterations, report.recovered_solves++;
    }
    if (r.breakdown && !s.regularised) {
      switch_to_regularised();
      set_initial_guess(params, guess, s.impulses);
      r = linear_solver.solve(s.rhs, s.impulses);
      report.linear_solves++, report.linear_iterations += r.iterations, report.recovered_solves++;
    }
    for (double v : s.impulses)
      if (!std::isfinite(v)) {
        std::fill(s.impulses.begin(), s.impulses.end(), 0.0);
        break;
      }
  };
  static const std::vector<double> no_guess;

  refill();

  report.velocity_error = velocity_errors(scene, s, w);
  if (params.velocity_stabilisation && report.velocity_error > 0) {
    for (size_t k = 0; k < 3 * nj; ++k) s.rhs[k] = -s.errors[k];
    solve(s.last_stabilisation);
    apply_joint_impulses(scene, s, w, s.impulses);
    s.last_stabilisation = s.impulses;
  }

  for (int i : w.active_bodies)
    apply_unconstrained_velocity_update(scene.bodies[i], s.rotation[i], scene.gravity, dt);

  double error = predicted_errors(scene, dt, s, w);
  while (error >= params.joint_tol && report.corrections < params.max_corrections) {
    if (params.refresh_matrix && report.corrections > 0) {
      // Newton-like variant: matrix and impulse arms at the predicted orientations.
      update_frames(scene, s, w, &s.predicted_orientation);
      refill();
    }
    for (size_t k = 0; k < 3 * nj; ++k) s.rhs[k] = -s.errors[k] / dt;
    solve(report.corrections == 0 ? s.last_correction : no_guess);
    apply_joint_impulses(scene, s, w, s.impulses);
    report.corrections++;
    double next = predicted_errors(scene, dt, s, w);
    // The linearised impulse overshoots when bodies turn far in one step (light links between heavy
    // ones): take back half of it until the error falls (a backtracking line search on max |C|).
    for (int halving = 0; next > error && halving < params.max_halvings; ++halving) {
      for (double &p : s.impulses) p *= -0.5;
      apply_joint_impulses(scene, s, w, s.impulses);
      for (double &p : s.impulses) p = -p;
      next = predicted_errors(scene, dt, s, w);
      report.halvings++;
    }
    for (size_t k = 0; k < 3 * nj; ++k) s.correction_sum[k] += s.impulses[k]; // what was applied
    // No fraction of the impulse helps: the linearisation has run out (round-off in very unequal masses,
    // or a step too long for the rotations); stop and report the step unconverged.
    if (next > error) {
      report.stalled = true;
      error          = next;
      break;
    }
    error = next;
  }
  if (report.corrections > 0) s.last_correction.swap(s.correction_sum);

  for (int i : w.active_bodies) {
    scene.bodies[i].position    = s.predicted_position[i];
    scene.bodies[i].orientation = s.predicted_orientation[i];
  }
  // The positions are the last predicted ones, so the last predicted error is the joint error.
  report.joint_error = error;
  report.converged   = report.joint_error < params.joint_tol;
  return report;
}

} // namespace physics
