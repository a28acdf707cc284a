#include "physics/tet_element.hpp"

#include <cmath>
#include "physics/tet_mesh.hpp"

#include <Eigen/LU>
#include <array>
#include <stdexcept>
#include <vector>

namespace physics {

LameParameters lame_from_young_poisson(double young, double poisson)
{
  if (!(young > 0) || !std::isfinite(young) || !(poisson > -1.0 && poisson < 0.5))
    throw std::invalid_argument("material: need a finite Young's modulus > 0 and -1 < Poisson's ratio < 0.5");
  return {young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))};
}

TetGeometry tet_geometry(const Eigen::Matrix<double, 3, 4> &X)
{
  TetGeometry     g;
  Eigen::Matrix3d Dm;
  for (int k = 0; k < 3; ++k) Dm.col(k) = X.col(k + 1) - X.col(0);
  g.volume             = Dm.determinant() / 6.0;
  g.rest_shape_inverse = Dm.inverse();
  // L_k = row k-1 of Dm^-1 applied to (x - X0), k = 1..3; L_0 = 1 - sum.
  for (int k = 0; k < 3; ++k) g.grad_barycentric.row(k + 1) = g.rest_shape_inverse.row(k);
  g.grad_barycentric.row(0) = -g.grad_barycentric.bottomRows<3>().colwise().sum();
  return g;
}

namespace {

// Gradients of the N shape functions at barycentric point L (rows).
Eigen::MatrixXd shape_gradients(const TetGeometry &g, int order, const std::array<double, 4> &L)
{
  const auto &G = g.grad_barycentric;
  if (order == 1) return G;
  Eigen::MatrixXd dN(10, 3);
  for (int a = 0; a < 4; ++a) dN.row(a) = (4 * L[a] - 1) * G.row(a); // N = L(2L-1)
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1]; // N = 4 La Lb
    dN.row(4 + k) = 4 * (L[b] * G.row(a) + L[a] * G.row(b));
  }
  return dN;
}

void add_stiffness_at_point(const Eigen::MatrixXd &dN, double weight, const LameParameters &p,
                            Eigen::MatrixXd &K)
{
  const int n = static_cast<int>(dN.rows());
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const Eigen::RowVector3d ga = dN.row(a), gb = dN.row(b);
      // K_ab(i,j) = int lambda dNa_i dNb_j + mu dNa_j dNb_i + mu delta_ij grad Na . grad Nb
      K.block<3, 3>(3 * a, 3 * b) += weight * (p.lambda * ga.transpose() * gb + p.mu * gb.transpose() * ga +
                                               p.mu * ga.dot(gb) * Eigen::Matrix3d::Identity());
    }
}

// A shape function as a polynomial in barycentric coordinates: sum coef * prod L_i^e_i.
struct Monomial {
  double             coef;
  std::array<int, 4> exp;
};
using Poly = std::vector<Monomial>;

std::vector<Poly> shape_polynomials(int order)
{
  std::vector<Poly> N;
  for (int a = 0; a < 4; ++a) {
    std::array<int, 4> e1{0, 0, 0, 0}, e2{0, 0, 0, 0};
    e1[a] = 1;
    e2[a] = 2;
    if (order == 1) N.push_back({{1.0, e1}});
    else N.push_back({{2.0, e2}, {-1.0, e1}});
  }
  if (order == 2)
    for (const auto &ed : kTetEdges) {
      std::array<int, 4> e{0, 0, 0, 0};
      e[ed[0]] = 1;
      e[ed[1]] = 1;
      N.push_back({{4.0, e}});
    }
  return N;
}

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

// (1/V) * integral over the tetrahedron of prod L_i^e_i = 6 e0! e1! e2! e3! / (|e| + 3)!
double monomial_integral(const std::array<int, 4> &e)
{
  return 6.0 * factorial(e[0]) * factorial(e[1]) * factorial(e[2]) * factorial(e[3]) /
         factorial(e[0] + e[1] + e[2] + e[3] + 3);
}

} // namespace

Eigen::MatrixXd element_stiffness(const TetGeometry &g, int order, const LameParameters &lame)
{
  if (order != 1 && order != 2) throw std::invalid_argument("element order must be 1 or 2");
  const int       n = order == 1 ? 4 : 10;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  if (order == 1) {
    add_stiffness_at_point(g.grad_barycentric, g.volume, lame, K);
  } else {
    // 4-point rule, exact for degree 2 (the integrand dN^T D dN is quadratic for P2).
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    for (int q = 0; q < 4; ++q) {
      std::array<double, 4> L{b, b, b, b};
      L[q] = a;
      add_stiffness_at_point(shape_gradients(g, 2, L), g.volume / 4, lame, K);
    }
  }
  return K;
}

Eigen::MatrixXd reference_mass(int order, MassLumping lumping)
{
  if (order != 1 && order != 2) throw std::invalid_argument("element order must be 1 or 2");
  if (order == 1) return Eigen::MatrixXd::Identity(4, 4) / 4.0; // P1: lumped, the standard choice
  const auto      N = shape_polynomials(2);
  Eigen::MatrixXd M(10, 10);
  for (int a = 0; a < 10; ++a)
    for (int b = 0; b < 10; ++b) {
      double s = 0;
      for (const auto &ma : N[a])
        for (const auto &mb : N[b]) {
          std::array<int, 4> e;
          for (int i = 0; i < 4; ++i) e[i] = ma.exp[i] + mb.exp[i];
          s += ma.coef * mb.coef * monomial_integral(e);
        }
      M(a, b) = s;
    }
  if (lumping == MassLumping::Consistent) return M;
  // HRZ: keep the diagonal's proportions, scale it to the element's total mass (1 per unit rho V).
  const Eigen::VectorXd d = M.diagonal();
  return Eigen::MatrixXd((d / d.sum()).asDiagonal());
}

Eigen::VectorXd shape_function_integrals(int order)
{
  const auto      N = shape_polynomials(order);
  Eigen::VectorXd v(N.size());
  for (size_t a = 0; a < N.size(); ++a) {
    double s = 0;
    for (const auto &m : N[a]) s += m.coef * monomial_integral(m.exp);
    v[a] = s;
  }
  return v;
}

} // namespace physics
