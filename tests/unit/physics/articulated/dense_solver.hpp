// Reference solver for the physics tests: the block COO system densified and solved with a rank-revealing
// LU, reporting failure on a (numerically) singular matrix the way a Krylov solver's divergence would.
#pragma once
#include "physics/block_solver.hpp"
#include "physics/joint_matrix.hpp"

#include <Eigen/Dense>
#include <memory>

struct DenseBlockSolver {
  std::vector<int> rows, cols;
  int              n = 0;
  Eigen::MatrixXd  A;
  int              solves = 0;

  physics::BlockLinearSolver adapter()
  {
    physics::BlockLinearSolver s;
    s.set_matrix = [this](const std::vector<double> &v) {
      A.setZero(3 * n, 3 * n);
      for (size_t k = 0; k < rows.size(); ++k)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) A(3 * rows[k] + i, 3 * cols[k] + j) += v[9 * k + 3 * i + j];
    };
    s.solve = [this](const std::vector<double> &rhs, std::vector<double> &x) {
      ++solves;
      Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
      lu.setThreshold(1e-13);
      physics::LinearSolveResult r;
      r.iterations = 1;
      r.converged  = lu.isInvertible();
      r.breakdown  = !r.converged;
      Eigen::VectorXd sol =
        r.converged ? Eigen::VectorXd(lu.solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), rhs.size())))
                    : Eigen::VectorXd::Zero(rhs.size());
      x.assign(sol.data(), sol.data() + sol.size());
      return r;
    };
    return s;
  }
};

inline DenseBlockSolver dense_solver_for(const physics::JointMatrixPattern &p)
{
  DenseBlockSolver d;
  d.rows = p.block_row, d.cols = p.block_col, d.n = p.n_joints;
  return d;
}
