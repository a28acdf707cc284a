// Jacobi-preconditioned CG on the block COO system, for tests of what an iterative solver sees: it starts
// from the incoming solution (a warm start), and either stops at a relative residual ||r|| < rtol ||b||
// (PETSc's default test) or runs a fixed number of iterations (KSPMCG's fixed-iteration mode).
#pragma once
#include "physics/block_solver.hpp"
#include "physics/joint_matrix.hpp"

#include <cmath>

struct CgBlockSolver {
  const physics::JointMatrixPattern *pattern = nullptr;
  std::vector<double>                values;
  double                             rtol             = 1e-10;
  int                                fixed_iterations = 0; // > 0: exactly this many, no test
  int                                max_iterations   = 10000;
  long                               total_iterations = 0;

  physics::BlockLinearSolver adapter()
  {
    physics::BlockLinearSolver s;
    s.set_matrix = [this](const std::vector<double> &v) { values = v; };
    s.solve      = [this](const std::vector<double> &b, std::vector<double> &x) {
      const size_t        n = b.size();
      std::vector<double> r(n), z(n), p(n), Ap(n), dinv(n);
      if (x.size() != n) x.assign(n, 0.0);
      for (int j = 0; j < pattern->n_joints; ++j)
        for (int k = 0; k < 3; ++k) dinv[3 * j + k] = 1.0 / values[9 * pattern->diagonal_block[j] + 4 * k];
      physics::joint_matrix_multiply(*pattern, values, x, Ap);
      double bb = 0, rz = 0;
      for (size_t i = 0; i < n; ++i)
        r[i] = b[i] - Ap[i], z[i] = dinv[i] * r[i], p[i] = z[i], bb += b[i] * b[i], rz += r[i] * z[i];
      physics::LinearSolveResult out;
      const int                  limit = fixed_iterations > 0 ? fixed_iterations : max_iterations;
      for (int it = 0; it < limit; ++it) {
        double rr = 0;
        for (double v : r) rr += v * v;
        if (fixed_iterations == 0 && rr <= rtol * rtol * bb) break;
        physics::joint_matrix_multiply(*pattern, values, p, Ap);
        double pAp = 0;
        for (size_t i = 0; i < n; ++i) pAp += p[i] * Ap[i];
        if (!(pAp > 0)) break;
        const double alpha  = rz / pAp;
        double       rz_new = 0;
        for (size_t i = 0; i < n; ++i)
          x[i] += alpha * p[i], r[i] -= alpha * Ap[i], z[i] = dinv[i] * r[i], rz_new += r[i] * z[i];
        for (size_t i = 0; i < n; ++i) p[i] = z[i] + rz_new / rz * p[i];
        rz = rz_new;
        out.iterations++;
      }
      total_iterations += out.iterations;
      return out;
    };
    return s;
  }
};
