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
  if (!(p.regularisation >= 0)) return "regularisation must be non-negative";
  return "";
}

namespace {

struct Arms {
  std::vector<Eigen::Vector3d> a, b; // world arms of each joint's two ends at the start of the step
};

void apply_joint_impulses(ArticulatedScene &scene, const Arms &arms, const std::vector<Eigen::Matrix3d> &inv_inertia, const std::vector<double> &impulses)
{
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d p(impulses[3 * j], impulses[3 * j + 1], impulses[3 * j + 2]);
    if (jt.body_a != kWorld) apply_impulse(scene.bodies[jt.body_a], inv_inertia[jt.body_a], arms.a[j], p);
    if (jt.body_b != kWorld) apply_impulse(scene.bodies[jt.body_b], inv_inertia[jt.body_b], arms.b[j], -p);
  }
}

// C(x~): joint errors at the positions the bodies would reach after dt with their current velocities.
double predicted_errors(const ArticulatedScene &scene, double dt, std::vector<Eigen::Vector3d> &pos, std::vector<Eigen::Quaterniond> &rot,
                        std::vector<double> &errors)
{
  const size_t nb = scene.bodies.size();
  pos.resize(nb);
  rot.resize(nb);
  for (size_t i = 0; i < nb; ++i) {
    const RigidBody &b = scene.bodies[i];
    pos[i]             = b.position + dt * b.velocity;
    rot[i]             = rotated(b.orientation, b.angular_velocity, dt);
  }
  auto at = [&](int body, const Eigen::Vector3d &anchor) -> Eigen::Vector3d { return body == kWorld ? anchor : Eigen::Vector3d(pos[body] + rot[body] * anchor); };
  errors.resize(3 * scene.joints.size());
  double worst = 0;
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d e  = at(jt.body_a, jt.anchor_a) - at(jt.body_b, jt.anchor_b);
    for (int k = 0; k < 3; ++k) errors[3 * j + k] = e[k];
    worst = std::max(worst, e.norm());
  }
  return worst;
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

  std::vector<Eigen::Matrix3d> inv_inertia(nb);
  for (size_t i = 0; i < nb; ++i) inv_inertia[i] = world_inverse_inertia(scene.bodies[i]);
  Arms arms;
  arms.a.resize(nj), arms.b.resize(nj);
  for (size_t j = 0; j < nj; ++j) {
    arms.a[j] = joint_arm(scene, scene.joints[j].body_a, scene.joints[j].anchor_a);
    arms.b[j] = joint_arm(scene, scene.joints[j].body_b, scene.joints[j].anchor_b);
  }

  auto refill = [&]() {
    fill_joint_matrix(scene, s.pattern, s.regularised ? params.regularisation : 0.0, s.block_values);
    linear_solver.set_matrix(s.block_values);
  };
  auto switch_to_regularised = [&]() {
    s.regularised            = true;
    report.singular_detected = true;
    refill();
  };
  // A breakdown on the unregularised matrix means A is (numerically) singular: regularise and retry.
  auto solve = [&]() {
    LinearSolveResult r = linear_solver.solve(s.rhs, s.impulses);
    report.linear_solves++, report.linear_iterations += r.iterations;
    if (r.breakdown && !s.regularised) {
      switch_to_regularised();
      r = linear_solver.solve(s.rhs, s.impulses);
      report.linear_solves++, report.linear_iterations += r.iterations;
    }
    for (double v : s.impulses)
      if (!std::isfinite(v)) {
        std::fill(s.impulses.begin(), s.impulses.end(), 0.0);
        break;
      }
  };

  refill();

  joint_velocity_errors(scene, s.errors);
  for (size_t j = 0; j < nj; ++j) report.velocity_error = std::max(report.velocity_error, Eigen::Vector3d(s.errors[3 * j], s.errors[3 * j + 1], s.errors[3 * j + 2]).norm());
  if (params.velocity_stabilisation && report.velocity_error > 0) {
    s.rhs.resize(3 * nj);
    for (size_t k = 0; k < 3 * nj; ++k) s.rhs[k] = -s.errors[k];
    solve();
    apply_joint_impulses(scene, arms, inv_inertia, s.impulses);
  }

  for (RigidBody &b : scene.bodies) apply_unconstrained_velocity_update(b, scene.gravity, dt);

  std::vector<Eigen::Vector3d>    pos;
  std::vector<Eigen::Quaterniond> rot;
  double                          error = predicted_errors(scene, dt, pos, rot, s.errors);
  while (error >= params.joint_tol && report.corrections < params.max_corrections) {
    if (params.refresh_matrix && report.corrections > 0) {
      // Newton-like variant: matrix and impulse arms at the predicted orientations.
      for (size_t i = 0; i < nb; ++i) {
        const Eigen::Matrix3d R = rot[i].toRotationMatrix();
        inv_inertia[i]          = R * scene.bodies[i].inertia_body.inverse() * R.transpose();
      }
      for (size_t j = 0; j < nj; ++j) {
        const BallJoint &jt = scene.joints[j];
        arms.a[j]           = jt.body_a == kWorld ? Eigen::Vector3d::Zero() : Eigen::Vector3d(rot[jt.body_a] * jt.anchor_a);
        arms.b[j]           = jt.body_b == kWorld ? Eigen::Vector3d::Zero() : Eigen::Vector3d(rot[jt.body_b] * jt.anchor_b);
      }
      fill_joint_matrix(scene, s.pattern, s.regularised ? params.regularisation : 0.0, s.block_values, &rot);
      linear_solver.set_matrix(s.block_values);
    }
    s.rhs.resize(3 * nj);
    for (size_t k = 0; k < 3 * nj; ++k) s.rhs[k] = -s.errors[k] / dt;
    solve();
    apply_joint_impulses(scene, arms, inv_inertia, s.impulses);
    report.corrections++;
    double next = predicted_errors(scene, dt, pos, rot, s.errors);
    // The linearised impulse overshoots when bodies turn far in one step (light links between heavy
    // ones): take back half of it until the error falls (a backtracking line search on max |C|).
    for (int halving = 0; next > error && halving < params.max_halvings; ++halving) {
      for (double &p : s.impulses) p *= -0.5;
      apply_joint_impulses(scene, arms, inv_inertia, s.impulses);
      for (double &p : s.impulses) p = -p;
      next = predicted_errors(scene, dt, pos, rot, s.errors);
    }
    // No fraction of the impulse helps: the linearisation has run out (round-off in very unequal masses,
    // or a step too long for the rotations); stop and report the step unconverged.
    if (next > error) {
      report.stalled = true;
      break;
    }
    error = next;
  }

  for (size_t i = 0; i < nb; ++i) {
    scene.bodies[i].position    = pos[i];
    scene.bodies[i].orientation = rot[i];
  }
  report.joint_error = max_joint_error(scene);
  report.converged   = report.joint_error < params.joint_tol;
  return report;
}

} // namespace physics
