// MATMPIBINBCSR with symmetric storage, MatSOR and COO refills seen by a PC set up before them: against
// the same matrix assembled serially and against MPIAIJ/MPIBAIJ. Collective, as mpibinbcsr.cpp.
#include "mpi_checks.hpp"

TEST_CASE(
  "mpibinbcsr with symmetric storage (upper diagonal part, full off-diagonal part) equals the serial matrix",
  "[mpi][sym]")
{
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", "1"));
  for (bool empty_rank0 : {false, true})
    for (Fill fill : {Fill::Blocked, Fill::Coo, Fill::ScalarOwnRows}) {
      INFO("fill " << fill_name(fill) << ", rank 0 empty " << empty_rank0);
      const FemProblem fem(5, 4, 3, true);
      Mat              A, S, C;
      PCHK(assemble(fem, MATMPIBINBCSR, fill, empty_rank0, &A));
      PetscBool sym = PETSC_FALSE;
      PCHK(MatBinBCSRGetSymmetricStorage(A, &sym));
      CHECK(sym);
      PCHK(serial_reference(fem, &S));
      check_products(A, S);
      // both triangles back out of it
      PCHK(MatConvert(A, MATMPIAIJ, MAT_INITIAL_MATRIX, &C));
      check_products(C, S);
      PCHK(MatDestroy(&C));
      PCHK(MatDestroy(&A));
      PCHK(MatDestroy(&S));
    }
  // CG and MCG: the iterations of aij
  const FemProblem fem(6, 5, 4, true);
  for (KSPType kt : {KSPCG, KSPMCG}) {
    PetscInt its[2];
    for (int t = 0; t < 2; ++t) {
      Mat                A;
      Vec                b, x;
      KSPConvergedReason reason;
      if (t == 0) PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage"));
      else PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", "1"));
      PCHK(assemble(fem, t == 0 ? MATMPIAIJ : MATMPIBINBCSR, Fill::Coo, false, &A));
      PCHK(MatCreateVecs(A, &x, &b));
      PCHK(fill_test_vector(b));
      PCHK(solve_to_tolerance(A, b, x, kt, PCJACOBI, &its[t], &reason));
      CHECK(reason > 0);
      PCHK(VecDestroy(&b));
      PCHK(VecDestroy(&x));
      PCHK(MatDestroy(&A));
    }
    INFO("ksp " << kt);
    CHECK(its[0] == its[1]);
  }
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage"));
}

TEST_CASE("mpibinbcsr with symmetric storage: MatZeroRowsColumns with rows named by any rank", "[mpi][sym]")
{
  const FemProblem fem(4, 3, 3, true);
  PetscMPIInt      rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  std::vector<PetscInt> rows, all_rows;
  for (PetscInt r = rank; r < fem.rows(); r += 7) rows.push_back(r);
  for (PetscInt r = 0; r < fem.rows(); ++r)
    if (r % 7 < size) all_rows.push_back(r);
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", "1"));
  Mat A, S;
  PCHK(assemble(fem, MATMPIBINBCSR, Fill::Coo, false, &A));
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage"));
  PCHK(serial_reference(fem, &S));
  Vec x, b, xs, bs;
  PCHK(MatCreateVecs(A, &x, &b));
  PCHK(fill_test_vector(x));
  PCHK(fill_test_vector(b, 1));
  PCHK(serial_test_vector(fem.rows(), 0, &xs));
  PCHK(serial_test_vector(fem.rows(), 1, &bs));
  PCHK(MatZeroRowsColumns(A, static_cast<PetscInt>(rows.size()), rows.data(), 2.5, x, b));
  PCHK(MatZeroRowsColumns(S, static_cast<PetscInt>(all_rows.size()), all_rows.data(), 2.5, xs, bs));
  CHECK(all_ranks(local_rel_diff(b, bs) < tol));
  check_products(A, S);
  for (Vec *v : {&x, &b, &xs, &bs}) PCHK(VecDestroy(v));
  PCHK(MatDestroy(&A));
  PCHK(MatDestroy(&S));
}

TEST_CASE("mpibinbcsr: MatSOR local sweeps and PCSOR in CG equal mpibaij's (whole and symmetric storage)",
          "[mpi][sor]")
{
  const FemProblem fem(6, 5, 4, true);
  for (const char *sym : {"0", "1"}) {
    INFO("symmetric storage " << sym);
    PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", sym));
    Mat A, R;
    PCHK(assemble(fem, MATMPIBINBCSR, Fill::Coo, true, &A));
    PCHK(MatConvert(A, MATMPIBAIJ, MAT_INITIAL_MATRIX, &R)); /* through MatGetRow: both triangles */
    Vec b, x, xr;
    PCHK(MatCreateVecs(A, &x, &b));
    PCHK(VecDuplicate(x, &xr));
    PCHK(fill_test_vector(b));
    // block SOR with omega 1 (BAIJ's bs 3 sweeps invert the diagonal blocks the same way)
    for (int flag : {SOR_LOCAL_SYMMETRIC_SWEEP | SOR_ZERO_INITIAL_GUESS, (int)SOR_LOCAL_FORWARD_SWEEP,
                     (int)SOR_LOCAL_BACKWARD_SWEEP})
      for (PetscInt its : {1, 3}) {
        INFO("flag " << flag << " its " << its);
        PCHK(fill_test_vector(x, 1));
        PCHK(VecCopy(x, xr));
        PCHK(MatSOR(A, b, 1.0, (MatSORType)flag, 0.0, its, 1, x));
        PCHK(MatSOR(R, b, 1.0, (MatSORType)flag, 0.0, its, 1, xr));
        PetscReal diff, ref;
        PCHK(VecAXPY(x, -1.0, xr));
        PCHK(VecNorm(x, NORM_INFINITY, &diff));
        PCHK(VecNorm(xr, NORM_INFINITY, &ref));
        CHECK(diff <= 1e-12 * ref);
      }
    // a global (not processor-local) sweep is refused, as by MPIAIJ
    CHECK(MatSOR(A, b, 1.0, SOR_FORWARD_SWEEP, 0.0, 1, 1, x) == PETSC_ERR_SUP);
    // CG + SSOR (PCSOR's default local symmetric sweep): the iterations and solution of mpibaij
    PetscInt its[2];
    Mat      mats[2] = {R, A};
    Vec      sol[2]  = {xr, x};
    for (int t = 0; t < 2; ++t) {
      KSPConvergedReason reason;
      PCHK(solve_to_tolerance(mats[t], b, sol[t], KSPCG, PCSOR, &its[t], &reason));
      CHECK(reason > 0);
    }
    CHECK(its[0] == its[1]);
    PetscReal diff, ref;
    PCHK(VecAXPY(x, -1.0, xr));
    PCHK(VecNorm(x, NORM_INFINITY, &diff));
    PCHK(VecNorm(xr, NORM_INFINITY, &ref));
    CHECK(diff <= 1e-8 * ref);
    PCHK(VecDestroy(&b));
    PCHK(VecDestroy(&x));
    PCHK(VecDestroy(&xr));
    PCHK(MatDestroy(&A));
    PCHK(MatDestroy(&R));
  }
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage"));
}

// A PC set up once must see later COO refills: block Jacobi's sub-PCs and the SOR cache key their
// set-up on the state of the part they read, which the refill of each part has to move (both the
// composed refill of BIN-BCSR parts and the plain one of other part types).
TEST_CASE("mpibinbcsr: a COO refill with values reaches a PC set up before it (bjacobi, sor)",
          "[mpi][coo_state]")
{
  const FemProblem fem(5, 4, 4, true);
  // the same elements, weighted unevenly so that a stale factor or diagonal is a different operator
  const std::vector<PetscScalar> cv = rank_coo_values(fem, [](int e) { return 1.0 + 3.0 * (e % 4); });
  for (const char *parts : {(const char *)nullptr, "seqaij"})
    for (PCType pt : {PCBJACOBI, PCSOR}) {
      INFO("parts " << (parts ? parts : "seqbinbcsr") << " pc " << pt);
      Mat      A, F; // A: refilled under a set-up KSP; F: fresh, filled with the new values before any set-up
      Vec      b, x, xf;
      KSP      ksp;
      PetscInt its_first, its, its_fresh;
      PCHK(assemble(fem, MATMPIBINBCSR, Fill::Coo, false, &A, parts));
      PCHK(assemble(fem, MATMPIBINBCSR, Fill::Coo, false, &F, parts));
      PCHK(MatSetValuesCOO(F, cv.data(), INSERT_VALUES));
      PCHK(MatCreateVecs(A, &x, &b));
      PCHK(VecDuplicate(x, &xf));
      PCHK(fill_test_vector(b));
      PCHK(create_solver(A, KSPCG, pt, &ksp));
      PCHK(KSPSolve(ksp, b, x));
      PCHK(KSPGetIterationNumber(ksp, &its_first));

      Mat              Ad;
      PetscObjectState before, after;
      PCHK(MatGetDiagonalBlock(A, &Ad));
      PCHK(PetscObjectStateGet((PetscObject)Ad, &before));
      PCHK(MatSetValuesCOO(A, cv.data(), INSERT_VALUES));
      PCHK(PetscObjectStateGet((PetscObject)Ad, &after));
      CHECK(after > before);

      PCHK(VecZeroEntries(x));
      PCHK(KSPSolve(ksp, b, x));
      PCHK(KSPGetIterationNumber(ksp, &its));
      KSPConvergedReason reason;
      PCHK(solve_to_tolerance(F, b, xf, KSPCG, pt, &its_fresh, &reason));
      CHECK(reason > 0);
      CHECK(its == its_fresh);
      PetscReal diff, ref;
      PCHK(VecAXPY(x, -1.0, xf));
      PCHK(VecNorm(x, NORM_INFINITY, &diff));
      PCHK(VecNorm(xf, NORM_INFINITY, &ref));
      CHECK(diff <= 1e-12 * ref);
      CHECK(its_first > 0);
      PCHK(KSPDestroy(&ksp));
      PCHK(VecDestroy(&b));
      PCHK(VecDestroy(&x));
      PCHK(VecDestroy(&xf));
      PCHK(MatDestroy(&A));
      PCHK(MatDestroy(&F));
    }
}

TEST_CASE("mpibinbcsr: symmetric storage and the COO mirror refuse unequal row and column layouts on every "
          "rank",
          "[mpi][sym]")
{
  PetscMPIInt rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  // square overall, but rank r's diagonal part has 3 (r + 1) rows and 3 (size - r) columns: square on
  // none or one rank, so an error on the others only would leave that one waiting in a collective
  const PetscInt m = 3 * (rank + 1), n = 3 * (size - rank), M = 3 * size * (size + 1) / 2;
  PetscInt       ci[] = {3 * rank, 3 * rank}, cj[] = {0, M - 1}; // non-const: PETSc 3.18's prototype
  // modes: symmetric storage at MatSetUp, at the COO preallocation; the COO mirror; symmetric storage of
  // a matrix 3 columns wider than high, given by local sizes only (the setter cannot tell yet)
  for (int mode = 0; mode < 4; ++mode) {
    INFO("mode " << mode);
    Mat A;
    PCHK(MatCreate(PETSC_COMM_WORLD, &A));
    if (mode == 3) PCHK(MatSetSizes(A, m, m + (rank == size - 1 ? 3 : 0), PETSC_DETERMINE, PETSC_DETERMINE));
    else PCHK(MatSetSizes(A, m, n, M, M));
    PCHK(MatSetBlockSize(A, 3));
    PCHK(MatSetType(A, MATMPIBINBCSR));
    if (mode == 2) PCHK(MatBinBCSRSetCOOMirror(A, PETSC_TRUE));
    else PCHK(MatBinBCSRSetSymmetricStorage(A, PETSC_TRUE));
    const PetscErrorCode ierr = mode == 0 || mode == 3 ? MatSetUp(A) : MatSetPreallocationCOO(A, 2, ci, cj);
    if (size > 1 || mode == 3) CHECK(all_ranks(ierr == PETSC_ERR_ARG_SIZ));
    else CHECK(ierr == 0);
    PCHK(MatDestroy(&A));
  }
}
