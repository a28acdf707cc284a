// Helpers for the FEM tests: the step's linear system assembled by the production kernel into an
// Eigen sparse matrix and solved directly, so physics checks do not depend on a Krylov tolerance.
#pragma once
#include "physics/corotational_assembly.hpp"
#include "physics/fem_model.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <vector>

namespace fem_test {

inline std::vector<int> all_elements(const physics::FemModel &m)
{
  std::vector<int> e(m.element_count());
  for (int i = 0; i < m.element_count(); ++i) e[i] = i;
  return e;
}

struct LinearSystem {
  Eigen::SparseMatrix<double> A;
  Eigen::VectorXd             rhs;
};

// A and rhs of one step with coefficients c (gravity force f_ext scaled by ext_scale added to rhs);
// fixed rows are identity with zero right-hand side, exactly as the driver does it.
inline LinearSystem assemble(const physics::FemModel &m, const std::vector<char> &fixed,
                             const physics::StepCoefficients &c, const std::vector<double> &x,
                             const std::vector<double> &v, const std::vector<double> &f_ext, double ext_scale)
{
  const auto            elements = all_elements(m);
  physics::BlockPattern p        = physics::make_block_pattern(m, elements, fixed, 0, m.node_count(), true);
  std::vector<double>   values;
  physics::reset_block_values(p, values);
  const int    n = m.node_count();
  LinearSystem s;
  s.rhs = Eigen::VectorXd::Zero(3 * n);
  physics::assemble_elements(m, elements, x.data(), v.data(), c, &p, values.data(), s.rhs.data());
  std::vector<Eigen::Triplet<double>> t;
  for (size_t k = 0; k < p.rows.size(); ++k)
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q)
        t.emplace_back(3 * p.rows[k] + r, 3 * p.cols[k] + q, values[9 * k + 3 * r + q]);
  s.A.resize(3 * n, 3 * n);
  s.A.setFromTriplets(t.begin(), t.end());
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      s.rhs[3 * i + d] =
        fixed[i] ? 0.0 : s.rhs[3 * i + d] + ext_scale * (f_ext.empty() ? 0.0 : f_ext[3 * i + d]);
  return s;
}

inline Eigen::VectorXd solve(const LinearSystem &s)
{
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(s.A);
  return ldlt.solve(s.rhs);
}

// Full mass matrix (3n x 3n) of the model, for momentum and residual checks.
inline Eigen::SparseMatrix<double> mass_matrix(const physics::FemModel &m)
{
  std::vector<Eigen::Triplet<double>> t;
  for (int e = 0; e < m.element_count(); ++e) {
    const int *nodes = &m.mesh.elements[static_cast<size_t>(e) * m.npe];
    for (int a = 0; a < m.npe; ++a)
      for (int b = 0; b < m.npe; ++b)
        for (int d = 0; d < 3; ++d)
          t.emplace_back(3 * nodes[a] + d, 3 * nodes[b] + d,
                         m.settings.density * m.volume[e] * m.reference_mass(a, b));
  }
  Eigen::SparseMatrix<double> M(3 * m.node_count(), 3 * m.node_count());
  M.setFromTriplets(t.begin(), t.end());
  return M;
}

} // namespace fem_test
