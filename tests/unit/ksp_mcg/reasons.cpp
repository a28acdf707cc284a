// KSPMCG reports a defined KSPConvergedReason for bad input: it never divides by zero, never loops
// past max_it and never reports a non-converged solve as converged.
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"

using namespace mcg_test;

TEST_CASE("indefinite operator or preconditioner", "[ksp_mcg][reasons]")
{
  Mat A = diagonal({3, 2, -1, 4, 1});
  Vec b = rhs(A);
  // no PC: r.r > 0 but p.Ap <= 0 at some step
  Result r = solve(A, b, Solve{KSPMCG, PCNONE});
  CHECK(r.err == 0);
  CHECK(r.reason == KSP_DIVERGED_INDEFINITE_MAT);
  // Jacobi on a negative definite matrix: r.M^-1 r < 0
  Mat N = diagonal({-3, -2, -1, -4, -1});
  r     = solve(N, b, Solve{KSPMCG, PCJACOBI});
  CHECK(r.reason == KSP_DIVERGED_INDEFINITE_PC);
  // same through the generic (PCApply) path
  r = solve(N, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1000, 0, "-ksp_mcg_fused_pc 0"});
  CHECK(r.reason == KSP_DIVERGED_INDEFINITE_PC);
  MatDestroy(&A);
  MatDestroy(&N);
  VecDestroy(&b);
}

TEST_CASE("singular operator", "[ksp_mcg][reasons]")
{
  Mat A = diagonal({1, 2, 0, 3});
  // inconsistent right-hand side (component in the null space): no solution, must not converge
  Vec    b = rhs(A, false, 1.0);
  Result r = solve(A, b, Solve{KSPMCG, PCNONE});
  CHECK(r.err == 0);
  CHECK(r.reason < 0);
  CHECK(r.its <= 1000);
  // consistent right-hand side: converges
  VecSetValue(b, 2, 0.0, INSERT_VALUES);
  VecAssemblyBegin(b);
  VecAssemblyEnd(b);
  r = solve(A, b, Solve{KSPMCG, PCNONE});
  CHECK(r.reason > 0);
  CHECK(r.x[0] == Approx(1.0));
  CHECK(r.x[3] == Approx(1.0 / 3.0));
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("zero right-hand side", "[ksp_mcg][reasons]")
{
  Mat          A  = block_laplacian(4, 3);
  Vec          b  = rhs(A, false, 0.0);
  const Result cg = solve(A, b, Solve{KSPCG, PCJACOBI});
  Result       r  = solve(A, b, Solve{KSPMCG, PCJACOBI});
  CHECK(r.reason > 0);
  CHECK(r.reason == cg.reason);
  CHECK(r.its == 0);
  CHECK(rel_diff(r.x, cg.x) == 0.0);
  // fixed-iteration mode cannot iterate on r = 0: converged, not garbage
  r = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1000, 30});
  CHECK(r.reason == KSP_CONVERGED_ATOL);
  CHECK(r.its == 0);
  for (PetscScalar v : r.x) CHECK(v == 0.0);
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("NaN or Inf in the right-hand side", "[ksp_mcg][reasons]")
{
  Mat A = block_laplacian(4, 3);
  Vec b = rhs(A);
  VecSetValue(b, 5, PETSC_MAX_REAL * 10.0 - PETSC_MAX_REAL * 10.0, INSERT_VALUES); // NaN
  VecAssemblyBegin(b);
  VecAssemblyEnd(b);
  for (const char *pc : {PCJACOBI, PCNONE, PCBJACOBI}) {
    INFO(pc);
    Result r = solve(A, b, Solve{KSPMCG, pc});
    CHECK(r.err == 0);
    CHECK(r.reason == KSP_DIVERGED_NANORINF);
    r = solve(A, b, Solve{KSPMCG, pc, KSP_NORM_DEFAULT, 1e-10, 1000, 10});
    CHECK(r.reason == KSP_DIVERGED_NANORINF);
  }
  VecSetValue(b, 5, PETSC_INFINITY, INSERT_VALUES);
  VecAssemblyBegin(b);
  VecAssemblyEnd(b);
  const Result r = solve(A, b, Solve{KSPMCG, PCJACOBI});
  CHECK(r.reason == KSP_DIVERGED_NANORINF);
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("max_it 0 and 1", "[ksp_mcg][reasons]")
{
  Mat    A  = block_laplacian(5, 5);
  Vec    b  = rhs(A);
  Result r0 = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 0});
  CHECK(r0.err == 0);
  CHECK(r0.reason == KSP_DIVERGED_ITS);
  CHECK(r0.its == 0);
  for (PetscScalar v : r0.x) CHECK(v == 0.0);
  Result       r1 = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1});
  const Result c1 = solve(A, b, Solve{KSPCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1});
  CHECK(r1.reason == KSP_DIVERGED_ITS);
  CHECK(r1.its == 1);
  CHECK(rel_diff(r1.x, c1.x) < 1e-12);
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("zero diagonal entries are treated as PCJACOBI treats them", "[ksp_mcg][jacobi]")
{
  // symmetric, zero diagonal entry in row 1; fused Jacobi and PCApply(PCJACOBI) must agree
  Mat          A     = diagonal({4, 0, 2, 5});
  Vec          b     = rhs(A);
  const Result fused = solve(A, b, Solve{KSPMCG, PCJACOBI});
  const Result generic =
    solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1000, 0, "-ksp_mcg_fused_pc 0"});
  CHECK(fused.reason == generic.reason);
  CHECK(fused.its == generic.its);
  CHECK(fused.reason < 0); // singular and inconsistent: must not claim convergence
  REQUIRE(fused.history.size() == generic.history.size());
  for (size_t k = 0; k < fused.history.size(); k++)
    CHECK(fused.history[k] == Approx(generic.history[k]).epsilon(1e-14));
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("an unattainable tolerance is not reported as converged", "[ksp_mcg][reasons]")
{
  // rtol far below what double precision can reach on this system: the recursive residual may go
  // below it, the true residual cannot; MCG must stop with a negative reason, not claim RTOL.
  Mat    A = block_laplacian(20, 20);
  Vec    b = rhs(A);
  Result r = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-22, 5000});
  CHECK(r.err == 0);
  CHECK(r.reason < 0);
  CHECK(r.its < 5000);
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("a NaN tolerance from the options database is an error, not a breakdown", "[ksp_mcg][reasons]")
{
  // -ksp_rtol nan reached the solve unchecked: it ran to max_it and reported DIVERGED_INDEFINITE_MAT
  // (PETSc 3.22's KSPSetFromOptions refuses the value itself, 3.18's stores it: solve() reports either)
  Mat A = diagonal({3, 2, 1, 4});
  Vec b = rhs(A);
  for (const char *opt : {"-ksp_rtol nan", "-ksp_atol nan", "-ksp_divtol nan"}) {
    CAPTURE(opt);
    Result r = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1000, 0, opt});
    CHECK(r.err == PETSC_ERR_ARG_OUTOFRANGE);
  }
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("errors on bad setter input", "[ksp_mcg]")
{
  KSP ksp;
  KSPCreate(PETSC_COMM_WORLD, &ksp);
  KSPSetType(ksp, KSPMCG);
  CHECK(KSPMCGSetFixedIterations(ksp, -1) != 0);
  CHECK(KSPMCGSetFixedIterations(ksp, 30) == 0);
  PetscInt n = 0;
  CHECK(KSPMCGGetFixedIterations(ksp, &n) == 0);
  CHECK(n == 30);
  KSPDestroy(&ksp);
}

TEST_CASE("fixed iterations far past convergence end converged, not in a breakdown", "[ksp_mcg][reasons]")
{
  // 1000 iterations on systems that converge in a few dozen: the recursive residual goes on shrinking
  // until r.M^-1 r or p.Ap are lost to rounding; that is a converged solve (KSPCG with norm none and
  // no convergence test says CONVERGED_ATOL), whatever the rounding does on 1 or 2 ranks
  for (PetscInt n : {6, 10, 16}) {
    Mat A = block_laplacian(n, n);
    Vec b = rhs(A);
    for (const char *pc : {PCJACOBI, PCNONE, PCPBJACOBI}) {
      INFO("grid " << n << ", pc " << pc);
      const Result r = solve(A, b, Solve{KSPMCG, pc, KSP_NORM_DEFAULT, 1e-10, 1000, 1000});
      REQUIRE(r.err == 0);
      CHECK(r.reason > 0);
      CHECK(rel_residual(A, b, r.x) < 1e-12);
      const Result none =
        solve(A, b, Solve{KSPMCG, pc, KSP_NORM_NONE, 1e-10, 1000, 0, "-ksp_convergence_test skip"});
      REQUIRE(none.err == 0);
      CHECK(none.reason > 0);
      CHECK(rel_residual(A, b, none.x) < 1e-12);
    }
    MatDestroy(&A);
    VecDestroy(&b);
  }
}

TEST_CASE("a NaN in the matrix or the right-hand side is reported as a NaN residual norm",
          "[ksp_mcg][reasons]")
{
  const PetscScalar nan = PETSC_MAX_REAL * 10.0 - PETSC_MAX_REAL * 10.0;
  PetscMPIInt       rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  Mat A = block_laplacian(4, 3);
  Vec b = rhs(A);
  Vec bn;
  VecDuplicate(b, &bn);
  VecCopy(b, bn);
  VecSetValue(bn, 5, nan, INSERT_VALUES);
  VecAssemblyBegin(bn);
  VecAssemblyEnd(bn);
  Mat An;
  MatDuplicate(A, MAT_COPY_VALUES, &An);
  if (!rank) MatSetValue(An, 4, 4, nan, INSERT_VALUES);
  MatAssemblyBegin(An, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(An, MAT_FINAL_ASSEMBLY);
  for (const char *pc : {PCJACOBI, PCNONE, PCBJACOBI}) {
    for (PetscInt fixed : {0, 10}) {
      INFO("pc " << pc << ", fixed iterations " << fixed);
      const Result rb = solve(A, bn, Solve{KSPMCG, pc, KSP_NORM_DEFAULT, 1e-10, 1000, fixed});
      CHECK(rb.reason == KSP_DIVERGED_NANORINF);
      CHECK(PetscIsInfOrNanReal(rb.rnorm));
      const Result ra = solve(An, b, Solve{KSPMCG, pc, KSP_NORM_DEFAULT, 1e-10, 1000, fixed});
      CHECK(ra.reason < 0);
      CHECK(PetscIsInfOrNanReal(ra.rnorm));
    }
  }
  MatDestroy(&An);
  MatDestroy(&A);
  VecDestroy(&bn);
  VecDestroy(&b);
}
