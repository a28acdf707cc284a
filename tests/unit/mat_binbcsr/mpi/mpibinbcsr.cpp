// MATMPIBINBCSR against the same matrix assembled serially (on every rank) and against MPIAIJ.
// Every TEST_CASE is collective on PETSC_COMM_WORLD: this program runs as unit_mpi on one rank and
// under mpiexec -n 2 and -n 3 (tests/mpi.cmake). Checks are reduced over the ranks first (all_ranks)
// so that every rank passes or fails together instead of leaving the others waiting.
#include "mpi_checks.hpp"

TEST_CASE("mpibinbcsr equals the serial matrix for every assembly path and partition", "[mpi]")
{
  for (bool shuffle : {false, true})
    for (bool empty_rank0 : {false, true})
      for (Fill fill : {Fill::Blocked, Fill::Coo, Fill::ScalarOwnRows}) {
        INFO("fill " << fill_name(fill) << ", shuffled numbering " << shuffle << ", rank 0 empty "
                     << empty_rank0);
        const FemProblem fem(5, 4, 3, shuffle);
        Mat              A, S;
        PCHK(assemble(fem, MATMPIBINBCSR, fill, empty_rank0, &A));
        PCHK(serial_reference(fem, &S));
        check_products(A, S);
        PCHK(MatDestroy(&A));
        PCHK(MatDestroy(&S));
      }
}

TEST_CASE("mpibinbcsr: refill in place (COO and MatSetValues) keeps the pattern and the scatter", "[mpi]")
{
  const FemProblem fem(4, 4, 4, true);
  Mat              A, S;
  PCHK(assemble(fem, MATMPIBINBCSR, Fill::Coo, false, &A));
  PCHK(serial_reference(fem, &S));
  // second COO refill with the same values scaled by 2 (ADD on top of the first)
  PetscMPIInt rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  const std::vector<PetscScalar> cv = rank_coo_values(fem, [](int) { return 1.0; });
  PCHK(MatSetValuesCOO(A, cv.data(), ADD_VALUES));
  PCHK(MatScale(S, 2.0));
  check_products(A, S);
  // no values (NULL) are zeros, with off-rank entries too: ADD leaves the matrix as it is
  PCHK(MatSetValuesCOO(A, nullptr, ADD_VALUES));
  check_products(A, S);

  // zero, then refill through the blocked/stash path into the frozen pattern
  PCHK(MatZeroEntries(A));
  for (int e = 0; e < fem.element_count(); ++e) {
    if (e % size != rank) continue;
    const auto blk = fem.element_blocks(e);
    const auto K   = fem.element_matrix(e);
    PCHK(MatSetValuesBlocked(A, 8, blk.data(), 8, blk.data(), K.data(), ADD_VALUES));
  }
  PCHK(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PCHK(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PCHK(MatScale(S, 0.5));
  check_products(A, S);

  // scale and shift
  PCHK(MatScale(A, -3.0));
  PCHK(MatShift(A, 7.0));
  PCHK(MatScale(S, -3.0));
  PCHK(MatShift(S, 7.0));
  check_products(A, S);
  PCHK(MatDestroy(&A));
  PCHK(MatDestroy(&S));
}

TEST_CASE("mpibinbcsr: MatGetRow, conversion to and from mpiaij, duplicate, copy", "[mpi]")
{
  const FemProblem fem(4, 3, 3, true);
  Mat              A, S, P, B, D;
  PCHK(assemble(fem, MATMPIBINBCSR, Fill::Blocked, true, &A));
  PCHK(serial_reference(fem, &S));
  PCHK(MatConvert(A, MATMPIAIJ, MAT_INITIAL_MATRIX, &P));
  check_products(P, S);
  // rows with global columns, sorted
  PetscInt rstart, rend;
  bool     rows_ok = true;
  PCHK(MatGetOwnershipRange(A, &rstart, &rend));
  for (PetscInt r = rstart; r < rend; ++r) {
    PetscInt           na, ns;
    const PetscInt    *ca, *cs;
    const PetscScalar *va, *vs;
    PCHK(MatGetRow(A, r, &na, &ca, &va));
    PCHK(MatGetRow(S, r, &ns, &cs, &vs));
    rows_ok = rows_ok && na == ns;
    for (PetscInt k = 0; rows_ok && k < na; ++k) rows_ok = ca[k] == cs[k] && std::abs(va[k] - vs[k]) < 1e-14;
    PCHK(MatRestoreRow(S, r, &ns, &cs, &vs));
    PCHK(MatRestoreRow(A, r, &na, &ca, &va));
  }
  CHECK(all_ranks(rows_ok));

  PCHK(MatConvert(P, MATMPIBINBCSR, MAT_INITIAL_MATRIX, &B));
  check_products(B, S);
  PetscBool same;
  PCHK(PetscObjectTypeCompare((PetscObject)B, MATMPIBINBCSR, &same));
  CHECK(same);

  PCHK(MatDuplicate(A, MAT_COPY_VALUES, &D));
  check_products(D, S);
  PCHK(MatScale(D, 5.0));
  PCHK(MatCopy(A, D, SAME_NONZERO_PATTERN));
  check_products(D, S);
  PCHK(MatCopy(P, D, DIFFERENT_NONZERO_PATTERN));
  check_products(D, S);

  MatInfo info;
  PCHK(MatGetInfo(A, MAT_GLOBAL_SUM, &info));
  CHECK(info.nz_used >= 1);
  CHECK(info.block_size == 3);
  for (Mat *m : {&A, &S, &P, &B, &D}) PCHK(MatDestroy(m));
}

TEST_CASE("mpibinbcsr: MatZeroRowsColumns and MatZeroRows with rows named by any rank", "[mpi]")
{
  const FemProblem fem(4, 3, 3, true);
  PetscMPIInt      rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  // each rank names a different set of rows, owned by anyone
  std::vector<PetscInt> rows;
  for (PetscInt r = rank; r < fem.rows(); r += 7) rows.push_back(r);
  std::vector<PetscInt> all_rows;
  for (PetscInt r = 0; r < fem.rows(); ++r) {
    PetscMPIInt size;
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    for (int q = 0; q < size; ++q)
      if (r % 7 == q) all_rows.push_back(r);
  }
  for (bool columns : {true, false}) {
    Mat A, S;
    PCHK(assemble(fem, MATMPIBINBCSR, Fill::Coo, false, &A));
    PCHK(serial_reference(fem, &S));
    Vec x, b, xs, bs;
    PCHK(MatCreateVecs(A, &x, &b));
    PCHK(fill_test_vector(x));
    PCHK(fill_test_vector(b, 1));
    PCHK(serial_test_vector(fem.rows(), 0, &xs));
    PCHK(serial_test_vector(fem.rows(), 1, &bs));
    if (columns) {
      PCHK(MatZeroRowsColumns(A, static_cast<PetscInt>(rows.size()), rows.data(), 2.5, x, b));
      PCHK(MatZeroRowsColumns(S, static_cast<PetscInt>(all_rows.size()), all_rows.data(), 2.5, xs, bs));
    } else {
      PCHK(MatZeroRows(A, static_cast<PetscInt>(rows.size()), rows.data(), 2.5, x, b));
      PCHK(MatZeroRows(S, static_cast<PetscInt>(all_rows.size()), all_rows.data(), 2.5, xs, bs));
    }
    INFO("columns too: " << columns);
    CHECK(all_ranks(local_rel_diff(b, bs) < tol));
    check_products(A, S);
    for (Vec *v : {&x, &b, &xs, &bs}) PCHK(VecDestroy(v));
    PCHK(MatDestroy(&A));
    PCHK(MatDestroy(&S));
  }
}

TEST_CASE("mpibinbcsr: CG solves equal aij's (iterations and solution)", "[mpi]")
{
  const FemProblem fem(6, 5, 4, true);
  PetscInt         its[2];
  Vec              sol[2];
  MatType          types[2] = {MATMPIAIJ, MATMPIBINBCSR};
  for (int t = 0; t < 2; ++t) {
    Mat                A;
    Vec                b;
    KSPConvergedReason reason;
    PCHK(assemble(fem, types[t], t == 0 ? Fill::Blocked : Fill::Coo, true, &A));
    PCHK(MatCreateVecs(A, &sol[t], &b));
    PCHK(fill_test_vector(b));
    PCHK(solve_to_tolerance(A, b, sol[t], KSPCG, PCJACOBI, &its[t], &reason));
    CHECK(reason > 0);
    PCHK(VecDestroy(&b));
    PCHK(MatDestroy(&A));
  }
  CHECK(its[0] == its[1]);
  PetscReal diff, ref;
  PCHK(VecAXPY(sol[1], -1.0, sol[0]));
  PCHK(VecNorm(sol[1], NORM_INFINITY, &diff));
  PCHK(VecNorm(sol[0], NORM_INFINITY, &ref));
  CHECK(diff <= 1e-8 * ref);
  PCHK(VecDestroy(&sol[0]));
  PCHK(VecDestroy(&sol[1]));
}

TEST_CASE("mpibinbcsr: parallel MatLoad of a PETSc binary file, and per-rank info view", "[mpi]")
{
  const FemProblem fem(4, 4, 3, false);
  Mat              P, A, S;
  PCHK(assemble(fem, MATMPIAIJ, Fill::Blocked, false, &P));
  PCHK(serial_reference(fem, &S));
  char        name[PETSC_MAX_PATH_LEN] = "";
  PetscMPIInt rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) std::snprintf(name, sizeof(name), "/tmp/mpibinbcsr_load_%d.bin", static_cast<int>(getpid()));
  MPI_Bcast(name, sizeof(name), MPI_CHAR, 0, PETSC_COMM_WORLD);
  PetscViewer v;
  PCHK(PetscViewerBinaryOpen(PETSC_COMM_WORLD, name, FILE_MODE_WRITE, &v));
  PCHK(MatView(P, v));
  PCHK(PetscViewerDestroy(&v));

  PCHK(MatCreate(PETSC_COMM_WORLD, &A));
  PCHK(MatSetType(A, MATMPIBINBCSR));
  PCHK(MatSetBlockSize(A, 3));
  PCHK(PetscViewerBinaryOpen(PETSC_COMM_WORLD, name, FILE_MODE_READ, &v));
  PCHK(MatSetFromOptions(A));
  PCHK(MatLoad(A, v));
  PCHK(PetscViewerDestroy(&v));
  check_products(A, S);

  // the info view lists every rank's parts
  std::string txt = std::string(name) + ".txt";
  PCHK(PetscViewerASCIIOpen(PETSC_COMM_WORLD, txt.c_str(), &v));
  PCHK(PetscViewerPushFormat(v, PETSC_VIEWER_ASCII_INFO));
  PCHK(MatView(A, v));
  PCHK(PetscViewerPopFormat(v));
  PCHK(PetscViewerDestroy(&v));
  MPI_Barrier(PETSC_COMM_WORLD);
  if (rank == 0) {
    PetscMPIInt size;
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    FILE *f = std::fopen(txt.c_str(), "r");
    REQUIRE(f);
    std::string content;
    char        buf[512];
    while (std::fgets(buf, sizeof(buf), f)) content += buf;
    std::fclose(f);
    for (int r = 0; r < size; ++r)
      CHECK(content.find("[" + std::to_string(r) + "] rows") != std::string::npos);
    CHECK(content.find("ghost block columns") != std::string::npos);
    std::remove(txt.c_str());
    std::remove(name);
    std::remove((std::string(name) + ".info").c_str());
  }
  for (Mat *m : {&P, &A, &S}) PCHK(MatDestroy(m));
}

TEST_CASE("mpibinbcsr: settings forwarded, bad input refused", "[mpi]")
{
  const FemProblem fem(3, 3, 3, false);
  Mat              A;
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_bin_width", "4"));
  PCHK(assemble(fem, MATMPIBINBCSR, Fill::Blocked, false, &A));
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_bin_width"));
  PetscInt bw = 0;
  PCHK(MatBinBCSRGetBinWidth(A, &bw));
  CHECK(bw == 4);
  PetscInt bwA = 0;
  Mat      Ad;
  PCHK(MatGetDiagonalBlock(A, &Ad));
  PCHK(MatBinBCSRGetBinWidth(Ad, &bwA));
  CHECK(bwA == 4); // forwarded to the parts
  MatBinBCSRPrecision p;
  PCHK(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_DOUBLE));
  PCHK(MatBinBCSRGetPrecision(A, &p));
  CHECK(p == MAT_BINBCSR_PRECISION_DOUBLE);

  // out-of-range column, and a new off-diagonal nonzero after the pattern is fixed: errors, no crash
  PetscInt    rstart, rend;
  PetscScalar one = 1.0;
  PCHK(MatGetOwnershipRange(A, &rstart, &rend));
  if (rend > rstart) {
    PetscInt bad = fem.rows() + 5;
    CHECK(MatSetValues(A, 1, &rstart, 1, &bad, &one, INSERT_VALUES) != 0);
    PetscMPIInt size;
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    if (size > 1) {
      // the column farthest from this rank's range is not coupled to it in a 3x3x3 grid
      PetscInt far = rstart < fem.rows() / 2 ? fem.rows() - 1 : 0;
      CHECK(MatSetValues(A, 1, &rstart, 1, &far, &one, INSERT_VALUES) != 0);
    }
  }
  PCHK(MatDestroy(&A));
}
