// Helpers of the MATMPIBINBCSR tests (mpibinbcsr.cpp, mpibinbcsr_sym.cpp): the FEM problem's matrix
// assembled every way, compared with the serial matrix and with MPIAIJ. Every check is collective.
#pragma once
#include <catch2/catch.hpp>

#include "support/fem_problem.hpp"
#include <petsc/private/petscimpl.h> // PetscObjectStateGet

#include <cmath>
#include <cstdio>
#include <string>
#include <unistd.h>

using namespace mpitest;

#define PCHK(expr) REQUIRE((expr) == 0)

namespace {

enum class Fill {
  Blocked,
  Coo,
  ScalarOwnRows
};

const char *fill_name(Fill f)
{
  return f == Fill::Blocked ? "blocked+stash" : f == Fill::Coo ? "coo" : "scalar own rows";
}

// parts: type of the diagonal/off-diagonal parts (-mat_mpibinbcsr_inner_type), default seqbinbcsr.
PetscErrorCode assemble(const FemProblem &fem, MatType type, Fill fill, bool empty_rank0, Mat *A,
                        const char *parts = nullptr)
{
  MPI_Comm    comm = PETSC_COMM_WORLD;
  PetscMPIInt rank, size;

  PetscFunctionBeginUser;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const PetscInt m = local_rows(fem, comm, empty_rank0);
  PetscCall(MatCreate(comm, A));
  PetscCall(MatSetSizes(*A, m, m, fem.rows(), fem.rows()));
  PetscCall(MatSetBlockSize(*A, 3));
  PetscCall(MatSetType(*A, type));
  if (parts) PetscCall(PetscOptionsSetValue(nullptr, "-mat_mpibinbcsr_inner_type", parts));
  PetscCall(MatSetFromOptions(*A));
  if (parts) PetscCall(PetscOptionsClearValue(nullptr, "-mat_mpibinbcsr_inner_type"));
  if (fill == Fill::Coo) {
    std::vector<PetscInt>    ci, cj;
    std::vector<PetscScalar> cv = rank_element_values(fem, [](int) { return 1.0; });
    rank_coo_entries(fem, ci, cj);
    ci.push_back(-1); // ignored, by PETSc's convention
    cj.push_back(0);
    cv.push_back(1e30);
    PetscCall(MatSetPreallocationCOO(*A, static_cast<PetscCount>(ci.size()), ci.data(), cj.data()));
    PetscCall(MatSetValuesCOO(*A, cv.data(), INSERT_VALUES));
    PetscFunctionReturn(0);
  }
  PetscCall(MatMPIAIJSetPreallocation(*A, 81, nullptr, 81, nullptr));
  PetscCall(MatSeqAIJSetPreallocation(*A, 81, nullptr));
  PetscInt rstart, rend;
  PetscCall(MatGetOwnershipRange(*A, &rstart, &rend));
  for (int e = 0; e < fem.element_count(); ++e) {
    const auto K = fem.element_matrix(e);
    if (fill == Fill::Blocked) {
      if (e % size != rank) continue;
      const auto blk = fem.element_blocks(e);
      PetscCall(MatSetValuesBlocked(*A, 8, blk.data(), 8, blk.data(), K.data(), ADD_VALUES));
    } else { // every rank adds the rows it owns, entry by entry
      const auto r = fem.element_rows(e);
      for (int a = 0; a < 24; ++a) {
        if (r[a] < rstart || r[a] >= rend) continue;
        PetscCall(MatSetValues(*A, 1, &r[a], 24, r.data(), &K[a * 24], ADD_VALUES));
      }
    }
  }
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

// This rank's COO values in assemble()'s order, element e scaled by weight(e), and a value for the
// ignored entry assemble() appends.
template <class Weight> std::vector<PetscScalar> rank_coo_values(const FemProblem &fem, Weight weight)
{
  std::vector<PetscScalar> cv = rank_element_values(fem, weight);
  cv.push_back(0);
  return cv;
}

PetscErrorCode serial_reference(const FemProblem &fem, Mat *S)
{
  PetscFunctionBeginUser;
  PetscCall(MatCreateSeqAIJ(PETSC_COMM_SELF, fem.rows(), fem.rows(), 81, nullptr, S));
  for (int e = 0; e < fem.element_count(); ++e) {
    const auto r = fem.element_rows(e);
    const auto K = fem.element_matrix(e);
    PetscCall(MatSetValues(*S, 24, r.data(), 24, r.data(), K.data(), ADD_VALUES));
  }
  PetscCall(MatAssemblyBegin(*S, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*S, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

double test_value(PetscInt i) { return std::sin(0.37 * i + 1.0) + 0.25 * (i % 3); }

PetscErrorCode fill_test_vector(Vec v, int salt = 0)
{
  PetscInt     lo, hi;
  PetscScalar *a;
  PetscFunctionBeginUser;
  PetscCall(VecGetOwnershipRange(v, &lo, &hi));
  PetscCall(VecGetArray(v, &a));
  for (PetscInt i = lo; i < hi; ++i) a[i - lo] = test_value(i + 17 * salt);
  PetscCall(VecRestoreArray(v, &a));
  PetscFunctionReturn(0);
}

// A KSP of the given type and PC on A, to rtol 1e-10.
PetscErrorCode create_solver(Mat A, KSPType kt, PCType pt, KSP *ksp)
{
  PC pc;
  PetscFunctionBeginUser;
  PetscCall(KSPCreate(PETSC_COMM_WORLD, ksp));
  PetscCall(KSPSetOperators(*ksp, A, A));
  PetscCall(KSPSetType(*ksp, kt));
  PetscCall(KSPGetPC(*ksp, &pc));
  PetscCall(PCSetType(pc, pt));
  PetscCall(KSPSetTolerances(*ksp, 1e-10, 1e-50, PETSC_DEFAULT, 1000));
  PetscFunctionReturn(0);
}

// Solves A x = b with the given KSP and PC to rtol 1e-10 (x is the initial guess and the result);
// returns the iterations and, through reason, why it stopped.
PetscErrorCode solve_to_tolerance(Mat A, Vec b, Vec x, KSPType kt, PCType pt, PetscInt *its,
                                  KSPConvergedReason *reason)
{
  KSP ksp;
  PetscFunctionBeginUser;
  PetscCall(create_solver(A, kt, pt, &ksp));
  PetscCall(KSPSolve(ksp, b, x));
  PetscCall(KSPGetIterationNumber(ksp, its));
  PetscCall(KSPGetConvergedReason(ksp, reason));
  PetscCall(KSPDestroy(&ksp));
  PetscFunctionReturn(0);
}

// max |y_par[i] - y_seq[i]| over the rows of this rank, relative to max |y_seq|.
double local_rel_diff(Vec ypar, Vec yseq)
{
  PetscInt           lo, hi, n;
  const PetscScalar *a, *s;
  VecGetOwnershipRange(ypar, &lo, &hi);
  VecGetSize(yseq, &n);
  VecGetArrayRead(ypar, &a);
  VecGetArrayRead(yseq, &s);
  double diff = 0, scale = 1e-300;
  for (PetscInt i = 0; i < n; ++i) scale = std::max(scale, std::abs(s[i]));
  for (PetscInt i = lo; i < hi; ++i) diff = std::max(diff, std::abs(a[i - lo] - s[i]));
  VecRestoreArrayRead(ypar, &a);
  VecRestoreArrayRead(yseq, &s);
  return diff / scale;
}

// The serial vector that equals the parallel test vector (every rank holds all of it).
PetscErrorCode serial_test_vector(PetscInt n, int salt, Vec *v)
{
  PetscFunctionBeginUser;
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, n, v));
  PetscScalar *a;
  PetscCall(VecGetArray(*v, &a));
  for (PetscInt i = 0; i < n; ++i) a[i] = test_value(i + 17 * salt);
  PetscCall(VecRestoreArray(*v, &a));
  PetscFunctionReturn(0);
}

const double tol = 1e-13;

void check_products(Mat A, Mat S)
{
  PetscInt n;
  Vec      x, y, z, xs, ys, zs;
  PCHK(MatGetSize(S, &n, nullptr));
  PCHK(MatCreateVecs(A, &x, &y));
  PCHK(VecDuplicate(y, &z));
  PCHK(fill_test_vector(x));
  PCHK(fill_test_vector(z, 1));
  PCHK(serial_test_vector(n, 0, &xs));
  PCHK(serial_test_vector(n, 1, &zs));
  PCHK(VecDuplicate(xs, &ys));

  PCHK(MatMult(A, x, y));
  PCHK(MatMult(S, xs, ys));
  CHECK(all_ranks(local_rel_diff(y, ys) < tol));

  PCHK(MatMultAdd(A, x, z, y));
  PCHK(MatMultAdd(S, xs, zs, ys));
  CHECK(all_ranks(local_rel_diff(y, ys) < tol));

  PCHK(MatMultTranspose(A, x, y));
  PCHK(MatMultTranspose(S, xs, ys));
  CHECK(all_ranks(local_rel_diff(y, ys) < tol));

  PCHK(MatMultTransposeAdd(A, x, z, y));
  PCHK(MatMultTransposeAdd(S, xs, zs, ys));
  CHECK(all_ranks(local_rel_diff(y, ys) < tol));

  PCHK(MatGetDiagonal(A, y));
  PCHK(MatGetDiagonal(S, ys));
  CHECK(all_ranks(local_rel_diff(y, ys) < tol));

  // fused product + local dot, reduced by the caller
  PetscScalar local, global, ref;
  PCHK(MatMultDotLocal(A, x, y, &local));
  MPI_Allreduce(&local, &global, 1, MPIU_SCALAR, MPIU_SUM, PETSC_COMM_WORLD);
  PCHK(MatMult(S, xs, ys));
  PCHK(VecDot(xs, ys, &ref));
  CHECK(all_ranks(local_rel_diff(y, ys) < tol));
  CHECK(std::abs(global - ref) <= tol * std::abs(ref));

  for (NormType t : {NORM_FROBENIUS, NORM_1, NORM_INFINITY}) {
    PetscReal na, ns;
    PCHK(MatNorm(A, t, &na));
    PCHK(MatNorm(S, t, &ns));
    CHECK(std::abs(na - ns) <= 1e-12 * ns);
  }
  for (Vec *v : {&x, &y, &z, &xs, &ys, &zs}) VecDestroy(v);
}

} // namespace
