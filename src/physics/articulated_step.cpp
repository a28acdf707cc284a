#include "physics/articulated_step.hpp"

#include <cmath>

namespace physics {

ArticulatedSolver make_articulated_solver(const ArticulatedScene &scene, const ArticulatedParams &params)
{
  ArticulatedSolver s;
  s.pattern     = build_joint_matrix_pattern(scene);
  s.regularised = params.regularise_from_start;
  return s;
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

void apply_joint_impulses(ArticulatedScene &scene, const ArticulatedSolver &s, const std::vector<double> &impulses)
{
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d p(impulses[3 * j], impulses[3 * j + 1], impulses[3 * j + 2]);
    if (jt.body_a != kWorld) apply_impulse(scene.bodies[jt.body_a], s.inverse_inertia[jt.body_a], s.arm_a[j], p);
    if (jt.body_b != kWorld) apply_impulse(scene.bodies[jt.body_b], s.inverse_inertia[jt.body_b], s.arm_b[j], -p);
  }
}

// C(x~): joint errors at the positions the bodies would reach after dt with their current velocities.
// Returns max |C|.
double predicted_errors(const ArticulatedScene &scene, double dt, ArticulatedSolver &s)
{
  const size_t nb = scene.bodies.size(), nj = scene.joints.size();
  for (size_t i = 0; i < nb; ++i) {
    const RigidBody &b         = scene.bodies[i];
    s.predicted_position[i]    = b.position + dt * b.velocity;
    s.predicted_orientation[i] = rotated(b.orientation, b.angular_velocity, dt);
  }
  auto at = [&](int body, const Eigen::Vector3d &anchor) -> Eigen::Vector3d {
    return body == kWorld ? anchor : Eigen::Vector3d(s.predicted_position[body] + s.predicted_orientation[body] * anchor);
  };
  double worst2 = 0;
  for (size_t j = 0; j < nj; ++j) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d e  = at(jt.body_a, jt.anchor_a) - at(jt.body_b, jt.anchor_b);
    for (int k = 0; k < 3; ++k) s.errors[3 * j + k] = e[k];
    worst2 = std::max(worst2, e.squaredNorm());
  }
  return std::sqrt(worst2);
}

// Rotation, world inverse inertia and joint arms for the given orientations (the bodies' own when null).
void update_frames(const ArticulatedScene &scene, ArticulatedSolver &s, const std::vector<Eigen::Quaterniond> *orientations)
{
  if (s.inverse_inertia_body.size() != scene.bodies.size()) {
    s.inverse_inertia_body.resize(scene.bodies.size());
    for (size_t i = 0; i < scene.bodies.size(); ++i) s.inverse_inertia_body[i] = scene.bodies[i].inertia_body.inverse();
  }
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    const RigidBody &b = scene.bodies[i];
    s.rotation[i]      = (orientations ? (*orientations)[i] : b.orientation).toRotationMatrix();
    s.inverse_inertia[i] = s.rotation[i] * s.inverse_inertia_body[i] * s.rotation[i].transpose();
  }
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint &jt = scene.joints[j];
    s.arm_a[j]          = jt.body_a == kWorld ? Eigen::Vector3d::Zero() : Eigen::Vector3d(s.rotation[jt.body_a] * jt.anchor_a);
    s.arm_b[j]          = jt.body_b == kWorld ? Eigen::Vector3d::Zero() : Eigen::Vector3d(s.rotation[jt.body_b] * jt.anchor_b);
  }
}

// Relative connector velocities u_a - u_b (J v) with the current arms; returns max |J v|.
double velocity_errors(const ArticulatedScene &scene, ArticulatedSolver &s)
{
  auto velocity = [&](int body, const Eigen::Vector3d &arm) -> Eigen::Vector3d {
    if (body == kWorld) return Eigen::Vector3d::Zero();
    const RigidBody &b = scene.bodies[body];
    return b.velocity + b.angular_velocity.cross(arm);
  };
  double worst2 = 0;
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d u  = velocity(jt.body_a, s.arm_a[j]) - velocity(jt.body_b, s.arm_b[j]);
    for (int k = 0; k < 3; ++k) s.errors[3 * j + k] = u[k];
    worst2 = std::max(worst2, u.squaredNorm());
  }
  return std::sqrt(worst2);
}

// The initial guess for a solve: `guess` if warm starting with one of the right size, otherwise zero.
void set_initial_guess(const ArticulatedParams &params, const std::vector<double> &guess, std::vector<double> &x)
{
  if (params.warm_start && guess.size() == x.size()) std::copy(guess.begin(), guess.end(), x.begin());
  else std::fill(x.begin(), x.end(), 0.0);
}

} // namespace

ArticulatedStepReport articulated_step(ArticulatedScene &scene, ArticulatedSolver &s, const ArticulatedParams &params, const BlockLinearSolver &linear_solver)
{
  ArticulatedStepReport report;
  const double          dt = params.dt;
  const size_t          nj = scene.joints.size();
  const size_t          nb = scene.bodies.size();

  if (nj == 0) {
    for (RigidBody &b : scene.bodies) apply_unconstrained_velocity_update(b, scene.gravity, dt), advance_positions(b, dt);
    report.converged = true;
    return report;
  }

  s.rotation.resize(nb), s.inverse_inertia.resize(nb), s.predicted_position.resize(nb), s.predicted_orientation.resize(nb);
  s.arm_a.resize(nj), s.arm_b.resize(nj);
  s.rhs.resize(3 * nj), s.impulses.resize(3 * nj), s.errors.resize(3 * nj);
  s.correction_sum.assign(3 * nj, 0.0);
  update_frames(scene, s, nullptr);

  // With the physics replicated over processes, each fills only the block rows its solver part takes.
  if (!linear_solver.needed_rows.empty() && s.fill_groups.size() != s.pattern.body_of_group.size())
    s.fill_groups = joint_groups_of_rows(s.pattern, linear_solver.needed_rows);
  auto refill = [&]() {
    fill_joint_matrix(scene, s.pattern, s.regularised ? params.regularisation : 0.0, s.inverse_inertia, s.arm_a, s.arm_b, s.block_values,
                      linear_solver.needed_rows.empty() ? nullptr : &s.fill_groups);
    linear_solver.set_matrix(s.block_values);
  };
  auto switch_to_regularised = [&]() {
    s.regularised            = true;
    report.singular_detected = true;
    refill();
  };
  // A breakdown on the unregularised matrix means A is (numerically) singular: regularise and retry.
  auto solve = [&](const std::vector<double> &guess) {
    set_initial_guess(params, guess, s.impulses);
    LinearSolveResult r = linear_solver.solve(s.rhs, s.impulses);
    report.linear_solves++, report.linear_iterations += r.iterations;
    if (r.breakdown && !s.regularised) {
      switch_to_regularised();
      set_initial_guess(params, guess, s.impulses);
      r = linear_solver.solve(s.rhs, s.impulses);
      report.linear_solves++, report.linear_iterations += r.iterations;
    }
    for (double v : s.impulses)
      if (!std::isfinite(v)) {
        std::fill(s.impulses.begin(), s.impulses.end(), 0.0);
        break;
      }
  };
  static const std::vector<double> no_guess;

  refill();

  report.velocity_error = velocity_errors(scene, s);
  if (params.velocity_stabilisation && report.velocity_error > 0) {
    for (size_t k = 0; k < 3 * nj; ++k) s.rhs[k] = -s.errors[k];
    solve(s.last_stabilisation);
    apply_joint_impulses(scene, s, s.impulses);
    s.last_stabilisation = s.impulses;
  }

  for (size_t i = 0; i < nb; ++i) apply_unconstrained_velocity_update(scene.bodies[i], s.rotation[i], scene.gravity, dt);

  double error = predicted_errors(scene, dt, s);
  while (error >= params.joint_tol && report.corrections < params.max_corrections) {
    if (params.refresh_matrix && report.corrections > 0) {
      // Newton-like variant: matrix and impulse arms at the predicted orientations.
      update_frames(scene, s, &s.predicted_orientation);
      refill();
    }
    for (size_t k = 0; k < 3 * nj; ++k) s.rhs[k] = -s.errors[k] / dt;
    solve(report.corrections == 0 ? s.last_correction : no_guess);
    apply_joint_impulses(scene, s, s.impulses);
    report.corrections++;
    double next = predicted_errors(scene, dt, s);
    // The linearised impulse overshoots when bodies turn far in one step (light links between heavy
    // ones): take back half of it until the error falls (a backtracking line search on max |C|).
    for (int halving = 0; next > error && halving < params.max_halvings; ++halving) {
      for (double &p : s.impulses) p *= -0.5;
      apply_joint_impulses(scene, s, s.impulses);
      for (double &p : s.impulses) p = -p;
      next = predicted_errors(scene, dt, s);
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

  for (size_t i = 0; i < nb; ++i) {
    scene.bodies[i].position    = s.predicted_position[i];
    scene.bodies[i].orientation = s.predicted_orientation[i];
  }
  // The positions are the last predicted ones, so the last predicted error is the joint error.
  report.joint_error = error;
  report.converged   = report.joint_error < params.joint_tol;
  return report;
}

} // namespace physics
