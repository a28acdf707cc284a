// Truncated CG from a nonzero initial guess (what a simulation does when it warm-starts a fixed number
// of iterations from the previous step's solution): mcg's fixed-iteration mode does what KSPCG does
// from the same guess, and the A-norm of the error never grows with the iteration count nor exceeds
// the guess's. (The cloth blows up with warm-started 30 iterations all the same: docs/cloth.md says why.)
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"

using namespace mcg_test;

namespace {

// sqrt((x - y)^T A (x - y)) for gathered x, y.
PetscReal a_norm_of_difference(Mat A, const std::vector<PetscScalar> &x, const std::vector<PetscScalar> &y)
{
  Vec      d, Ad;
  PetscInt lo, hi;
  MatCreateVecs(A, &d, &Ad);
  VecGetOwnershipRange(d, &lo, &hi);
  for (PetscInt i = lo; i < hi; i++) VecSetValue(d, i, x[i] - y[i], INSERT_VALUES);
  VecAssemblyBegin(d);
  VecAssemblyEnd(d);
  MatMult(A, d, Ad);
  PetscScalar e2;
  VecDot(d, Ad, &e2);
  VecDestroy(&d);
  VecDestroy(&Ad);
  return std::sqrt(PetscRealPart(e2));
}

void check_warm_started_fixed_iterations(Mat A, Vec b, Vec x0)
{
  const Result exact = solve(A, b, Solve{KSPCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-14, 5000});
  REQUIRE(exact.reason > 0);
  const PetscReal e_guess = a_norm_of_difference(A, gather(x0), exact.x);
  REQUIRE(e_guess > 0);
  PetscReal previous = e_guess;
  for (PetscInt k : {1, 2, 5, 10, 20, 30}) {
    INFO("k = " << k);
    Solve fixed{KSPMCG, PCJACOBI, KSP_NORM_NONE, 1e-30, 3};
    fixed.fixed_its  = k;
    const Result mcg = solve(A, b, fixed, x0);
    const Result cg  = solve(A, b, Solve{KSPCG, PCJACOBI, KSP_NORM_NONE, 1e-30, k}, x0);
    REQUIRE(mcg.err == 0);
    CHECK(mcg.its == k);
    CHECK(rel_diff(mcg.x, cg.x) < 1e-10);
    const PetscReal e = a_norm_of_difference(A, mcg.x, exact.x);
    CHECK(e <= previous * (1 + 1e-12));
    CHECK(e < e_guess);
    previous = e;
  }
  CHECK(previous < 0.5 * e_guess);
}

} // namespace

TEST_CASE("fixed iterations from a nonzero guess: same as cg, A-norm error never grows", "[ksp_mcg][cg]")
{
  Mat A = block_laplacian(16, 12, MATAIJ, 1e-3); // condition number ~1e3: 30 iterations do not converge
  Vec b = rhs(A), x0 = rhs(A, true, -0.7);
  SECTION("aij") { check_warm_started_fixed_iterations(A, b, x0); }
  SECTION("binbcsr, upper-triangle storage (the fused fast path)")
  {
    Mat B = to_binbcsr(A, MAT_BINBCSR_PRECISION_DOUBLE);
    if (!B) {
      WARN("binbcsr not available on this communicator: skipped");
    } else {
      // storage is chosen before the values go in: rebuild from A with the option set
      MatDestroy(&B);
      PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", "1");
      REQUIRE(MatConvert(A, MATBINBCSR, MAT_INITIAL_MATRIX, &B) == 0);
      PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage");
      PetscBool sym = PETSC_FALSE;
      MatBinBCSRGetSymmetricStorage(B, &sym);
      CHECK(sym);
      check_warm_started_fixed_iterations(B, b, x0);
      MatDestroy(&B);
    }
  }
  MatDestroy(&A);
  VecDestroy(&b);
  VecDestroy(&x0);
}
