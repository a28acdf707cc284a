// Rest-state matrices of one linear (4-node) or quadratic (10-node) tetrahedron for isotropic linear
// elasticity: stiffness K0 (exact: constant strain for P1, 4-point degree-2 quadrature for P2, whose
// integrand is quadratic) and the mass matrix per unit density and volume.
#pragma once
#include <Eigen/Core>

namespace physics {

struct LameParameters {
  double lambda, mu;
};
// Throws std::invalid_argument unless young > 0 and -1 < poisson < 0.5.
LameParameters lame_from_young_poisson(double young, double poisson);

// Gradients of the 4 barycentric coordinates (rows) of the tetrahedron with corners X (columns),
// and its signed volume. grad.row(i) = grad L_i.
struct TetGeometry {
  Eigen::Matrix<double, 4, 3> grad_barycentric;
  Eigen::Matrix3d             rest_shape_inverse; // Dm^-1, Dm = (X1-X0, X2-X0, X3-X0)
  double                      volume;
};
TetGeometry tet_geometry(const Eigen::Matrix<double, 3, 4> &corners);

// Element stiffness, 3N x 3N with node-major ordering (3 rows per node), N = 4 or 10, for the
// element with the given corner geometry (edge nodes at the edge midpoints).
Eigen::MatrixXd element_stiffness(const TetGeometry &g, int order, const LameParameters &lame);

// Mass per unit density and volume, N x N (the same for every component): for order 1 the lumped
// diagonal 1/4; for order 2 the consistent matrix (exact integrals of products of shape functions) or
// its HRZ lumping (diagonal scaled to the total mass; row-sum lumping would give corners a
// negative mass of -1/20, so it is never used).
enum class MassLumping {
  Consistent,
  Lumped
};
Eigen::MatrixXd reference_mass(int order, MassLumping lumping);

// Integral of each shape function divided by the volume (order 2: corners -1/20, edges 1/5).
Eigen::VectorXd shape_function_integrals(int order);

} // namespace physics
