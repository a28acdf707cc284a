// One spring's force and its Jacobians for implicit integration (Baraff & Witkin 1998).
#pragma once
#include "physics/cloth_model.hpp"

#include <cmath>

namespace physics {

struct SpringLinearisation {
  Eigen::Vector3d force_on_a; // f_b = -f_a
  Eigen::Matrix3d stiffness;  // K = -df_a/dx_a (enters as +K at (a,a), (b,b), -K at (a,b), (b,a))
  Eigen::Matrix3d damping;    // D = -df_a/dv_a, same pattern
};

// The same in the compact form the assembly uses: K = k_iso I + k_dir d d^T, D = damping d d^T
// (d = unit direction from a to b; zero, with k_iso = k, for coincident particles).
struct SpringTerms {
  Eigen::Vector3d direction;
  Eigen::Vector3d force_on_a;
  double          k_iso = 0, k_dir = 0, damping = 0;
};

// The terms of one spring from plain numbers: the separation xb - xa = (dx, dy, dz) and the relative velocity
// vb - va = (wx, wy, wz) of its ends. What spring_terms computes, written so that a loop over springs vectorises
// (the assembly runs it over a chunk of springs at a time); branch-free: a coincident pair gets direction and
// force zero, k_iso = stiffness, k_dir = 0.
inline void spring_terms_lane(double rest_length, double stiffness, double dx, double dy, double dz,
                              double wx, double wy, double wz, double damping, bool choi_ko, double &d0,
                              double &d1, double &d2, double &f0, double &f1, double &f2, double &k_iso,
                              double &k_dir)
{
  const double length     = std::sqrt(dx * dx + dy * dy + dz * dz);
  const bool   coincident = length < 1e-12 * rest_length; // no direction, no force
  const double l          = coincident ? 1.0 : length;
  const double e0 = coincident ? 0.0 : dx / l, e1 = coincident ? 0.0 : dy / l, e2 = coincident ? 0.0 : dz / l;
  const double exact      = 1.0 - rest_length / l;
  const double transverse = choi_ko && exact < 0 ? 0.0 : exact;
  const double f =
    coincident ? 0.0 : stiffness * (length - rest_length) + damping * (e0 * wx + e1 * wy + e2 * wz);
  d0 = e0, d1 = e1, d2 = e2;
  f0 = f * e0, f1 = f * e1, f2 = f * e2;
  k_iso = coincident ? stiffness : stiffness * transverse;
  k_dir = coincident ? 0.0 : stiffness * (1.0 - transverse);
}

inline SpringTerms spring_terms(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb,
                                const Eigen::Vector3d &va, const Eigen::Vector3d &vb, double damping,
                                bool choi_ko = true)
{
  SpringTerms           out;
  const Eigen::Vector3d delta = xb - xa, w = vb - va;
  spring_terms_lane(s.rest_length, s.stiffness, delta[0], delta[1], delta[2], w[0], w[1], w[2], damping,
                    choi_ko, out.direction[0], out.direction[1], out.direction[2], out.force_on_a[0],
                    out.force_on_a[1], out.force_on_a[2], out.k_iso, out.k_dir);
  out.damping = damping;
  return out;
}

// Hooke spring plus damping along the spring. The exact stiffness is
//   k [ d d^T + (1 - L/l) (I - d d^T) ]   (d = unit direction, l = length, L = rest length),
// whose transverse term is negative for a compressed spring (l < L) and can make M + h^2 K indefinite.
// Following Choi & Ko (2002) the transverse term is dropped for compressed springs, so K is always
// positive semi-definite and the system stays SPD for CG at any time step.
SpringLinearisation linearise_spring(const Spring &s, const Eigen::Vector3d &xa, const Eigen::Vector3d &xb,
                                     const Eigen::Vector3d &va, const Eigen::Vector3d &vb, double damping,
                                     bool choi_ko = true);

} // namespace physics
