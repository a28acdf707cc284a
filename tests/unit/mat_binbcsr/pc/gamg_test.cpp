// PCGAMG on binbcsr (seq on one rank, mpi on more; bs 1 and 3; full, symmetric and single storage)
// against aij: one V-cycle (KSPPREONLY) equal to round-off, CG iterations and solutions, before and
// after a refill of the values, with GAMG's interpolation reused (its default) and rebuilt, and with a
// near null space (rigid body modes, 3 x 6 prolongator blocks). Also the pieces: the matrix products
// through the AIJ shadow, the graph, and a binbcsr matrix whose row and column block sizes differ
// becoming aij at its AIJ preallocation. Every TEST_CASE is collective: this program runs as unit_pc
// and under mpiexec -n 2 and -n 3 (tests/pc.cmake).
#include "pc_support.hpp"

#include <petsc/private/matimpl.h> // nonzerostate
#include <petscksp.h>
#include "petsc_compat.h" // MatCreateGraph's arguments

using namespace pctest;

namespace {

// The rigid body modes of the FEM grid (node coordinates i, j, k) as A's near null space.
PetscErrorCode set_rigid_body_modes(const FemProblem &fem, Mat A)
{
  Vec          coords;
  PetscInt     lo, hi;
  PetscScalar *c;
  MatNullSpace nsp;
  PetscFunctionBeginUser;
  std::vector<int> grid_of(fem.nodes());
  for (int g = 0; g < fem.nodes(); g++) grid_of[fem.node_of[g]] = g;
  PetscCall(MatCreateVecs(A, &coords, nullptr));
  PetscCall(VecSetBlockSize(coords, 3));
  PetscCall(VecGetOwnershipRange(coords, &lo, &hi));
  PetscCall(VecGetArray(coords, &c));
  for (PetscInt n = lo / 3; n < hi / 3; n++) {
    const int g             = grid_of[n];
    c[3 * (n - lo / 3) + 0] = g % fem.nx;
    c[3 * (n - lo / 3) + 1] = (g / fem.nx) % fem.ny;
    c[3 * (n - lo / 3) + 2] = g / (fem.nx * fem.ny);
  }
  PetscCall(VecRestoreArray(coords, &c));
  PetscCall(MatNullSpaceCreateRigidBody(coords, &nsp));
  PetscCall(MatSetNearNullSpace(A, nsp));
  PetscCall(MatNullSpaceDestroy(&nsp));
  PetscCall(VecDestroy(&coords));
  PetscFunctionReturn(0);
}

struct GamgCase {
  const char                                      *name;
  std::vector<std::pair<std::string, std::string>> opts; // without the KSP prefix
  bool                                             rigid_body_modes = false;
};

PetscErrorCode gamg_ksp(Mat A, const char *prefix, const GamgCase &c, KSPType type, double rtol, KSP *ksp)
{
  PetscFunctionBeginUser;
  std::vector<std::pair<std::string, std::string>> opts = {{"pc_type", "gamg"}};
  opts.insert(opts.end(), c.opts.begin(), c.opts.end());
  for (auto &o : opts) o.first = "-" + std::string(prefix) + o.first;
  ScopedOptions so(opts);
  PetscCall(KSPCreate(PETSC_COMM_WORLD, ksp));
  PetscCall(KSPSetOptionsPrefix(*ksp, prefix));
  PetscCall(KSPSetOperators(*ksp, A, A));
  PetscCall(KSPSetType(*ksp, type));
  PetscCall(KSPSetTolerances(*ksp, rtol, 1e-50, PETSC_DEFAULT, 200));
  PetscCall(KSPSetFromOptions(*ksp));
  PetscCall(KSPSetUp(*ksp));
  // the level KSPs read their options at the first PCSetUp (in KSPSetUp above); the options go now,
  // so one case's options never reach the next
  PetscFunctionReturn(0);
}

// A tall aij matrix: fine row i -> coarse column i / 4 (and a second, weaker, entry), the shape of a
// tentative prolongator; n local rows of A, bs 1 columns.
PetscErrorCode aggregate_prolongator(Mat A, Mat *P)
{
  PetscInt lo, hi, N;
  PetscFunctionBeginUser;
  PetscCall(MatGetOwnershipRange(A, &lo, &hi));
  PetscCall(MatGetSize(A, &N, nullptr));
  const PetscInt nc = (hi - lo + 3) / 4;
  PetscCall(MatCreateAIJ(PETSC_COMM_WORLD, hi - lo, nc, N, PETSC_DETERMINE, 2, nullptr, 2, nullptr, P));
  PetscInt clo, chi, NC;
  PetscCall(MatGetOwnershipRangeColumn(*P, &clo, &chi));
  PetscCall(MatGetSize(*P, nullptr, &NC));
  for (PetscInt i = lo; i < hi; i++) {
    const PetscInt    cols[2] = {clo + (i - lo) / 4, (clo + (i - lo) / 4 + 1) % NC};
    const PetscScalar vals[2] = {1.0 + 0.1 * (i % 3), 0.25};
    PetscCall(MatSetValues(*P, 1, &i, 2, cols, vals, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(*P, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*P, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

} // namespace

TEST_CASE(
  "Matrix products with binbcsr operands (P^T A P from the blocks on one rank, the others through the AIJ shadow) equal aij's, also reused after a refill",
  "[pc][gamg][product]")
{
  const FemProblem fem(5, 4, 3, true);
  for (PetscInt bs : {1, 3})
    for (const Storage &st : storages) {
      INFO("bs " << bs << ", " << st.name);
      Mat A, R, P;
      PCHK(matrix_pair(fem, bs, st, &A, &R));
      PCHK(aggregate_prolongator(A, &P));
      Mat ptap_a, ptap_r, ap_a, ap_r, pta_a, pta_r, aa_a, aa_r;
      PCHK(MatPtAP(A, P, MAT_INITIAL_MATRIX, 2.0, &ptap_a));
      PCHK(MatPtAP(R, P, MAT_INITIAL_MATRIX, 2.0, &ptap_r));
      {
        // on one rank P^T A P makes A P from the blocks: no AIJ shadow of A (the products below make one)
        PetscMPIInt size;
        PetscObject shadow = nullptr;
        PCHK(MPI_Comm_size(PETSC_COMM_WORLD, &size));
        PCHK(PetscObjectQuery((PetscObject)A, "MatBinBCSR_AIJShadow", &shadow));
        CHECK((size == 1) == (shadow == nullptr));
      }
      PCHK(MatMatMult(A, P, MAT_INITIAL_MATRIX, 2.0, &ap_a));
      PCHK(MatMatMult(R, P, MAT_INITIAL_MATRIX, 2.0, &ap_r));
      PCHK(MatTransposeMatMult(P, A, MAT_INITIAL_MATRIX, 2.0, &pta_a)); // binbcsr as the second operand
      PCHK(MatTransposeMatMult(P, R, MAT_INITIAL_MATRIX, 2.0, &pta_r));
      PCHK(MatMatMult(A, A, MAT_INITIAL_MATRIX, 2.0, &aa_a)); // both binbcsr
      PCHK(MatMatMult(R, R, MAT_INITIAL_MATRIX, 2.0, &aa_r));
      const double tol = 1e-13; // the same AIJ kernels on the same values
      CHECK(mat_rel_diff(ptap_a, ptap_r) < tol);
      CHECK(mat_rel_diff(ap_a, ap_r) < tol);
      CHECK(mat_rel_diff(pta_a, pta_r) < tol);
      CHECK(mat_rel_diff(aa_a, aa_r) < tol);
      PetscBool aij;
      PCHK(PetscObjectTypeCompareAny((PetscObject)ptap_a, &aij, MATSEQAIJ, MATMPIAIJ, ""));
      CHECK(aij);
      { // a dense block of vectors: PETSc's column-by-column product with binbcsr's own MatMult, no AIJ copy
        Mat      F, X, Y, YR;
        PetscInt n;
        PCHK(coo_matrix(fem, bs, MATBINBCSR, st, &F));
        PCHK(MatGetLocalSize(F, &n, nullptr));
        PCHK(MatCreateDense(PETSC_COMM_WORLD, n, PETSC_DECIDE, PETSC_DETERMINE, 3, nullptr, &X));
        PCHK(MatSetRandom(X, nullptr));
        PCHK(MatMatMult(F, X, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &Y));
        PCHK(MatMatMult(R, X, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &YR));
        CHECK(mat_rel_diff(Y, YR) <
              (st.single ? 1e-6 : 1e-13)); // F holds weight0 values, R (single: a copy of A) too
        PetscObject shadow = nullptr;
        PCHK(PetscObjectQuery((PetscObject)F, "MatBinBCSR_AIJShadow", &shadow));
        CHECK(shadow == nullptr);
        Mat ms[] = {F, X, Y, YR};
        for (Mat &M : ms) PCHK(MatDestroy(&M));
      }
      // a refill reaches the reused products (GAMG's coarse operators after a refill)
      Mat before;
      PCHK(MatDuplicate(ptap_a, MAT_COPY_VALUES, &before));
      PCHK(refill_pair(fem, bs, st, A, R));
      PCHK(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &ptap_a));
      PCHK(MatPtAP(R, P, MAT_REUSE_MATRIX, 2.0, &ptap_r));
      PCHK(MatMatMult(A, P, MAT_REUSE_MATRIX, 2.0, &ap_a));
      PCHK(MatMatMult(R, P, MAT_REUSE_MATRIX, 2.0, &ap_r));
      PCHK(MatProductNumeric(aa_a));
      PCHK(MatProductNumeric(aa_r));
      CHECK(mat_rel_diff(ptap_a, ptap_r) < tol);
      CHECK(mat_rel_diff(ap_a, ap_r) < tol);
      CHECK(mat_rel_diff(aa_a, aa_r) < tol);
      CHECK(mat_rel_diff(ptap_a, before) > 1e-2);
      // new values through an assembly with the same pattern (MatSetValues on this rank's diagonal)
      PetscInt lo, hi;
      PCHK(MatGetOwnershipRange(A, &lo, &hi));
      for (PetscInt i = lo; i < hi; i++) {
        PCHK(MatSetValue(A, i, i, 50.0 + i % 5, ADD_VALUES));
        PCHK(MatSetValue(R, i, i, 50.0 + i % 5, ADD_VALUES));
      }
      PCHK(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
      PCHK(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
      PCHK(MatAssemblyBegin(R, MAT_FINAL_ASSEMBLY));
      PCHK(MatAssemblyEnd(R, MAT_FINAL_ASSEMBLY));
      PCHK(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &ptap_a));
      PCHK(MatPtAP(R, P, MAT_REUSE_MATRIX, 2.0, &ptap_r));
      CHECK(mat_rel_diff(ptap_a, ptap_r) <
            (st.single ? 1e-6 : tol)); // single: A rounds the new diagonal to float, R does not
      // a new preallocation: if it gave a new nonzero state (a rebuilt shadow), the old symbolic phase
      // cannot serve it and that is a clear error; a preallocation that kept the layout keeps the product
      std::vector<PetscInt> ci, cj;
      coo_entries(fem, bs, ci, cj);
      const PetscObjectState nz_before = A->nonzerostate;
      PCHK(MatSetPreallocationCOO(A, static_cast<PetscCount>(ci.size()), ci.data(), cj.data()));
      PCHK(MatSetValuesCOO(A, coo_values(fem, bs, weight0).data(), INSERT_VALUES));
      const bool new_pattern = all_ranks(A->nonzerostate == nz_before) ? false : true;
      if (!st.sym && !st.single) CHECK(new_pattern); // whole double storage rebuilds its layout
      if (new_pattern) CHECK(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &ptap_a) == PETSC_ERR_ARG_INCOMP);
      else {
        PCHK(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &ptap_a));
        CHECK(mat_rel_diff(ptap_a, before) < (st.single ? 1e-6 : tol)); // weight0 again
      }
      Mat all[] = {A, R, P, ptap_a, ptap_r, ap_a, ap_r, pta_a, pta_r, aa_a, aa_r, before};
      for (Mat &M : all) PCHK(MatDestroy(&M));
    }
}

TEST_CASE(
  "MatCreateGraph of binbcsr is aij's; a binbcsr matrix with row and column block sizes 3 and 6 becomes aij at its AIJ preallocation",
  "[pc][gamg]")
{
  const FemProblem fem(4, 3, 3, true);
  Mat              A, R, GA, GR;
  PCHK(matrix_pair(fem, 3, storages[1], &A, &R)); // symmetric storage: the graph still sees the whole matrix
  PCHK(MatCreateGraph(A, PETSC_TRUE, PETSC_TRUE, 0.01 BINBCSR_CREATEGRAPH_NO_INDEX, &GA));
  PCHK(MatCreateGraph(R, PETSC_TRUE, PETSC_TRUE, 0.01 BINBCSR_CREATEGRAPH_NO_INDEX, &GR));
  CHECK(mat_rel_diff(GA, GR) < 1e-14);
  PetscInt m, n;
  PCHK(MatGetSize(GA, &m, &n));
  CHECK(m == fem.nodes());
  PCHK(MatDestroy(&GA));
  PCHK(MatDestroy(&GR));
  // GAMG's prolongator with rigid body modes: 3 x 6 blocks, made in the operator's type
  PetscInt lo, hi;
  PCHK(MatGetOwnershipRange(A, &lo, &hi));
  Mat P;
  PCHK(MatCreate(PETSC_COMM_WORLD, &P));
  PCHK(MatSetSizes(P, hi - lo, 2 * (hi - lo), PETSC_DETERMINE, PETSC_DETERMINE));
  PCHK(MatSetBlockSizes(P, 3, 6));
  PCHK(MatSetType(P, MATBINBCSR));
  PCHK(MatSeqAIJSetPreallocation(P, 6, nullptr));
  PCHK(MatMPIAIJSetPreallocation(P, 6, nullptr, 6, nullptr));
  PetscBool aij;
  PCHK(PetscObjectTypeCompareAny((PetscObject)P, &aij, MATSEQAIJ, MATMPIAIJ, ""));
  CHECK(aij);
  PetscInt rbs, cbs;
  PCHK(MatGetBlockSizes(P, &rbs, &cbs));
  CHECK((rbs == 3 && cbs == 6));
  PCHK(MatDestroy(&P));
  PCHK(MatDestroy(&A));
  PCHK(MatDestroy(&R));
}

TEST_CASE(
  "PCGAMG on binbcsr equals aij's: one V-cycle, CG iterations and solution, before and after a refill",
  "[pc][gamg]")
{
  const FemProblem fem(6, 5, 5, true);
  const double   rtol = 1e-8, tol = 10 * rtol; // two solutions that each meet rtol, from the same iterations
  const GamgCase cases[] = {
    {"default (interpolation reused after a refill)", {}},
    {"interpolation rebuilt after a refill", {{"pc_gamg_reuse_interpolation", "false"}}},
    {"unsmoothed aggregation (binbcsr tentative prolongator)", {{"pc_gamg_agg_nsmooths", "0"}}},
    {"rigid body modes", {}, true},
  };
  for (PetscInt bs : {1, 3})
    for (const Storage &st : storages)
      for (const GamgCase &c : cases) {
        if (c.rigid_body_modes && bs != 3) continue;
        DYNAMIC_SECTION("bs " << bs << ", " << st.name << ", " << c.name)
        {
          Mat A, R;
          PCHK(matrix_pair(fem, bs, st, &A, &R));
          if (c.rigid_body_modes) {
            PCHK(set_rigid_body_modes(fem, A));
            PCHK(set_rigid_body_modes(fem, R));
          }
          KSP pa, pr, ka, kr;
          PCHK(gamg_ksp(A, "pa_", c, KSPPREONLY, rtol, &pa));
          PCHK(gamg_ksp(R, "pr_", c, KSPPREONLY, rtol, &pr));
          PCHK(gamg_ksp(A, "ka_", c, KSPCG, rtol, &ka));
          PCHK(gamg_ksp(R, "kr_", c, KSPCG, rtol, &kr));
          Vec b, xa, xr, before;
          PCHK(random_vec(A, 9, &b));
          PCHK(VecDuplicate(b, &xa));
          PCHK(VecDuplicate(b, &xr));
          PCHK(VecDuplicate(b, &before));
          for (int pass = 0; pass < 2; ++pass) {
            INFO("pass " << pass << (pass ? " (after the refill)" : ""));
            // one V-cycle: equal to round-off (a stale coarse operator or graph would differ a lot)
            PCHK(KSPSolve(pa, b, xa));
            PCHK(KSPSolve(pr, b, xr));
            INFO("V-cycle rel diff " << vec_rel_diff(xa, xr));
            CHECK(all_ranks(vec_rel_diff(xa, xr) < 1e-9));
            if (pass == 1) CHECK(all_ranks(vec_rel_diff(xa, before) > 1e-2));
            PCHK(VecCopy(xa, before));
            SolveResult ra, rr;
            PCHK(solve(ka, b, xa, &ra));
            PCHK(solve(kr, b, xr, &rr));
            INFO("CG iterations binbcsr " << ra.its << ", aij " << rr.its);
            CHECK(ra.reason > 0);
            CHECK(rr.reason > 0);
            CHECK(std::abs(ra.its - rr.its) <= 1);
            INFO("solution rel diff " << vec_rel_diff(xa, xr));
            CHECK(all_ranks(vec_rel_diff(xa, xr) < tol));
            if (pass == 0) PCHK(refill_pair(fem, bs, st, A, R));
          }
          KSP all[] = {pa, pr, ka, kr};
          for (KSP &k : all) PCHK(KSPDestroy(&k));
          Vec vs[] = {b, xa, xr, before};
          for (Vec &v : vs) PCHK(VecDestroy(&v));
          PCHK(MatDestroy(&A));
          PCHK(MatDestroy(&R));
        }
      }
}
