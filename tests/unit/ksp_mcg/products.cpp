// Counts matrix products: KSPMCG makes one per iteration, plus one at the start (w = A u); the last
// allowed iteration of a solve skips its product (nothing would use it), so a fixed-iteration solve
// of N iterations makes exactly N products, as KSPCG does; on one process a solve to a tolerance skips
// the product after the converged iteration too.
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"

using namespace mcg_test;

namespace {
struct Counted {
  Mat  inner;
  long mults = 0;
};

PetscErrorCode CountedMult(Mat S, Vec x, Vec y)
{
  Counted *c;
  PetscFunctionBegin;
  PetscCall(MatShellGetContext(S, &c));
  c->mults++;
  PetscCall(MatMult(c->inner, x, y));
  PetscFunctionReturn(0);
}

PetscErrorCode CountedDiagonal(Mat S, Vec d)
{
  Counted *c;
  PetscFunctionBegin;
  PetscCall(MatShellGetContext(S, &c));
  PetscCall(MatGetDiagonal(c->inner, d));
  PetscFunctionReturn(0);
}

Mat counted(Counted *c)
{
  PetscInt m, n, M, N;
  Mat      S;
  MatGetLocalSize(c->inner, &m, &n);
  MatGetSize(c->inner, &M, &N);
  MatCreateShell(PETSC_COMM_WORLD, m, n, M, N, c, &S);
  MatShellSetOperation(S, MATOP_MULT, (void (*)(void))CountedMult);
  MatShellSetOperation(S, MATOP_GET_DIAGONAL, (void (*)(void))CountedDiagonal);
  return S;
}
} // namespace

TEST_CASE("matrix products per solve", "[ksp_mcg][passes]")
{
  Counted c;
  c.inner = block_laplacian(10, 10);
  Mat S   = counted(&c);
  Vec b   = rhs(c.inner);

  c.mults  = 0;
  Result r = solve(S, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-10, 1000, 30});
  CHECK(r.reason == KSP_CONVERGED_ITS);
  CHECK(r.its == 30);
  CHECK(c.mults == 30);

  c.mults = 0;
  r       = solve(S, b, Solve{KSPCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-30, 30});
  CHECK(c.mults == 30);

  // to a tolerance far above the rounding drift: one product per iteration plus the first one; on
  // one process the product after the converged iteration is not made (the reduction is free there,
  // so the test comes first), which leaves one per iteration, as KSPCG
  PetscMPIInt size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  c.mults = 0;
  r       = solve(S, b, Solve{KSPMCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-6});
  CHECK(r.reason == KSP_CONVERGED_RTOL);
  CHECK(c.mults == r.its + (size > 1 ? 1 : 0));
  const PetscInt mcg_its = r.its;
  c.mults                = 0;
  r                      = solve(S, b, Solve{KSPCG, PCJACOBI, KSP_NORM_DEFAULT, 1e-6});
  CHECK(r.its == mcg_its);
  if (size == 1) CHECK(c.mults == r.its);

  MatDestroy(&S);
  MatDestroy(&c.inner);
  VecDestroy(&b);
}
