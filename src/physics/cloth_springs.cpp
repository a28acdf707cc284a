#include "physics/cloth_springs.hpp"

namespace physics {

SpringLinearisation linearise_spring(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb, const Eigen::Vector3d &va, const Eigen::Vector3d &vb,
                                     double damping, bool choi_ko)
{
  SpringLinearisation out;
  const Eigen::Vector3d delta  = xb - xa;
  const double          length = delta.norm();
  if (length < 1e-12 * s.rest_length) { // coincident particles: no direction, no force
    out.force_on_a.setZero();
    out.stiffness = s.stiffness * Eigen::Matrix3d::Identity();
    out.damping.setZero();
    return out;
  }
  const Eigen::Vector3d d  = delta / length;
  const Eigen::Matrix3d dd = d * d.transpose();
  double transverse = 1.0 - s.rest_length / length;
  if (choi_ko && transverse < 0) transverse = 0;
  out.force_on_a = s.stiffness * (length - s.rest_length) * d + damping * d.dot(vb - va) * d;
  out.stiffness  = s.stiffness * (dd + transverse * (Eigen::Matrix3d::Identity() - dd));
  out.damping    = damping * dd;
  return out;
}

} // namespace physics
