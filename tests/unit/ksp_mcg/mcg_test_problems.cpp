#include "mcg_test_problems.hpp"
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <unistd.h>

namespace mcg_test {

Mat block_laplacian(PetscInt nx, PetscInt ny, const char *mattype, PetscReal neumann_shift)
{
  const PetscInt    bs = 3, nodes = nx * ny;
  const PetscScalar K[3][3]     = {{4, 1, 0}, {1, 3, 1}, {0, 1, 2}};
  PetscInt          local_nodes = PETSC_DECIDE, global_nodes = nodes, start;
  Mat               A;
  PetscSplitOwnership(PETSC_COMM_WORLD, &local_nodes, &global_nodes);
  MPI_Scan(&local_nodes, &start, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD);
  start -= local_nodes;
  MatCreate(PETSC_COMM_WORLD, &A);
  MatSetSizes(A, bs * local_nodes, bs * local_nodes, PETSC_DETERMINE, PETSC_DETERMINE);
  MatSetType(A, mattype);
  MatSetBlockSize(A, bs);
  MatSeqAIJSetPreallocation(A, 5 * bs, nullptr);
  MatMPIAIJSetPreallocation(A, 5 * bs, nullptr, 4 * bs, nullptr);
  MatSetUp(A);
  MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE);
  auto scale = [&](PetscInt node) { return 1.0 + 0.5 * std::sin(0.37 * node); };
  for (PetscInt node = start; node < start + local_nodes; node++) {
    const PetscInt i = node % nx, j = node / nx;
    const PetscInt nb[5][2]   = {{i, j}, {i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
    PetscInt       neighbours = 0;
    for (int k = 1; k < 5; k++)
      neighbours += nb[k][0] >= 0 && nb[k][1] >= 0 && nb[k][0] < nx && nb[k][1] < ny;
    const PetscScalar centre = neumann_shift >= 0 ? neighbours + neumann_shift : 4.0 + 1.0;
    for (int k = 0; k < 5; k++) {
      const PetscInt ni = nb[k][0], nj = nb[k][1];
      if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
      const PetscInt    other = nj * nx + ni;
      const PetscScalar lap   = k == 0 ? centre : -1.0; // shifted Laplacian: SPD
      for (PetscInt a = 0; a < bs; a++)
        for (PetscInt b = 0; b < bs; b++) {
          const PetscScalar v = lap * K[a][b] * scale(node) * scale(other);
          if (v != 0.0) MatSetValue(A, bs * node + a, bs * other + b, v, INSERT_VALUES);
        }
    }
  }
  MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
  return A;
}

Mat diagonal(const std::vector<PetscScalar> &d)
{
  PetscMPIInt rank;
  Mat         A;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  const PetscInt n = (PetscInt)d.size(), local = rank == 0 ? n : 0;
  MatCreateAIJ(PETSC_COMM_WORLD, local, local, n, n, 1, nullptr, 0, nullptr, &A);
  if (rank == 0)
    for (PetscInt i = 0; i < n; i++) MatSetValue(A, i, i, d[i], INSERT_VALUES);
  MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
  return A;
}

Vec rhs(Mat A, bool ramp, PetscScalar value)
{
  Vec      b;
  PetscInt lo, hi;
  MatCreateVecs(A, nullptr, &b);
  VecGetOwnershipRange(b, &lo, &hi);
  for (PetscInt i = lo; i < hi; i++)
    VecSetValue(b, i, ramp ? value * (1.0 + std::cos(1.3 * i)) : value, INSERT_VALUES);
  VecAssemblyBegin(b);
  VecAssemblyEnd(b);
  return b;
}

std::vector<PetscScalar> gather(Vec x)
{
  VecScatter         sc;
  Vec                all;
  PetscInt           n;
  const PetscScalar *a;
  VecScatterCreateToAll(x, &sc, &all);
  VecScatterBegin(sc, x, all, INSERT_VALUES, SCATTER_FORWARD);
  VecScatterEnd(sc, x, all, INSERT_VALUES, SCATTER_FORWARD);
  VecGetSize(all, &n);
  VecGetArrayRead(all, &a);
  std::vector<PetscScalar> out(a, a + n);
  VecRestoreArrayRead(all, &a);
  VecScatterDestroy(&sc);
  VecDestroy(&all);
  return out;
}

Result solve(Mat A, Vec b, const Solve &s, Vec x0)
{
  Result           r;
  KSP              ksp;
  PC               pc;
  Vec              x;
  PetscInt         nhist;
  PetscReal        hist[4096];
  const PetscReal *h;

  VecDuplicate(b, &x);
  if (x0) VecCopy(x0, x);
  else VecSet(x, 0.0);
  KSPCreate(PETSC_COMM_WORLD, &ksp);
  KSPSetOperators(ksp, A, A);
  KSPSetType(ksp, s.type.c_str());
  KSPGetPC(ksp, &pc);
  PCSetType(pc, s.pc.c_str());
  KSPSetTolerances(ksp, s.rtol, 1e-50, PETSC_DEFAULT, s.max_it);
  if (s.norm != KSP_NORM_DEFAULT) KSPSetNormType(ksp, s.norm);
  if (x0) KSPSetInitialGuessNonzero(ksp, PETSC_TRUE);
  KSPSetResidualHistory(ksp, hist, 4096, PETSC_TRUE);
  if (s.fixed_its) KSPMCGSetFixedIterations(ksp, s.fixed_its);
  PetscOptionsInsertString(nullptr, s.options);
  r.err = KSPSetFromOptions(ksp); // an option PETSc refuses is the result too (3.22 refuses -ksp_rtol nan)
  if (!r.err) r.err = KSPSolve(ksp, b, x);
  KSPGetConvergedReason(ksp, &r.reason);
  KSPGetIterationNumber(ksp, &r.its);
  KSPGetResidualNorm(ksp, &r.rnorm);
  KSPMCGGetPrecisionFloor(ksp, &r.floor, &r.floor_stopped);
  KSPGetResidualHistory(ksp, &h, &nhist);
  r.history.assign(h, h + nhist);
  r.x = gather(x);
  PetscOptionsClear(nullptr);
  KSPDestroy(&ksp);
  VecDestroy(&x);
  return r;
}

PetscReal rel_diff(const std::vector<PetscScalar> &a, const std::vector<PetscScalar> &b)
{
  PetscReal d = 0, n = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); i++) {
    d += PetscRealPart((a[i] - b[i]) * (a[i] - b[i]));
    n += PetscRealPart(b[i] * b[i]);
  }
  if (a.size() != b.size()) return PETSC_MAX_REAL;
  return n > 0 ? std::sqrt(d / n) : std::sqrt(d);
}

// The aij test matrix converted to binbcsr; nullptr (and a warning) where binbcsr is not available
// for this communicator (MPI binbcsr may not have landed yet).
Mat to_binbcsr(Mat aij, MatBinBCSRPrecision precision)
{
  Mat         B = nullptr;
  PetscMPIInt size;
  MPI_Comm_size(PetscObjectComm((PetscObject)aij), &size);
  const PetscErrorCode err = MatConvert(aij, MATBINBCSR, MAT_INITIAL_MATRIX, &B);
  if (size == 1) REQUIRE(err == 0); // the sequential type is there: no skipping
  if (err) return nullptr;
  REQUIRE(MatBinBCSRSetPrecision(B, precision) == 0);
  return B;
}

void check_mcg_same_as_cg(Mat A, Vec b, const char *pc, const char *options)
{
  const Result cg  = solve(A, b, Solve{KSPCG, pc, KSP_NORM_UNPRECONDITIONED, 1e-10});
  const Result mcg = solve(A, b, Solve{KSPMCG, pc, KSP_NORM_UNPRECONDITIONED, 1e-10, 1000, 0, options});
  REQUIRE(mcg.err == 0);
  CHECK(cg.reason > 0);
  CHECK(mcg.reason == cg.reason);
  CHECK(std::abs(mcg.its - cg.its) <= 1);
  CHECK(rel_diff(mcg.x, cg.x) < 1e-7);
  for (size_t k = 0;
       k < 15 && k < cg.history.size() && k < mcg.history.size() && cg.history[k] > 1e-9 * cg.history[0]; k++)
    CHECK(mcg.history[k] == Approx(cg.history[k]).epsilon(1e-8));
  // k iterates equal to round-off
  const Result cg5  = solve(A, b, Solve{KSPCG, pc, KSP_NORM_UNPRECONDITIONED, 1e-30, 5});
  const Result mcg5 = solve(A, b, Solve{KSPMCG, pc, KSP_NORM_UNPRECONDITIONED, 1e-30, 5, 0, options});
  CHECK(rel_diff(mcg5.x, cg5.x) < 1e-12);
}

PetscReal rel_residual(Mat A, Vec b, const std::vector<PetscScalar> &x)
{
  Vec       xv, r;
  PetscInt  lo, hi;
  PetscReal rn, bn;
  VecDuplicate(b, &xv);
  VecDuplicate(b, &r);
  VecGetOwnershipRange(xv, &lo, &hi);
  for (PetscInt i = lo; i < hi; i++) VecSetValue(xv, i, x[i], INSERT_VALUES);
  VecAssemblyBegin(xv);
  VecAssemblyEnd(xv);
  MatMult(A, xv, r);
  VecAYPX(r, -1.0, b);
  VecNorm(r, NORM_2, &rn);
  VecNorm(b, NORM_2, &bn);
  VecDestroy(&xv);
  VecDestroy(&r);
  return rn / bn;
}

std::string view_after_solve(Mat A, Vec b, const char *options)
{
  KSP         ksp;
  PC          pc;
  Vec         x;
  PetscViewer viewer;
  char        path[] = "/tmp/ksp_mcg_view_XXXXXX";
  PetscMPIInt rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) {
    const int fd = mkstemp(path);
    REQUIRE(fd >= 0);
    close(fd);
  }
  MPI_Bcast(path, sizeof path, MPI_CHAR, 0, PETSC_COMM_WORLD);
  VecDuplicate(b, &x);
  KSPCreate(PETSC_COMM_WORLD, &ksp);
  KSPSetOperators(ksp, A, A);
  KSPSetType(ksp, KSPMCG);
  KSPGetPC(ksp, &pc);
  PCSetType(pc, PCJACOBI);
  PetscOptionsInsertString(nullptr, options);
  KSPSetFromOptions(ksp);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  PetscViewerASCIIOpen(PETSC_COMM_WORLD, path, &viewer);
  KSPView(ksp, viewer);
  PetscViewerDestroy(&viewer);
  PetscOptionsClear(nullptr);
  MPI_Barrier(PETSC_COMM_WORLD);
  FILE       *fp = fopen(path, "r");
  std::string text;
  char        line[512];
  while (fp && fgets(line, sizeof line, fp)) text += line;
  if (fp) fclose(fp);
  MPI_Barrier(PETSC_COMM_WORLD);
  if (rank == 0) remove(path);
  KSPDestroy(&ksp);
  VecDestroy(&x);
  return text;
}

} // namespace mcg_test
