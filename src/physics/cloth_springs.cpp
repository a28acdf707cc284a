#include "physics/cloth_springs.hpp"

namespace physics {

SpringTerms spring_terms(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb, const Eigen::Vector3d &va, const Eigen::Vector3d &vb,
                         double damping, bool choi_ko)
{
  SpringTerms           out;
  const Eigen::Vector3d delta  = xb - xa;
  const double          length = delta.norm();
  if (length < 1e-12 * s.rest_length) { // coincident particles: no direction, no force
    out.direction.setZero();
    out.force_on_a.setZero();
    out.k_iso = s.stiffness;
    return out;
  }
  const Eigen::Vector3d d = delta / length;
  double transverse = 1.0 - s.rest_length / length;
  if (choi_ko && transverse < 0) transverse = 0;
  out.direction  = d;
  out.force_on_a = (s.stiffness * (length - s.rest_length) + damping * d.dot(vb - va)) * d;
  out.k_iso      = s.stiffness * transverse;
  out.k_dir      = s.stiffness * (1.0 - transverse);
  out.damping    = damping;
  return out;
}

SpringLinearisation linearise_spring(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb, const Eigen::Vector3d &va, const Eigen::Vector3d &vb,
                                     double damping, bool choi_ko)
{
  const SpringTerms     t  = spring_terms(s, xa, xb, va, vb, damping, choi_ko);
  const Eigen::Matrix3d dd = t.direction * t.direction.transpose();
  SpringLinearisation   out;
  out.force_on_a = t.force_on_a;
  out.stiffness  = t.k_iso * Eigen::Matrix3d::Identity() + t.k_dir * dd;
  out.damping    = t.damping * dd;
  return out;
}

} // namespace physics
