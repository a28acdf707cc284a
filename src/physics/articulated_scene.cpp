#include "physics/articulated_scene.hpp"

#include <cmath>

namespace physics {

static bool finite(const Eigen::Vector3d &v)
{
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

std::string validate_scene(const ArticulatedScene &scene)
{
  const int nb = static_cast<int>(scene.bodies.size());
  for (int i = 0; i < nb; ++i) {
    const RigidBody  &b   = scene.bodies[i];
    const std::string who = "body " + std::to_string(i);
    if (!(b.mass > 0) || !std::isfinite(b.mass)) return who + ": mass must be positive and finite";
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(b.inertia_body);
    if (!b.inertia_body.allFinite() ||
        (b.inertia_body - b.inertia_body.transpose()).norm() > 1e-12 * b.inertia_body.norm() ||
        !(eig.eigenvalues().minCoeff() > 0))
      return who + ": inertia tensor must be symmetric positive definite";
    if (!finite(b.position) || !finite(b.velocity) || !finite(b.angular_velocity) ||
        !b.orientation.coeffs().allFinite() || std::abs(b.orientation.norm() - 1) > 1e-6)
      return who + ": state must be finite with a unit quaternion";
  }
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint  &jt  = scene.joints[j];
    const std::string who = "joint " + std::to_string(j);
    for (int b : {jt.body_a, jt.body_b})
      if (b != kWorld && (b < 0 || b >= nb))
        return who + ": names body " + std::to_string(b) + " but the scene has " + std::to_string(nb) +
               " bodies";
    if (jt.body_a == jt.body_b) return who + ": joins a body to itself";
    if (!finite(jt.anchor_a) || !finite(jt.anchor_b)) return who + ": anchors must be finite";
  }
  if (!finite(scene.gravity)) return "gravity must be finite";
  return "";
}

Eigen::Vector3d joint_arm(const ArticulatedScene &scene, int body, const Eigen::Vector3d &anchor)
{
  if (body == kWorld) return Eigen::Vector3d::Zero();
  return scene.bodies[body].orientation * anchor;
}

Eigen::Vector3d connector_position(const ArticulatedScene &scene, int body, const Eigen::Vector3d &anchor)
{
  if (body == kWorld) return anchor;
  return scene.bodies[body].position + scene.bodies[body].orientation * anchor;
}

/* errors[3j..3j+2] = point(a) - point(b) of joint j: the position and the velocity constraint residuals
   differ only in which point of a body's anchor they take. */
template <typename Point>
static void joint_differences(const ArticulatedScene &scene, std::vector<double> &errors, Point &&point)
{
  errors.resize(3 * scene.joints.size());
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const BallJoint      &jt = scene.joints[j];
    const Eigen::Vector3d e  = point(scene, jt.body_a, jt.anchor_a) - point(scene, jt.body_b, jt.anchor_b);
    for (int k = 0; k < 3; ++k) errors[3 * j + k] = e[k];
  }
}

void joint_errors(const ArticulatedScene &scene, std::vector<double> &errors)
{
  joint_differences(scene, errors, connector_position);
}

double max_joint_error(const ArticulatedScene &scene)
{
  double worst = 0;
  for (const BallJoint &jt : scene.joints)
    worst = std::max(worst, (connector_position(scene, jt.body_a, jt.anchor_a) -
                             connector_position(scene, jt.body_b, jt.anchor_b))
                              .norm());
  return worst;
}

static Eigen::Vector3d point_velocity(const ArticulatedScene &scene, int body, const Eigen::Vector3d &anchor)
{
  if (body == kWorld) return Eigen::Vector3d::Zero();
  const RigidBody &b = scene.bodies[body];
  return b.velocity + b.angular_velocity.cross(b.orientation * anchor);
}

void joint_velocity_errors(const ArticulatedScene &scene, std::vector<double> &errors)
{
  joint_differences(scene, errors, point_velocity);
}

double total_energy(const ArticulatedScene &scene)
{
  double e = 0;
  for (const RigidBody &b : scene.bodies) e += mechanical_energy(b, scene.gravity);
  return e;
}

} // namespace physics
