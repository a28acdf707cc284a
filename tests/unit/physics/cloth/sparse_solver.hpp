// Reference solver for the cloth tests: the block COO system as an Eigen sparse matrix, factorised with a
// sparse Cholesky (LLT), which fails exactly when the matrix is not positive definite.
#pragma once
#include "physics/block_solver.hpp"

#include <Eigen/Sparse>

struct SparseBlockSolver {
  std::vector<int>            rows, cols;
  int                         n = 0; // block rows
  Eigen::SparseMatrix<double> A;
  bool                        last_spd = true;

  physics::BlockLinearSolver adapter()
  {
    physics::BlockLinearSolver s;
    s.set_matrix = [this](const std::vector<double> &v) {
      std::vector<Eigen::Triplet<double>> t;
      for (size_t k = 0; k < rows.size(); ++k)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) t.emplace_back(3 * rows[k] + i, 3 * cols[k] + j, v[9 * k + 3 * i + j]);
      A.resize(3 * n, 3 * n);
      A.setFromTriplets(t.begin(), t.end());
    };
    s.solve = [this](const std::vector<double> &rhs, std::vector<double> &x) {
      Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(A);
      physics::LinearSolveResult                        r;
      last_spd     = llt.info() == Eigen::Success;
      r.converged  = last_spd;
      r.breakdown  = !last_spd;
      r.iterations = 1;
      Eigen::VectorXd sol =
        last_spd ? Eigen::VectorXd(llt.solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), rhs.size())))
                 : Eigen::VectorXd::Zero(rhs.size());
      x.assign(sol.data(), sol.data() + sol.size());
      return r;
    };
    return s;
  }
};

template <class System> SparseBlockSolver sparse_solver_for(const System &sys)
{
  SparseBlockSolver s;
  s.rows = sys.block_row, s.cols = sys.block_col, s.n = sys.n_particles;
  return s;
}
