// The layout tuner on MATMPIBINBCSR: every rank tunes its own diagonal and off-diagonal parts (no
// communication: the ranks may choose differently), the matrix equals MPIAIJ's, the products agree,
// and -mat_binbcsr_tune off / explicit settings reach the parts. Collective on PETSC_COMM_WORLD (run
// on 1, 2 and 3 ranks by tests/mpi.cmake).
#include <catch2/catch.hpp>

#include "support/fem_problem.hpp"
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

using namespace mpitest;

#define PCHK(expr) REQUIRE((expr) == 0)

namespace {

// prefix: the matrix's options prefix, or null
Mat coo_matrix(const FemProblem &fem, MatType type, const char *prefix = nullptr)
{
  Mat                   A;
  std::vector<PetscInt> ci, cj;
  const PetscInt        m = local_rows(fem, PETSC_COMM_WORLD, false);
  rank_coo_entries(fem, ci, cj);
  const auto cv = rank_element_values(fem, [](int e) { return 1.0 + 0.01 * (e % 5); });
  PCHK(MatCreate(PETSC_COMM_WORLD, &A));
  PCHK(MatSetOptionsPrefix(A, prefix));
  PCHK(MatSetSizes(A, m, m, fem.rows(), fem.rows()));
  PCHK(MatSetBlockSize(A, 3));
  PCHK(MatSetType(A, type));
  PCHK(MatSetFromOptions(A));
  PCHK(MatSetPreallocationCOO(A, (PetscCount)ci.size(), ci.data(), cj.data()));
  PCHK(MatSetValuesCOO(A, cv.data(), ADD_VALUES));
  return A;
}

std::string info_text(Mat A)
{
  char        name[] = "/tmp/tune_mpi_viewXXXXXX";
  PetscViewer v;
  PetscMPIInt rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  std::string path;
  if (rank == 0) {
    const int fd = mkstemp(name);
    if (fd >= 0) close(fd);
    path = name;
  }
  int len = (int)path.size();
  MPI_Bcast(&len, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  path.resize(len);
  MPI_Bcast(&path[0], len, MPI_CHAR, 0, PETSC_COMM_WORLD);
  PCHK(PetscViewerASCIIOpen(PETSC_COMM_WORLD, path.c_str(), &v));
  PCHK(PetscViewerPushFormat(v, PETSC_VIEWER_ASCII_INFO));
  PCHK(MatView(A, v));
  PCHK(PetscViewerPopFormat(v));
  PCHK(PetscViewerDestroy(&v));
  std::string text;
  if (FILE *f = fopen(path.c_str(), "r")) {
    char buf[4096];
    for (size_t n; (n = fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
    fclose(f);
  }
  MPI_Barrier(PETSC_COMM_WORLD);
  if (rank == 0) remove(path.c_str());
  return text;
}

} // namespace

TEST_CASE("mpi: each rank tunes its parts; the matrix and its products stay MPIAIJ's", "[mpi][tune]")
{
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune_min_kib", "0"));
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune_cache", "0"));
  const FemProblem fem(9, 8, 7, true);
  Mat              A = coo_matrix(fem, MATMPIBINBCSR), R = coo_matrix(fem, MATMPIAIJ);
  // each stored value is a sum of up to 8 element entries, summed in another order than MPIAIJ's
  const double sum_tol = 16 * PETSC_MACHINE_EPSILON;
  CHECK(all_ranks(mat_rel_diff(A, R) < sum_tol));
  Vec x, y, yr;
  PCHK(MatCreateVecs(R, &x, &y));
  PCHK(VecDuplicate(y, &yr));
  PCHK(VecSetRandom(x, nullptr));
  PCHK(MatMult(A, x, y));
  PCHK(MatMult(R, x, yr));
  CHECK(all_ranks(vec_rel_diff(y, yr) < 1e-13)); // the summation orders of the two formats differ
  const std::string txt = info_text(A);
  PetscMPIInt       size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  // every rank's diagonal part says what it measured (rank 0's viewer gathers them all)
  size_t n = 0;
  for (size_t p = txt.find("measured on block rows"); p != std::string::npos;
       p        = txt.find("measured on block rows", p + 1))
    n++;
  PetscMPIInt rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) {
    CAPTURE(txt);
    CHECK(n >= (size_t)size);
  }
  // a duplicate keeps every rank's choice and values
  Mat D;
  PCHK(MatDuplicate(A, MAT_COPY_VALUES, &D));
  CHECK(all_ranks(mat_rel_diff(D, R) < sum_tol));
  MatDestroy(&D);
  // off reaches the parts; the untuned matrix gives bit-identical products (same values, same order
  // of summation in each row)
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune", "off"));
  Mat U = coo_matrix(fem, MATMPIBINBCSR);
  Vec yu;
  PCHK(VecDuplicate(y, &yu));
  PCHK(MatMult(U, x, yu));
  CHECK(all_ranks(vec_rel_diff(y, yu) == 0.0));
  VecDestroy(&yu);
  MatDestroy(&A);
  A = U;
  MatBinBCSRTune t;
  PCHK(MatBinBCSRGetTune(A, &t));
  CHECK(t == MAT_BINBCSR_TUNE_OFF);
  CHECK(all_ranks(info_text(A).find("measured on block rows") == std::string::npos));
  CHECK(all_ranks(mat_rel_diff(A, R) < sum_tol));
  MatDestroy(&A);
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune"));
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune_min_kib"));
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune_cache"));
  MatDestroy(&R);
  VecDestroy(&x);
  VecDestroy(&y);
  VecDestroy(&yr);
}

// A matrix with an options prefix: the tuner's knobs read by the parts themselves (the size below
// which a part is not tuned, the cache) come under that prefix, as the type's other options do; the
// same knobs without it are another matrix's and change nothing here.
TEST_CASE("mpi: the parts read the tuner's options under the matrix's prefix", "[mpi][tune]")
{
  const FemProblem fem(7, 6, 5, true); // under 512 KiB of values on one rank
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune_min_kib", "0")); // not this matrix's
  PCHK(PetscOptionsSetValue(nullptr, "-sys_mat_binbcsr_tune_cache", "0"));
  Mat A = coo_matrix(fem, MATMPIBINBCSR, "sys_"); // the parts are below the default 512 KiB: not tuned
  CHECK(all_ranks(info_text(A).find("measured on block rows") == std::string::npos));
  MatDestroy(&A);
  PCHK(PetscOptionsSetValue(nullptr, "-sys_mat_binbcsr_tune_min_kib", "0"));
  A                     = coo_matrix(fem, MATMPIBINBCSR, "sys_");
  const std::string txt = info_text(A);
  PetscMPIInt       rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) {
    CAPTURE(txt);
    CHECK(txt.find("measured on block rows") != std::string::npos);
  }
  MatDestroy(&A);
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune_min_kib"));
  PCHK(PetscOptionsClearValue(nullptr, "-sys_mat_binbcsr_tune_min_kib"));
  PCHK(PetscOptionsClearValue(nullptr, "-sys_mat_binbcsr_tune_cache"));
}
