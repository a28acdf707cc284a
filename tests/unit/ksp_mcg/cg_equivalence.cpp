// KSPMCG is CG in exact arithmetic: its iterates, residual histories and iteration counts must match
// KSPCG's (same PC, same norm type) to round-off on SPD systems.
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"
#include <cstdlib>

using namespace mcg_test;

static void check_same_as_cg(Mat A, Vec b, const char *pc, KSPNormType norm, PetscReal rtol)
{
  Solve        s_cg{KSPCG, pc, norm, rtol}, s_mcg{KSPMCG, pc, norm, rtol};
  const Result cg = solve(A, b, s_cg), mcg = solve(A, b, s_mcg);
  INFO("pc " << pc << " norm " << KSPNormTypes[norm] << ": cg " << cg.its << " its "
             << KSPConvergedReasons[cg.reason] << ", mcg " << mcg.its << " its "
             << KSPConvergedReasons[mcg.reason]);
  REQUIRE(cg.err == 0);
  REQUIRE(mcg.err == 0);
  CHECK(cg.reason > 0);
  CHECK(mcg.reason == cg.reason);
  // the two recurrences differ by rounding, which CG amplifies over many iterations: counts may
  // differ by one, the first iterations agree closely, the solutions to the tolerance
  CHECK(std::abs(mcg.its - cg.its) <= 1);
  CHECK(rel_diff(mcg.x, cg.x) < 1e-7);
  REQUIRE(mcg.history.size() >= 2);
  const size_t n = std::min<size_t>(std::min(cg.history.size(), mcg.history.size()), 15);
  for (size_t k = 0; k < n && cg.history[k] > 1e-9 * cg.history[0]; k++) {
    INFO("iteration " << k);
    CHECK(mcg.history[k] == Approx(cg.history[k]).epsilon(1e-8));
  }
}

TEST_CASE("mcg matches cg on SPD block systems of several sizes", "[ksp_mcg][cg]")
{
  const PetscInt sizes[][2] = {{2, 2}, {7, 5}, {24, 20}};
  for (auto &sz : sizes) {
    Mat A = block_laplacian(sz[0], sz[1]);
    Vec b = rhs(A);
    INFO("grid " << sz[0] << " x " << sz[1]);
    for (const char *pc : {PCJACOBI, PCNONE, PCBJACOBI}) {
      check_same_as_cg(A, b, pc, KSP_NORM_PRECONDITIONED, 1e-10);
      check_same_as_cg(A, b, pc, KSP_NORM_UNPRECONDITIONED, 1e-10);
      check_same_as_cg(A, b, pc, KSP_NORM_NATURAL, 1e-10);
    }
    MatDestroy(&A);
    VecDestroy(&b);
  }
}

TEST_CASE("mcg iterates equal cg iterates after k iterations", "[ksp_mcg][cg]")
{
  Mat A = block_laplacian(16, 16);
  Vec b = rhs(A);
  for (PetscInt k : {1, 2, 5, 17, 40}) {
    Solve s_cg{KSPCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-30, k}, s_mcg = s_cg;
    s_mcg.type      = KSPMCG;
    const Result cg = solve(A, b, s_cg), mcg = solve(A, b, s_mcg);
    INFO("k = " << k);
    CHECK(cg.reason == KSP_DIVERGED_ITS);
    CHECK(mcg.reason == KSP_DIVERGED_ITS);
    CHECK(mcg.its == k);
    CHECK(rel_diff(mcg.x, cg.x) < 1e-10);
    // fixed-iteration mode does the same k iterations without any convergence test
    Solve s_fixed      = s_mcg;
    s_fixed.fixed_its  = k;
    s_fixed.max_it     = 3; // ignored in fixed mode
    const Result fixed = solve(A, b, s_fixed);
    CHECK(fixed.reason == KSP_CONVERGED_ITS);
    CHECK(fixed.its == k);
    CHECK(rel_diff(fixed.x, cg.x) < 1e-10);
  }
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("mcg honours a nonzero initial guess and norm type none", "[ksp_mcg][cg]")
{
  Mat   A = block_laplacian(10, 9);
  Vec   b = rhs(A), x0                                              = rhs(A, true, -0.5);
  Solve s_cg{KSPCG, PCJACOBI, KSP_NORM_PRECONDITIONED, 1e-9}, s_mcg = s_cg;
  s_mcg.type = KSPMCG;
  Result cg = solve(A, b, s_cg, x0), mcg = solve(A, b, s_mcg, x0);
  CHECK(mcg.reason == cg.reason);
  CHECK(mcg.its == cg.its);
  CHECK(rel_diff(mcg.x, cg.x) < 1e-8);
  REQUIRE(cg.history.size() > 0);
  CHECK(mcg.history[0] == Approx(cg.history[0]).epsilon(1e-12));

  s_cg.norm = s_mcg.norm = KSP_NORM_NONE;
  s_cg.max_it = s_mcg.max_it = 12;
  cg                         = solve(A, b, s_cg, x0);
  mcg                        = solve(A, b, s_mcg, x0);
  CHECK(mcg.reason == cg.reason);
  CHECK(mcg.its == 12);
  CHECK(rel_diff(mcg.x, cg.x) < 1e-10);
  MatDestroy(&A);
  VecDestroy(&b);
  VecDestroy(&x0);
}

TEST_CASE("mcg rebuilds its Jacobi diagonal when the operator changes", "[ksp_mcg][jacobi]")
{
  Mat       A = block_laplacian(8, 8);
  Vec       b = rhs(A), x;
  KSP       ksp;
  PC        pc;
  PetscReal n1, n2;
  VecDuplicate(b, &x);
  KSPCreate(PETSC_COMM_WORLD, &ksp);
  KSPSetOperators(ksp, A, A);
  KSPSetType(ksp, KSPMCG);
  KSPGetPC(ksp, &pc);
  PCSetType(pc, PCJACOBI);
  KSPSetTolerances(ksp, 1e-12, 1e-50, PETSC_DEFAULT, 500);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  VecNorm(x, NORM_2, &n1);
  // same pattern, new values (as a simulation refills its matrix): x must halve
  MatScale(A, 2.0);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  VecNorm(x, NORM_2, &n2);
  CHECK(n2 == Approx(0.5 * n1).epsilon(1e-9));
  KSPConvergedReason reason;
  KSPGetConvergedReason(ksp, &reason);
  CHECK(reason > 0);
  KSPDestroy(&ksp);
  VecDestroy(&x);
  VecDestroy(&b);
  MatDestroy(&A);
}
