// One spring's force and its Jacobians for implicit integration (Baraff & Witkin 1998).
#pragma once
#include "physics/cloth_model.hpp"

namespace physics {

struct SpringLinearisation {
  Eigen::Vector3d force_on_a;   // f_b = -f_a
  Eigen::Matrix3d stiffness;    // K = -df_a/dx_a (enters as +K at (a,a), (b,b), -K at (a,b), (b,a))
  Eigen::Matrix3d damping;      // D = -df_a/dv_a, same pattern
};

// The same in the compact form the assembly uses: K = k_iso I + k_dir d d^T, D = damping d d^T
// (d = unit direction from a to b; zero, with k_iso = k, for coincident particles).
struct SpringTerms {
  Eigen::Vector3d direction;
  Eigen::Vector3d force_on_a;
  double          k_iso = 0, k_dir = 0, damping = 0;
};

// Inline: the assembly calls it once per spring, and returning the struct through memory from another
// translation unit cost a store-forwarding stall per call (a third of the assembly time).
inline SpringTerms spring_terms(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb, const Eigen::Vector3d &va,
                                const Eigen::Vector3d &vb, double damping, bool choi_ko = true)
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

// Hooke spring plus damping along the spring. The exact stiffness is
//   k [ d d^T + (1 - L/l) (I - d d^T) ]   (d = unit direction, l = length, L = rest length),
// whose transverse term is negative for a compressed spring (l < L) and can make M + h^2 K indefinite.
// Following Choi & Ko (2002) the transverse term is dropped for compressed springs, so K is always
// positive semi-definite and the system stays SPD for CG at any time step.
SpringLinearisation linearise_spring(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb, const Eigen::Vector3d &va,
                                     const Eigen::Vector3d &vb, double damping, bool choi_ko = true);

} // namespace physics
