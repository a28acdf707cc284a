// Small SPD and not-SPD systems for the KSPMCG tests, and a solve helper that records what a solve did.
// Everything lives on PETSC_COMM_WORLD so the same tests run serially and under mpiexec.
#pragma once
#include <petscbinbcsr.h>
#include <string>
#include <vector>

namespace mcg_test {

// 3x3-block operator on an nx x ny grid: (5-point Laplacian) (x) K + shift, with K a fixed SPD 3x3
// block, then scaled symmetrically by a smoothly varying diagonal so that Jacobi matters. SPD.
// neumann_shift >= 0: the Laplacian's diagonal is the node's neighbour count + neumann_shift instead
// of 5 (singular Neumann Laplacian shifted by neumann_shift: condition number ~ 1 / neumann_shift).
Mat block_laplacian(PetscInt nx, PetscInt ny, const char *mattype = MATAIJ, PetscReal neumann_shift = -1);
// Diagonal matrix with the given diagonal (rank 0 owns everything, other ranks nothing).
Mat diagonal(const std::vector<PetscScalar> &d);
// Vector compatible with A, every entry equal to `value` (or 1, 2, 3, ... when value is NaN-free
// and `ramp` is set: a right-hand side with every eigen-component present).
Vec rhs(Mat A, bool ramp = true, PetscScalar value = 1.0);

struct Solve {
  std::string type, pc;
  KSPNormType norm      = KSP_NORM_DEFAULT;
  PetscReal   rtol      = 1e-10;
  PetscInt    max_it    = 1000;
  PetscInt    fixed_its = 0;  // mcg only
  const char *options   = ""; // extra options, inserted before KSPSetFromOptions
};
struct Result {
  PetscErrorCode           err    = 0;
  KSPConvergedReason       reason = KSP_CONVERGED_ITERATING;
  PetscInt                 its    = -1;
  PetscReal                rnorm  = -1;
  std::vector<PetscReal>   history;
  std::vector<PetscScalar> x;                  // gathered on every rank
  PetscReal                floor         = -1; // KSPMCGGetPrecisionFloor
  PetscBool                floor_stopped = PETSC_FALSE;
};
// Solves A x = b from x0 (zero when x0 is null) with the given settings; err: the error of
// KSPSetFromOptions (then no solve) or of KSPSolve.
Result solve(Mat A, Vec b, const Solve &s, Vec x0 = nullptr);
// All entries of a parallel vector, on every rank.
std::vector<PetscScalar> gather(Vec x);
// ||a - b|| / ||b|| of two gathered vectors.
PetscReal rel_diff(const std::vector<PetscScalar> &a, const std::vector<PetscScalar> &b);

// The aij test matrix converted to binbcsr with the given value storage; nullptr where binbcsr is not
// available on this communicator (required, checked, on one rank).
Mat to_binbcsr(Mat aij, MatBinBCSRPrecision precision);
// KSPMCG with the given PC and extra options against KSPCG with the PC on A x = b (unpreconditioned
// norm): same reason, iterations +-1, solutions to 1e-7 at rtol 1e-10, residual histories to 1e-8 over
// the first 15 iterations, and the iterates after 5 iterations equal to rounding (1e-12). Catch checks.
void check_mcg_same_as_cg(Mat A, Vec b, const char *pc, const char *options);
// ||b - A x|| / ||b|| with the gathered x.
PetscReal rel_residual(Mat A, Vec b, const std::vector<PetscScalar> &x);

// KSPView (as text, the same on every rank) of an mcg + Jacobi solve of A x = b after the given options
// are inserted (cleared again afterwards).
std::string view_after_solve(Mat A, Vec b, const char *options = "");

} // namespace mcg_test
