// MATMPIBINBCSR against the same matrix assembled serially (on every rank) and against MPIAIJ.
// Every TEST_CASE is collective on PETSC_COMM_WORLD: this program runs as unit_mpi on one rank and
// under mpiexec -n 2 and -n 3 (tests/mpi.cmake). Checks are reduced over the ranks first (all_ranks)
// so that every rank passes or fails together instead of leaving the others waiting.
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

enum class Fill { Blocked, Coo, ScalarOwnRows };

const char *fill_name(Fill f) { return f == Fill::Blocked ? "blocked+stash" : f == Fill::Coo ? "coo" : "scalar own rows"; }

// parts: type of the diagonal/off-diagonal parts (-mat_mpibinbcsr_inner_type), default seqbinbcsr.
PetscErrorCode assemble(const FemProblem &fem, MatType type, Fill fill, bool empty_rank0, Mat *A, const char *parts = nullptr)
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
template <class Weight>
std::vector<PetscScalar> rank_coo_values(const FemProblem &fem, Weight weight)
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
PetscErrorCode solve_to_tolerance(Mat A, Vec b, Vec x, KSPType kt, PCType pt, PetscInt *its, KSPConvergedReason *reason)
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

TEST_CASE("mpibinbcsr equals the serial matrix for every assembly path and partition", "[mpi]")
{
  for (bool shuffle : {false, true})
    for (bool empty_rank0 : {false, true})
      for (Fill fill : {Fill::Blocked, Fill::Coo, Fill::ScalarOwnRows}) {
        INFO("fill " << fill_name(fill) << ", shuffled numbering " << shuffle << ", rank 0 empty " << empty_rank0);
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
    for (int r = 0; r < size; ++r) CHECK(content.find("[" + std::to_string(r) + "] rows") != std::string::npos);
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

TEST_CASE("mpibinbcsr with symmetric storage (upper diagonal part, full off-diagonal part) equals the serial matrix", "[mpi][sym]")
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

TEST_CASE("mpibinbcsr: MatSOR local sweeps and PCSOR in CG equal mpibaij's (whole and symmetric storage)", "[mpi][sor]")
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
    for (int flag : {SOR_LOCAL_SYMMETRIC_SWEEP | SOR_ZERO_INITIAL_GUESS, (int)SOR_LOCAL_FORWARD_SWEEP, (int)SOR_LOCAL_BACKWARD_SWEEP})
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
TEST_CASE("mpibinbcsr: a COO refill with values reaches a PC set up before it (bjacobi, sor)", "[mpi][coo_state]")
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
