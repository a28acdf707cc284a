// The physics library's view of a linear solver for a fixed-pattern 3x3-block system: the drivers plug in
// PETSc (any -mat_type/-ksp_type), the tests may plug in a reference solver. Kept free of PETSc on purpose.
#pragma once
#include <functional>
#include <vector>

namespace physics {

struct LinearSolveResult {
  int  iterations = 0;
  bool converged  = true;  // false when the solver reports any divergence (max iterations included)
  bool breakdown  = false; // the solver found the matrix singular or indefinite (the evidence for loops)
};

struct BlockLinearSolver {
  // New values for the pattern the solver was built with: 9 per COO block, row-major.
  std::function<void(const std::vector<double> &block_values)>                                    set_matrix;
  std::function<LinearSolveResult(const std::vector<double> &rhs, std::vector<double> &solution)> solve;
  // The block rows whose values set_matrix passes on (this process's rows when the physics is replicated
  // over processes); empty: all. The physics may leave the other rows' values unset.
  std::vector<int> needed_rows;
};

} // namespace physics
