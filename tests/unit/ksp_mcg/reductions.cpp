// Counts global reductions: MPI_Allreduce is wrapped here through the MPI profiling interface, so
// every call made by PETSc and by the plug-in during a solve passes through this counter.
#include <catch2/catch.hpp>
#include "mcg_test_problems.hpp"

using namespace mcg_test;

static long allreduce_calls = 0;

// petsclog.h turns MPI_Allreduce into a counting macro for code compiled against PETSc; the wrapper
// must define the real symbol.
#undef MPI_Allreduce

extern "C" int MPI_Allreduce(const void *sendbuf, void *recvbuf, int count, MPI_Datatype type, MPI_Op op,
                             MPI_Comm comm)
{
  allreduce_calls++;
  return PMPI_Allreduce(sendbuf, recvbuf, count, type, op, comm);
}

// Reductions made by one solve of `its` iterations that does not converge (rtol unreachable).
static long reductions_for(Mat A, Vec b, const char *type, KSPNormType norm, PetscInt its,
                           const char *options = "")
{
  const long   before = allreduce_calls;
  const Result r      = solve(A, b, Solve{type, PCJACOBI, norm, 1e-30, its, 0, options});
  REQUIRE(r.err == 0);
  REQUIRE(r.its == its);
  return allreduce_calls - before;
}

TEST_CASE("one global reduction per iteration", "[ksp_mcg][reductions]")
{
  // MPI vectors even on one rank, so that CG's dots and norms reduce too and the counter sees them
  Mat      A  = block_laplacian(12, 12, MATMPIAIJ);
  Vec      b0 = rhs(A), b;
  PetscInt n;
  VecGetLocalSize(b0, &n);
  VecCreateMPI(PETSC_COMM_WORLD, n, PETSC_DETERMINE, &b);
  VecCopy(b0, b);
  VecDestroy(&b0);
  // the counter sees the library's calls (sanity: CG makes two or three per iteration)
  const long cg_per_it = (reductions_for(A, b, KSPCG, KSP_NORM_UNPRECONDITIONED, 30) -
                          reductions_for(A, b, KSPCG, KSP_NORM_UNPRECONDITIONED, 20)) /
                         10;
  CHECK(cg_per_it == 3);
  for (KSPNormType norm :
       {KSP_NORM_PRECONDITIONED, KSP_NORM_UNPRECONDITIONED, KSP_NORM_NATURAL, KSP_NORM_NONE}) {
    INFO("norm " << KSPNormTypes[norm]);
    const long r20 = reductions_for(A, b, KSPMCG, norm, 20), r30 = reductions_for(A, b, KSPMCG, norm, 30);
    CHECK(r30 - r20 == 10);
    // the generic path (PCApply) too
    const long g20 = reductions_for(A, b, KSPMCG, norm, 20, "-ksp_mcg_fused_pc 0"),
               g30 = reductions_for(A, b, KSPMCG, norm, 30, "-ksp_mcg_fused_pc 0");
    CHECK(g30 - g20 == 10);
  }
  MatDestroy(&A);
  VecDestroy(&b);
}
