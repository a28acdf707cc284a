#include "physics/cloth_springs.hpp"

namespace physics {

SpringLinearisation linearise_spring(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb,
                                     const Eigen::Vector3d &va, const Eigen::Vector3d &vb, double damping,
                                     bool choi_ko)
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
