// Repeated entries and bad column indices in MatLoad files and in MatSetValues(ADD_VALUES), on any
// number of ranks (unit_mpi, unit_mpi_np2, unit_mpi_np3). seqaij keeps a repeated entry of a file as
// two stored nonzeros and its product sums them, which is also what ADD_VALUES means: the product
// must be that sum whether the load goes through the serial or the parallel reader. A negative or
// too large column index is refused on every rank (seqaij would read outside x, mpiaij drops it).
#include <catch2/catch.hpp>

#include "support/fem_problem.hpp"

#include <petscbinbcsr.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <unistd.h>
#include <vector>

using namespace mpitest;

#define PCHK(expr) REQUIRE((expr) == 0)

namespace {

// 6 x 6, both bs 1 and bs 3 fit. Row 0 names its diagonal twice (4 and -1: aij's product uses 3),
// row 4 names column 0 twice (on two ranks an off-diagonal-part column) and row 5 column 5 three times.
struct FileMatrix {
  std::vector<PetscInt>    lens{3, 2, 2, 2, 3, 4};
  std::vector<PetscInt>    cols{0, 1, 0, 1, 2, 2, 3, 3, 4, 4, 0, 0, 5, 5, 5, 1};
  std::vector<PetscScalar> vals{4, 1, -1, 4, 1, 4, 1, 4, 1, 4, 2, 0.5, 4, -1, 0.25, 1};
  PetscInt                 n = 6;
  // y = A x with every entry counted (seqaij's product).
  std::vector<double> product(const std::vector<double> &x) const
  {
    std::vector<double> y(n, 0.0);
    size_t              k = 0;
    for (PetscInt i = 0; i < n; ++i)
      for (PetscInt q = 0; q < lens[i]; ++q, ++k) y[i] += vals[k] * x[cols[k]];
    return y;
  }
};

std::string shared_name(const char *tag)
{
  char        name[PETSC_MAX_PATH_LEN] = "";
  PetscMPIInt rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) std::snprintf(name, sizeof name, "/tmp/binbcsr_%s_%d.bin", tag, static_cast<int>(getpid()));
  MPI_Bcast(name, sizeof name, MPI_CHAR, 0, PETSC_COMM_WORLD);
  return name;
}

// No .info side file: its -matload_block_size would land in the global options database.
PetscErrorCode open(const std::string &name, PetscFileMode mode, PetscViewer *v)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerCreate(PETSC_COMM_WORLD, v));
  PetscCall(PetscViewerSetType(*v, PETSCVIEWERBINARY));
  PetscCall(PetscViewerBinarySkipInfo(*v));
  PetscCall(PetscViewerFileSetMode(*v, mode));
  PetscCall(PetscViewerFileSetName(*v, name.c_str()));
  PetscFunctionReturn(0);
}

PetscErrorCode write_file(const std::string &name, const FileMatrix &f)
{
  PetscViewer    v;
  const PetscInt header[4] = {MAT_FILE_CLASSID, f.n, f.n, (PetscInt)f.cols.size()};
  PetscFunctionBeginUser;
  PetscCall(open(name, FILE_MODE_WRITE, &v));
  PetscCall(PetscViewerBinaryWrite(v, header, 4, PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(v, f.lens.data(), (PetscInt)f.lens.size(), PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(v, f.cols.data(), (PetscInt)f.cols.size(), PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(v, f.vals.data(), (PetscInt)f.vals.size(), PETSC_SCALAR));
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

PetscErrorCode load(MatType type, PetscInt bs, const std::string &name, Mat *A)
{
  PetscViewer v;
  PetscFunctionBeginUser;
  PetscCall(MatCreate(PETSC_COMM_WORLD, A));
  PetscCall(MatSetType(*A, type));
  PetscCall(MatSetBlockSize(*A, bs));
  PetscCall(open(name, FILE_MODE_READ, &v));
  PetscErrorCode ierr = MatLoad(*A, v);
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(ierr);
}

// Largest |A x - y_expected| over every rank for x_i = 1 + i.
double product_error(Mat A, const std::vector<double> &expected)
{
  Vec      x, y;
  PetscInt rstart, rend;
  double   err = 0;
  REQUIRE(MatCreateVecs(A, &x, &y) == 0);
  REQUIRE(VecGetOwnershipRange(x, &rstart, &rend) == 0);
  for (PetscInt i = rstart; i < rend; ++i) REQUIRE(VecSetValue(x, i, 1.0 + i, INSERT_VALUES) == 0);
  REQUIRE(VecAssemblyBegin(x) == 0);
  REQUIRE(VecAssemblyEnd(x) == 0);
  REQUIRE(MatMult(A, x, y) == 0);
  const PetscScalar *a;
  REQUIRE(VecGetArrayRead(y, &a) == 0);
  for (PetscInt i = rstart; i < rend; ++i)
    err = std::max(err, std::abs((double)PetscRealPart(a[i - rstart]) - expected[i]));
  REQUIRE(VecRestoreArrayRead(y, &a) == 0);
  REQUIRE(VecDestroy(&x) == 0);
  REQUIRE(VecDestroy(&y) == 0);
  MPI_Allreduce(MPI_IN_PLACE, &err, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  return err;
}

std::vector<double> ramp(PetscInt n)
{
  std::vector<double> x(n);
  for (PetscInt i = 0; i < n; ++i) x[i] = 1.0 + i;
  return x;
}

} // namespace

TEST_CASE("MatLoad of a file with repeated entries gives seqaij's product (the sum)", "[mpi][load]")
{
  const FileMatrix  f;
  const std::string name     = shared_name("dups");
  const auto        expected = f.product(ramp(f.n));
  PCHK(write_file(name, f));
  {
    Mat         S; // the reference itself, where it is serial
    PetscMPIInt size;
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    if (size == 1) {
      PCHK(load(MATSEQAIJ, 1, name, &S));
      CHECK(product_error(S, expected) < 1e-12);
      PCHK(MatDestroy(&S));
    }
  }
  for (MatType type : {MATBINBCSR, MATMPIBINBCSR})
    for (PetscInt bs : {1, 3}) {
      INFO("type " << type << " bs " << bs);
      Mat A;
      PCHK(load(type, bs, name, &A));
      CHECK(product_error(A, expected) < 1e-12);
      PCHK(MatDestroy(&A));
    }
  MPI_Barrier(PETSC_COMM_WORLD);
  std::remove(name.c_str());
}

TEST_CASE("MatLoad refuses a negative or too large column on every rank and any reader",
          "[mpi][load][errors]")
{
  for (PetscInt bad : {-1, 6}) {
    FileMatrix f;
    f.cols[13]             = bad; // row 5: on the last rank when there are several
    const std::string name = shared_name("badcol");
    PCHK(write_file(name, f));
    for (MatType type : {MATBINBCSR, MATMPIBINBCSR})
      for (PetscInt bs : {1, 3}) {
        INFO("type " << type << " bs " << bs << " column " << bad);
        Mat                  A    = nullptr;
        const PetscErrorCode ierr = load(type, bs, name, &A);
        CHECK(all_ranks(ierr != 0));
        PCHK(MatDestroy(&A));
      }
    MPI_Barrier(PETSC_COMM_WORLD);
    std::remove(name.c_str());
  }
}

TEST_CASE("MatSetValues with ADD_VALUES and a column named twice in one call sums both", "[mpi][load]")
{
  const FileMatrix f;
  const auto       expected = f.product(ramp(f.n));
  PetscMPIInt      rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  for (PetscInt bs : {1, 3})
    for (bool refill : {false, true}) {
      INFO("bs " << bs << (refill ? " refill of the assembled pattern" : " first assembly"));
      Mat A;
      PCHK(MatCreate(PETSC_COMM_WORLD, &A));
      PCHK(MatSetSizes(A, PETSC_DECIDE, PETSC_DECIDE, f.n, f.n));
      PCHK(MatSetBlockSize(A, bs));
      PCHK(MatSetType(A, MATBINBCSR));
      PCHK(MatSetUp(A));
      // Every row from the rank after its owner's (rows of other ranks go through the stash).
      auto set_all = [&] {
        const PetscInt *ranges;
        REQUIRE(MatGetOwnershipRanges(A, &ranges) == 0);
        size_t k = 0;
        for (PetscInt i = 0; i < f.n; ++i) {
          PetscMPIInt owner = 0;
          while (i >= ranges[owner + 1]) ++owner;
          if ((owner + 1) % size == rank)
            REQUIRE(MatSetValues(A, 1, &i, f.lens[i], &f.cols[k], &f.vals[k], ADD_VALUES) == 0);
          k += (size_t)f.lens[i];
        }
        REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
        REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
      };
      set_all();
      if (refill) {
        PCHK(MatZeroEntries(A));
        set_all();
      }
      CHECK(product_error(A, expected) < 1e-12);
      PCHK(MatDestroy(&A));
    }
}
