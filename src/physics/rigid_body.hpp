// A rigid body's state and its unconstrained motion (gravity plus the gyroscopic term), the part of an
// articulated step that needs no knowledge of joints.
#pragma once
#include <Eigen/Dense>

namespace physics {

struct RigidBody {
  double             mass             = 1.0;
  Eigen::Matrix3d    inertia_body     = Eigen::Matrix3d::Identity(); // about the centre of mass, body frame
  Eigen::Vector3d    position         = Eigen::Vector3d::Zero();     // centre of mass, world frame
  Eigen::Quaterniond orientation      = Eigen::Quaterniond::Identity();
  Eigen::Vector3d    velocity         = Eigen::Vector3d::Zero();
  Eigen::Vector3d    angular_velocity = Eigen::Vector3d::Zero(); // world frame
};

// Inertia of a solid box with full side lengths `size` (body axes along the box edges).
Eigen::Matrix3d box_inertia(double mass, const Eigen::Vector3d &size);

Eigen::Matrix3d world_inverse_inertia(const RigidBody &body);

// Orientation after rotating for dt at constant angular velocity (exact exponential map, unit result).
Eigen::Quaterniond rotated(const Eigen::Quaterniond &q, const Eigen::Vector3d &angular_velocity, double dt);

// Velocity update of the free body over dt: gravity, and the gyroscopic torque -w x (I w) taken
// implicitly (one Newton step in the body frame) so that fast spinning bodies do not gain energy.
void apply_unconstrained_velocity_update(RigidBody &body, const Eigen::Vector3d &gravity, double dt);
// The same with the body's rotation matrix already at hand (R = orientation.toRotationMatrix()).
void apply_unconstrained_velocity_update(RigidBody &body, const Eigen::Matrix3d &R,
                                         const Eigen::Vector3d &gravity, double dt);

// Where position/orientation go after dt with the current velocities (symplectic Euler position step).
void advance_positions(RigidBody &body, double dt);

// Kinetic plus gravitational potential energy (potential zero at the origin).
double mechanical_energy(const RigidBody &body, const Eigen::Vector3d &gravity);

// Applies impulse `impulse` at world offset `arm` from the centre of mass.
void apply_impulse(RigidBody &body, const Eigen::Matrix3d &inverse_inertia_world, const Eigen::Vector3d &arm,
                   const Eigen::Vector3d &impulse);

} // namespace physics
