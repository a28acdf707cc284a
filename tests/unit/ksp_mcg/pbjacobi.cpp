// KSPMCG's fused point-block Jacobi (-pc_type pbjacobi, 3x3 blocks): the same iterates as KSPCG with
// PCPBJACOBI on every storage binbcsr offers, rebuilt when the values change, a singular block named.
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"
#include <cstring>

using namespace mcg_test;

namespace {

// binbcsr copy of the aij matrix with the given value precision and storage (nullptr where binbcsr is
// not available on this communicator)
Mat binbcsr_copy(Mat A, MatBinBCSRPrecision precision, bool symmetric)
{
  if (symmetric) PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", "1");
  Mat B = to_binbcsr(A, precision);
  if (symmetric) PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage");
  if (B && symmetric) {
    PetscBool sym = PETSC_FALSE;
    MatBinBCSRGetSymmetricStorage(B, &sym);
    CHECK(sym);
  }
  return B;
}

// the shared cg comparison, and the generic (PCApply) path's iterates equal to cg's
void check_same_as_cg(Mat B, Vec b, const char *floor)
{
  check_mcg_same_as_cg(B, b, PCPBJACOBI, floor);
  const Result      cg5     = solve(B, b, Solve{KSPCG, PCPBJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-30, 5});
  const std::string generic = std::string(floor) + " -ksp_mcg_fused_pc 0";
  const Result      g5 =
    solve(B, b, Solve{KSPMCG, PCPBJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-30, 5, 0, generic.c_str()});
  CHECK(rel_diff(g5.x, cg5.x) < 1e-12);
}

} // namespace

TEST_CASE("fused pbjacobi: same iterates as cg + pbjacobi on aij and every binbcsr storage",
          "[ksp_mcg][pbjacobi]")
{
  Mat A = block_laplacian(9, 11);
  Vec b = rhs(A);
  SECTION("aij") { check_same_as_cg(A, b, ""); }
  for (bool symmetric : {false, true})
    for (MatBinBCSRPrecision precision : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE}) {
      INFO("binbcsr " << (symmetric ? "symmetric" : "whole") << " storage, "
                      << MatBinBCSRPrecisions[precision]);
      Mat B = binbcsr_copy(A, precision, symmetric);
      if (!B) {
        WARN("binbcsr not available on this communicator: skipped");
        continue;
      }
      check_same_as_cg(B, b, "-ksp_mcg_precision_floor 0");
      const std::string text = view_after_solve(B, b, "-pc_type pbjacobi");
      CHECK(text.find("point-block Jacobi fused into the vector pass") != std::string::npos);
      MatDestroy(&B);
    }
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("fused pbjacobi beats fused jacobi on coupled 3x3 blocks", "[ksp_mcg][pbjacobi]")
{
  Mat          A  = block_laplacian(20, 20);
  Vec          b  = rhs(A);
  const Result jb = solve(A, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-8});
  const Result pb = solve(A, b, Solve{KSPMCG, PCPBJACOBI, KSP_NORM_UNPRECONDITIONED, 1e-8});
  CHECK(jb.reason > 0);
  CHECK(pb.reason > 0);
  CHECK(pb.its < jb.its);
  MatDestroy(&A);
  VecDestroy(&b);
}

TEST_CASE("fused pbjacobi follows a refill of the values", "[ksp_mcg][pbjacobi]")
{
  Mat A = block_laplacian(8, 8);
  Mat B = binbcsr_copy(A, MAT_BINBCSR_PRECISION_DOUBLE, false);
  if (!B) {
    WARN("binbcsr not available on this communicator: skipped");
    MatDestroy(&A);
    return;
  }
  Vec b = rhs(A);
  KSP ksp;
  PC  pc;
  Vec x;
  VecDuplicate(b, &x);
  KSPCreate(PETSC_COMM_WORLD, &ksp);
  KSPSetOperators(ksp, B, B);
  KSPSetType(ksp, KSPMCG);
  KSPGetPC(ksp, &pc);
  PCSetType(pc, PCPBJACOBI);
  KSPSetTolerances(ksp, 1e-10, 1e-50, PETSC_DEFAULT, 1000);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  // the same matrix with new values (a diagonal shift changes every diagonal block)
  REQUIRE(MatShift(B, 3.0) == 0);
  REQUIRE(MatShift(A, 3.0) == 0);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  KSPConvergedReason reason;
  PetscInt           its;
  KSPGetConvergedReason(ksp, &reason);
  KSPGetIterationNumber(ksp, &its);
  const std::vector<PetscScalar> xs = gather(x);
  const Result                   cg = solve(A, b, Solve{KSPCG, PCPBJACOBI, KSP_NORM_DEFAULT, 1e-10});
  CHECK(reason > 0);
  CHECK(std::abs(its - cg.its) <= 1);
  CHECK(rel_diff(xs, cg.x) < 1e-8);
  KSPDestroy(&ksp);
  VecDestroy(&x);
  VecDestroy(&b);
  MatDestroy(&B);
  MatDestroy(&A);
}

TEST_CASE("fused pbjacobi on a singular 3x3 diagonal block: an error naming the block row",
          "[ksp_mcg][pbjacobi]")
{
  Mat      A = block_laplacian(4, 4);
  PetscInt N;
  MatGetSize(A, &N, nullptr);
  const PetscInt row = N / 3 - 2; // on the last rank under MPI
  // make block row `row`'s diagonal block singular: rank 1 (its first two rows equal)
  PetscInt    lo, hi;
  PetscScalar v[9];
  PetscInt    idx[3] = {3 * row, 3 * row + 1, 3 * row + 2};
  MatGetOwnershipRange(A, &lo, &hi);
  for (int k = 0; k < 9; k++) v[k] = 1.0;
  if (3 * row >= lo && 3 * row < hi) MatSetValues(A, 3, idx, 3, idx, v, INSERT_VALUES);
  MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
  Vec b = rhs(A);
  for (bool bin : {false, true}) {
    INFO((bin ? "binbcsr" : "aij"));
    Mat B = bin ? binbcsr_copy(A, MAT_BINBCSR_PRECISION_DOUBLE, false) : A;
    if (!B) continue;
    const Result r = solve(B, b, Solve{KSPMCG, PCPBJACOBI});
    CHECK(r.err == PETSC_ERR_MAT_LU_ZRPVT);
    char *text = nullptr;
    PetscErrorMessage(r.err, nullptr, &text);
    REQUIRE(text);
    const std::string expected = "block row " + std::to_string(row) + " ";
    CHECK(std::strstr(text, expected.c_str()) != nullptr);
    CHECK(std::strstr(text, "singular") != nullptr);
    if (bin) MatDestroy(&B);
  }
  MatDestroy(&A);
  VecDestroy(&b);
}
