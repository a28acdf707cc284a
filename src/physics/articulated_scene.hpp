// An articulated scene: rigid bodies connected by ball joints, each joint joining two bodies or a body
// and the world. This file holds the data and its geometry (connector points, joint errors); the
// solver lives in articulated_step.hpp, the scene generators in articulated_scenes.hpp.
#pragma once
#include "physics/rigid_body.hpp"

#include <string>
#include <vector>

namespace physics {

constexpr int kWorld = -1;

struct BallJoint {
  int             body_a = kWorld;
  int             body_b = kWorld;
  Eigen::Vector3d anchor_a =
    Eigen::Vector3d::Zero(); // body_a's frame, or a world point if body_a is the world
  Eigen::Vector3d anchor_b = Eigen::Vector3d::Zero();
};

struct ArticulatedScene {
  std::vector<RigidBody>       bodies;
  std::vector<BallJoint>       joints;
  std::vector<Eigen::Vector3d> body_sizes; // box edge lengths, only for output
  Eigen::Vector3d              gravity = Eigen::Vector3d(0, -9.81, 0);
};

// Empty string when the scene is usable, otherwise what is wrong (first problem found).
std::string validate_scene(const ArticulatedScene &scene);

// World-frame offset from body's centre of mass to a joint end (zero for the world).
Eigen::Vector3d joint_arm(const ArticulatedScene &scene, int body, const Eigen::Vector3d &anchor);
// World position of a joint end.
Eigen::Vector3d connector_position(const ArticulatedScene &scene, int body, const Eigen::Vector3d &anchor);

// C = p_a - p_b for each joint, 3 per joint.
void joint_errors(const ArticulatedScene &scene, std::vector<double> &errors);
// Largest |C| over joints (0 without joints).
double max_joint_error(const ArticulatedScene &scene);
// Relative connector velocity u_a - u_b, 3 per joint (the J v of the velocity constraint).
void joint_velocity_errors(const ArticulatedScene &scene, std::vector<double> &errors);

double total_energy(const ArticulatedScene &scene);

} // namespace physics
