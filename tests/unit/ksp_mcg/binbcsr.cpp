// KSPMCG on MATBINBCSR storage (double and single values): same iterates as KSPCG on the same matrix,
// the fused product is used, and single storage behaves as documented (converges on the rounded
// operator; against the double-precision matrix the residual has a floor near float rounding).
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"
#include <cstdlib>
#include <cstring>

using namespace mcg_test;

TEST_CASE("mcg matches cg on binbcsr, double and single storage", "[ksp_mcg][binbcsr]")
{
  for (PetscInt n : {3, 14}) {
    Mat A = block_laplacian(n, n + 1);
    Vec b = rhs(A);
    for (MatBinBCSRPrecision precision : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE}) {
      Mat B = to_binbcsr(A, precision);
      if (!B) {
        WARN("binbcsr not available on this communicator: skipped");
        continue;
      }
      INFO("grid " << n << ", precision " << MatBinBCSRPrecisions[precision]);
      // the same iteration as KSPCG on the operator both are given: for single storage that needs the
      // precision floor off (with it, mcg stops at the floor instead of claiming rtol 1e-10; see
      // precision_floor.cpp)
      const char *floor_off = "-ksp_mcg_precision_floor 0";
      for (const char *pc : {PCJACOBI, PCNONE}) {
        INFO("pc " << pc);
        check_mcg_same_as_cg(B, b, pc, floor_off);
      }
      // binbcsr double storage is the same operator as aij: same iterates as mcg on aij
      if (precision == MAT_BINBCSR_PRECISION_DOUBLE) {
        const Result on_aij = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-30, 8});
        const Result on_bin = solve(B, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-30, 8});
        CHECK(rel_diff(on_bin.x, on_aij.x) < 1e-12);
      }
      MatDestroy(&B);
    }
    MatDestroy(&A);
    VecDestroy(&b);
  }
}

TEST_CASE("mcg uses the fused product of binbcsr and says so", "[ksp_mcg][binbcsr]")
{
  Mat A = block_laplacian(5, 5);
  Mat B = to_binbcsr(A, MAT_BINBCSR_PRECISION_SINGLE);
  if (!B) {
    WARN("binbcsr not available on this communicator: skipped");
    MatDestroy(&A);
    return;
  }
  Vec               b    = rhs(A);
  const std::string text = view_after_solve(B, b);
  CHECK(text.find("fast path: on, Jacobi fused") != std::string::npos);
  CHECK(text.find("fused with u.Au: yes") != std::string::npos);
  CHECK(text.find("single precision") != std::string::npos);
  // default rtol 1e-5 is far above the rounding drift: convergence accepted without an extra product
  CHECK(text.find("estimated rounding drift") != std::string::npos);
  CHECK(text.find("true-residual checks") == std::string::npos);
  VecDestroy(&b);
  MatDestroy(&B);
  MatDestroy(&A);
}

TEST_CASE("single storage: rtol 1e-6 converges, rtol 1e-11 stops at the precision floor",
          "[ksp_mcg][binbcsr]")
{
  Mat A = block_laplacian(12, 12);
  Mat B = to_binbcsr(A, MAT_BINBCSR_PRECISION_SINGLE);
  if (!B) {
    WARN("binbcsr not available on this communicator: skipped");
    MatDestroy(&A);
    return;
  }
  Vec       b = rhs(A);
  PetscReal bnorm;
  VecNorm(b, NORM_2, &bnorm);
  // rtol 1e-6: reachable also against the double-precision matrix
  Result r = solve(B, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-6});
  CHECK(r.reason == KSP_CONVERGED_RTOL);
  CHECK(rel_residual(A, b, r.x) < 2e-6);
  // rtol 1e-11 with the precision floor off: met on the operator MCG was given (up to the recursive
  // residual's rounding drift) ...
  r = solve(B, b,
            Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-11, 1000, 0, "-ksp_mcg_precision_floor 0"});
  CHECK(r.reason == KSP_CONVERGED_RTOL);
  CHECK(rel_residual(B, b, r.x) < 1.05e-11);
  // ... but against the double-precision values the residual stays at float rounding level
  const PetscReal floor_vs_double = rel_residual(A, b, r.x);
  CHECK(floor_vs_double > 1e-10);
  CHECK(floor_vs_double < 1e-5);
  // by default no such claim: stopped at the floor, which is reported as the residual norm and is
  // not below the residual against the double-precision values
  r = solve(B, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-11});
  CHECK(r.reason == KSP_DIVERGED_BREAKDOWN);
  const PetscReal true_vs_double = rel_residual(A, b, r.x);
  CHECK(r.rnorm / bnorm >= true_vs_double);
  CHECK(r.rnorm / bnorm < 20 * true_vs_double);
  CHECK(true_vs_double < 2 * floor_vs_double); // as accurate as iterating on
  MatDestroy(&B);
  MatDestroy(&A);
  VecDestroy(&b);
}
