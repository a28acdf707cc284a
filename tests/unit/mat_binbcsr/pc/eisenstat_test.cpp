// PCEISENSTAT on binbcsr (seq on one rank, mpi on more; bs 1 and 3; full, symmetric and single storage):
// MatSOR's SOR_EISENSTAT and SOR_APPLY_UPPER and MatMultDiagonalBlock checked against identities built
// from the already-tested local sweeps and products, and the whole PC in GMRES against aij (same
// iterations, same solution), before and after a refill of the values. Every TEST_CASE is collective:
// this program runs as unit_pc and under mpiexec -n 2 and -n 3 (tests/pc.cmake).
#include "pc_support.hpp"

#include <petscksp.h>

using namespace pctest;

namespace {

PetscErrorCode sor(Mat A, Vec b, PetscReal omega, MatSORType flag, Vec x)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(x, 0.0));
  PetscCall(MatSOR(A, b, omega, flag, 0.0, 1, 1, x));
  PetscFunctionReturn(0);
}

// x = D^-1 y block by block, from MatInvertBlockDiagonal (column-major blocks, as BAIJ).
PetscErrorCode apply_inverse_blocks(Mat A, Vec y, Vec x)
{
  const PetscScalar *id, *ya;
  PetscScalar       *xa;
  PetscInt           bs, n;
  PetscFunctionBeginUser;
  PetscCall(MatGetBlockSize(A, &bs));
  PetscCall(MatGetLocalSize(A, &n, nullptr));
  PetscCall(MatInvertBlockDiagonal(A, &id));
  PetscCall(VecGetArrayRead(y, &ya));
  PetscCall(VecGetArray(x, &xa));
  for (PetscInt r = 0; r < n / bs; r++)
    for (PetscInt i = 0; i < bs; i++) {
      PetscScalar s = 0;
      for (PetscInt j = 0; j < bs; j++) s += id[r * bs * bs + j * bs + i] * ya[r * bs + j];
      xa[r * bs + i] = s;
    }
  PetscCall(VecRestoreArray(x, &xa));
  PetscCall(VecRestoreArrayRead(y, &ya));
  PetscFunctionReturn(0);
}

PetscErrorCode eisenstat_ksp(Mat A, const char *prefix, double rtol, KSP *ksp)
{
  PetscFunctionBeginUser;
  PetscCall(KSPCreate(PETSC_COMM_WORLD, ksp));
  PetscCall(KSPSetOptionsPrefix(*ksp, prefix));
  PetscCall(KSPSetOperators(*ksp, A, A));
  PetscCall(KSPSetType(*ksp, KSPGMRES));
  PC pc;
  PetscCall(KSPGetPC(*ksp, &pc));
  PetscCall(PCSetType(pc, PCEISENSTAT));
  PetscCall(KSPSetTolerances(*ksp, rtol, 1e-50, PETSC_DEFAULT, 500));
  PetscCall(KSPSetFromOptions(*ksp));
  PetscFunctionReturn(0);
}

} // namespace

TEST_CASE("MatSOR SOR_EISENSTAT, SOR_APPLY_UPPER, MatMultDiagonalBlock of binbcsr satisfy their definitions",
          "[pc][eisenstat]")
{
  const FemProblem fem(5, 4, 3, true);
  for (PetscInt bs : {1, 3})
    for (const Storage &st : storages)
      for (double omega : {1.0, 1.3}) {
        INFO("bs " << bs << ", " << st.name << ", omega " << omega);
        Mat A;
        PCHK(coo_matrix(fem, bs, MATBINBCSR, st, &A));
        Vec b, y, v, w, z;
        PCHK(random_vec(A, 5, &b));
        PCHK(VecDuplicate(b, &y));
        PCHK(VecDuplicate(b, &v));
        PCHK(VecDuplicate(b, &w));
        PCHK(VecDuplicate(b, &z));
        // (L + E)^-1 A (U + E)^-1 b, with L, U the local triangles (E = D / omega, D the block diagonal)
        PCHK(sor(A, b, omega, SOR_EISENSTAT, y));
        PCHK(sor(A, b, omega, (MatSORType)(SOR_ZERO_INITIAL_GUESS | SOR_LOCAL_BACKWARD_SWEEP), v));
        PCHK(MatMult(A, v, w));
        PCHK(sor(A, w, omega, (MatSORType)(SOR_ZERO_INITIAL_GUESS | SOR_LOCAL_FORWARD_SWEEP), z));
        INFO("Eisenstat rel diff " << vec_rel_diff(y, z));
        CHECK(all_ranks(vec_rel_diff(y, z) < 1e-12));
        // (U + E) b, undone by the backward sweep (U + E)^-1
        PCHK(sor(A, b, omega, SOR_APPLY_UPPER, v));
        PCHK(sor(A, v, omega, (MatSORType)(SOR_ZERO_INITIAL_GUESS | SOR_LOCAL_BACKWARD_SWEEP), w));
        CHECK(all_ranks(vec_rel_diff(w, b) < 1e-12));
        CHECK(all_ranks(vec_rel_diff(v, b) > 1e-2)); // it did something
        // D b, undone by the inverted diagonal blocks
        PCHK(MatMultDiagonalBlock(A, b, v));
        PCHK(apply_inverse_blocks(A, v, w));
        CHECK(all_ranks(vec_rel_diff(w, b) < 1e-12));
        Vec all[] = {b, y, v, w, z};
        for (Vec &x : all) PCHK(VecDestroy(&x));
        PCHK(MatDestroy(&A));
      }
}

TEST_CASE("MatSOR of binbcsr: flags PCEISENSTAT does not use are refused clearly", "[pc][eisenstat]")
{
  const FemProblem fem(3, 3, 2, false);
  Mat              A;
  PCHK(coo_matrix(fem, 3, MATBINBCSR, storages[0], &A));
  Vec b, x;
  PCHK(random_vec(A, 1, &b));
  PCHK(VecDuplicate(b, &x));
  CHECK(MatSOR(A, b, 1.0, SOR_APPLY_LOWER, 0.0, 1, 1, x) == PETSC_ERR_SUP);
  PetscMPIInt size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  if (size > 1) CHECK(MatSOR(A, b, 1.0, SOR_FORWARD_SWEEP, 0.0, 1, 1, x) == PETSC_ERR_SUP); // global sweeps
  else CHECK(MatSOR(A, b, 0.0, SOR_EISENSTAT, 0.0, 1, 1, x) == PETSC_ERR_ARG_WRONG);        // omega 0
  PCHK(VecDestroy(&b));
  PCHK(VecDestroy(&x));
  PCHK(MatDestroy(&A));
}

// PETSc 3.18's MPIAIJ cannot run PCEISENSTAT when its diagonal part has no inodes (bs 1): MatSOR_MPIAIJ
// calls MatMultDiagonalBlock, which seqaij has only with inodes. The aij reference is taken where it
// works: on one rank always, on more ranks for bs 3 (3-row inodes: the same point-block Eisenstat).
TEST_CASE("PCEISENSTAT in GMRES: binbcsr takes aij's iterations and gives its solution, also after a refill",
          "[pc][eisenstat]")
{
  const FemProblem fem(6, 5, 4, true);
  PetscMPIInt      size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  const double rtol = 1e-8, tol = 10 * rtol; // two solutions that each meet rtol, from the same iterations
  for (PetscInt bs : {1, 3})
    for (const Storage &st : storages) {
      DYNAMIC_SECTION("bs " << bs << ", " << st.name)
      {
        const bool has_ref = size == 1 || bs == 3;
        Mat        A, R;
        PCHK(matrix_pair(fem, bs, st, &A, &R));
        KSP ka, kr = nullptr;
        PCHK(eisenstat_ksp(A, "a_", rtol, &ka));
        if (has_ref) PCHK(eisenstat_ksp(R, "r_", rtol, &kr));
        Vec b, xa, xr, t;
        PCHK(random_vec(A, 3, &b));
        PCHK(VecDuplicate(b, &xa));
        PCHK(VecDuplicate(b, &xr));
        PCHK(VecDuplicate(b, &t));
        Vec before;
        PCHK(VecDuplicate(b, &before));
        for (int pass = 0; pass < 2; ++pass) {
          INFO("pass " << pass << (pass ? " (after the refill)" : ""));
          SolveResult ra, rr;
          PCHK(solve(ka, b, xa, &ra));
          CHECK(ra.reason > 0);
          // the true residual meets the tolerance (GMRES's left-preconditioned norm is not b - A x)
          PCHK(MatMult(A, xa, t));
          PCHK(VecAYPX(t, -1.0, b));
          PetscReal nr, nb;
          PCHK(VecNorm(t, NORM_2, &nr));
          PCHK(VecNorm(b, NORM_2, &nb));
          INFO("true residual " << nr / nb);
          CHECK(nr / nb < 1e3 * rtol);
          if (has_ref) {
            PCHK(solve(kr, b, xr, &rr));
            INFO("iterations binbcsr " << ra.its << ", aij " << rr.its);
            CHECK(rr.reason > 0);
            CHECK(std::abs(ra.its - rr.its) <= 1);
            INFO("solution rel diff " << vec_rel_diff(xa, xr));
            CHECK(all_ranks(vec_rel_diff(xa, xr) < tol));
          }
          if (pass == 0) {
            PCHK(VecCopy(xa, before));
            PCHK(refill_pair(fem, bs, st, A, R));
          } else CHECK(all_ranks(vec_rel_diff(xa, before) > 1e-2)); // the solve saw the new values
        }
        PCHK(KSPDestroy(&ka));
        PCHK(KSPDestroy(&kr));
        Vec all[] = {b, xa, xr, t, before};
        for (Vec &x : all) PCHK(VecDestroy(&x));
        PCHK(MatDestroy(&A));
        PCHK(MatDestroy(&R));
      }
    }
}
