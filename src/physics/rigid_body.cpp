#include "physics/rigid_body.hpp"

#include <cmath>

namespace physics {

Eigen::Matrix3d box_inertia(double mass, const Eigen::Vector3d &size)
{
  const Eigen::Vector3d s2 = size.cwiseProduct(size);
  return (mass / 12.0 * Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y())).asDiagonal();
}

Eigen::Matrix3d world_inverse_inertia(const RigidBody &body)
{
  const Eigen::Matrix3d R = body.orientation.toRotationMatrix();
  return R * body.inertia_body.inverse() * R.transpose();
}

Eigen::Quaterniond rotated(const Eigen::Quaterniond &q, const Eigen::Vector3d &angular_velocity, double dt)
{
  // exp of the half angle h = |w| dt / 2 about w / |w|: r = (cos h, w sin(h) / |w|), written out (Eigen's
  // AngleAxis path normalises twice). Per step every body turns by a small angle (the bridge: h ~ 1e-2), and
  // this runs for every body at every prediction, so small angles take the Taylor series in h^2: no square
  // root, no sin/cos, no division; below h = 0.1 the next term is < 1e-21, exact to rounding.
  const double h2 = 0.25 * dt * dt * angular_velocity.squaredNorm();
  double       s, c;
  if (h2 < 0.01) {
    s = 0.5 * dt *
        (1 + h2 * (-1.0 / 6 +
                   h2 * (1.0 / 120 + h2 * (-1.0 / 5040 + h2 * (1.0 / 362880 + h2 * (-1.0 / 39916800))))));
    c = 1 + h2 * (-0.5 + h2 * (1.0 / 24 +
                               h2 * (-1.0 / 720 +
                                     h2 * (1.0 / 40320 + h2 * (-1.0 / 3628800 + h2 * (1.0 / 479001600))))));
  } else {
    const double speed = angular_velocity.norm(), half = 0.5 * speed * dt;
    s = std::sin(half) / speed, c = std::cos(half);
  }
  Eigen::Quaterniond r(c, s * angular_velocity.x(), s * angular_velocity.y(), s * angular_velocity.z());
  Eigen::Quaterniond out = r * q;
  out.normalize();
  return out;
}

static Eigen::Matrix3d cross_matrix(const Eigen::Vector3d &a)
{
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

void apply_unconstrained_velocity_update(RigidBody &body, const Eigen::Vector3d &gravity, double dt)
{
  apply_unconstrained_velocity_update(body, body.orientation.toRotationMatrix(), gravity, dt);
}

void apply_unconstrained_velocity_update(RigidBody &body, const Eigen::Matrix3d &R,
                                         const Eigen::Vector3d &gravity, double dt)
{
  body.velocity += dt * gravity;
  // Solve I (w' - w) + dt w' x (I w') = 0 in the body frame with one Newton step from w (Catto 2015):
  // explicit treatment of the gyroscopic term adds energy to bodies spinning about unstable axes.
  const Eigen::Matrix3d &I        = body.inertia_body;
  const Eigen::Vector3d  wb       = R.transpose() * body.angular_velocity;
  const Eigen::Vector3d  residual = dt * wb.cross(I * wb);
  const Eigen::Matrix3d  jacobian = I + dt * (cross_matrix(wb) * I - cross_matrix(I * wb));
  // The Jacobian is I plus O(dt |w|) terms: far from singular, and the closed-form 3x3 inverse is cheap.
  const Eigen::Vector3d wb_new = wb - jacobian.inverse() * residual;
  body.angular_velocity        = R * wb_new;
}

void advance_positions(RigidBody &body, double dt)
{
  body.position += dt * body.velocity;
  body.orientation = rotated(body.orientation, body.angular_velocity, dt);
}

double mechanical_energy(const RigidBody &body, const Eigen::Vector3d &gravity)
{
  const Eigen::Matrix3d R  = body.orientation.toRotationMatrix();
  const Eigen::Vector3d wb = R.transpose() * body.angular_velocity;
  return 0.5 * body.mass * body.velocity.squaredNorm() + 0.5 * wb.dot(body.inertia_body * wb) -
         body.mass * gravity.dot(body.position);
}

void apply_impulse(RigidBody &body, const Eigen::Matrix3d &inverse_inertia_world, const Eigen::Vector3d &arm,
                   const Eigen::Vector3d &impulse)
{
  body.velocity += impulse / body.mass;
  body.angular_velocity += inverse_inertia_world * arm.cross(impulse);
}

} // namespace physics
