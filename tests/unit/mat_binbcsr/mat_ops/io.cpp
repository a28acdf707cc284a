// PETSc binary files: MatView/MatLoad round trips with seqaij files, block sizes, malformed files.
#include "harness.hpp"

#include <cstdio>
#include <string>
#include <unistd.h>

using namespace matops;

namespace {

std::string temp_file(const char *tag)
{
  return "mat_ops_" + std::string(tag) + "_" + std::to_string((long)getpid()) + ".bin";
}

// No .info side file: its -matload_block_size would land in the global options database.
PetscErrorCode open(const std::string &name, PetscFileMode mode, PetscViewer *v)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerCreate(PETSC_COMM_SELF, v));
  PetscCall(PetscViewerSetType(*v, PETSCVIEWERBINARY));
  PetscCall(PetscViewerBinarySkipInfo(*v));
  PetscCall(PetscViewerFileSetMode(*v, mode));
  PetscCall(PetscViewerFileSetName(*v, name.c_str()));
  PetscFunctionReturn(0);
}

PetscErrorCode save(Mat A, const std::string &name)
{
  PetscViewer v;
  PetscFunctionBeginUser;
  PetscCall(open(name, FILE_MODE_WRITE, &v));
  PetscCall(MatView(A, v));
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

// Loads into a new matrix of the flavour (seqaij when null); block size from MatSetBlockSize when
// bs > 0, else whatever the options say.
PetscErrorCode load(const Flavour *f, PetscInt bs, const std::string &name, Mat *A)
{
  PetscViewer v;
  PetscFunctionBeginUser;
  PetscCall(MatCreate(PETSC_COMM_SELF, A));
  PetscCall(MatSetType(*A, f ? f->type : MATSEQAIJ));
  if (bs > 0) PetscCall(MatSetBlockSize(*A, bs));
  if (f && f->is_binbcsr()) {
    PetscCall(MatBinBCSRSetPrecision(*A, f->precision));
    if (f->bin_width) PetscCall(MatBinBCSRSetBinWidth(*A, f->bin_width));
  }
  PetscCall(open(name, FILE_MODE_READ, &v));
  PetscErrorCode ierr = MatLoad(*A, v);
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(ierr);
}

// Writes a raw binary matrix file: header, row lengths, columns, values, each possibly cut short.
PetscErrorCode write_raw(const std::string &name, PetscInt classid, PetscInt M, PetscInt N, PetscInt nz,
                         const std::vector<PetscInt> &rowlens, const std::vector<PetscInt> &cols,
                         const std::vector<PetscScalar> &vals)
{
  PetscViewer    v;
  const PetscInt header[4] = {classid, M, N, nz};
  PetscFunctionBeginUser;
  PetscCall(open(name, FILE_MODE_WRITE, &v));
  PetscCall(PetscViewerBinaryWrite(v, header, 4, PETSC_INT));
  if (!rowlens.empty())
    PetscCall(PetscViewerBinaryWrite(v, rowlens.data(), (PetscInt)rowlens.size(), PETSC_INT));
  if (!cols.empty()) PetscCall(PetscViewerBinaryWrite(v, cols.data(), (PetscInt)cols.size(), PETSC_INT));
  if (!vals.empty()) PetscCall(PetscViewerBinaryWrite(v, vals.data(), (PetscInt)vals.size(), PETSC_SCALAR));
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

} // namespace

TEST_CASE("MatView and MatLoad round-trip with seqaij files", "[mat_ops][io]")
{
  const std::string name = temp_file("roundtrip");
  for (const Flavour &f : flavours()) {
    for (const Pattern &p : patterns()) {
      INFO("flavour: " << f.name << ", pattern: " << p.name);
      Mat R, A, B, C;
      PETSC_OK(build(nullptr, p, &R));
      const std::vector<double> scale = row_abs_sums(R);
      // seqaij file -> flavour, block size set before the load
      PETSC_OK(save(R, name));
      PETSC_OK(load(&f, p.bs, name, &A));
      PetscInt bs;
      PETSC_OK(MatGetBlockSize(A, &bs));
      CHECK(bs == p.bs);
      CHECK_CLOSE(compare(A, R, scale), f.eps());
      // flavour -> file -> seqaij
      PETSC_OK(save(A, name));
      PETSC_OK(load(nullptr, 0, name, &B));
      CHECK_CLOSE(compare(B, R, scale), f.eps());
      // flavour -> file -> flavour, block size from -matload_block_size
      PETSC_OK(PetscOptionsSetValue(nullptr, "-matload_block_size", std::to_string(p.bs).c_str()));
      const PetscErrorCode loaded = load(&f, 0, name, &C);
      PETSC_OK(PetscOptionsClearValue(nullptr, "-matload_block_size"));
      PETSC_OK(loaded);
      PETSC_OK(MatGetBlockSize(C, &bs));
      CHECK(bs == p.bs);
      CHECK_CLOSE(compare(C, R, scale), f.eps());
      PETSC_OK(MatDestroy(&R));
      PETSC_OK(MatDestroy(&A));
      PETSC_OK(MatDestroy(&B));
      PETSC_OK(MatDestroy(&C));
    }
  }
  std::remove(name.c_str());
}

TEST_CASE("MatLoad of PETSc's data matrix with block size 3", "[mat_ops][io]")
{
  // the data files of the PETSc in use (tests/CMakeLists.txt finds them or stops configuring)
  const char *file = BINBCSR_PETSC_DATAFILES "/matrices/spd-real-int32-float64";
  REQUIRE(access(file, R_OK) == 0);
  for (const Flavour &f : flavours()) {
    INFO("flavour: " << f.name);
    Mat A, R;
    PETSC_OK(load(nullptr, 0, file, &R));
    PETSC_OK(load(&f, 3, file, &A));
    CHECK_CLOSE(compare(A, R, row_abs_sums(R)), f.eps());
    PetscReal na, nr;
    PETSC_OK(MatNorm(A, NORM_FROBENIUS, &na));
    PETSC_OK(MatNorm(R, NORM_FROBENIUS, &nr));
    CHECK(std::abs(na - nr) <= kRoundings * f.eps() * nr);
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  }
}

TEST_CASE("MatLoad refuses malformed files", "[mat_ops][io][errors]")
{
  const std::string name = temp_file("malformed");
  // A valid 4 x 4 file: rows {0,1}, {1}, {2,3}, {3}.
  const std::vector<PetscInt>    lens = {2, 1, 2, 1}, cols = {0, 1, 1, 2, 3, 3};
  const std::vector<PetscScalar> vals = {4, 1, 4, 4, 1, 4};
  for (const Flavour &f : flavours()) {
    INFO("flavour: " << f.name);
    Mat A = nullptr;
    PETSC_OK(write_raw(name, MAT_FILE_CLASSID, 4, 4, 6, lens, cols, vals));
    PETSC_OK(load(&f, 1, name, &A));
    PETSC_OK(MatDestroy(&A));
    struct Bad {
      const char              *what;
      bool                     generic; // refused by every type, not just the validating ones
      PetscInt                 classid, M, N, nz;
      std::vector<PetscInt>    lens, cols;
      std::vector<PetscScalar> vals;
      PetscInt                 bs;
    } bad[] = {
      {"not a matrix", true, VEC_FILE_CLASSID, 4, 4, 6, lens, cols, vals, 1},
      {"negative size", true, MAT_FILE_CLASSID, -4, 4, 6, lens, cols, vals, 1},
      {"row lengths do not sum to nz", true, MAT_FILE_CLASSID, 4, 4, 7, lens, cols, vals, 1},
      {"truncated values", true, MAT_FILE_CLASSID, 4, 4, 6, lens, cols, {4, 1}, 1},
      {"truncated row lengths", true, MAT_FILE_CLASSID, 4, 4, 6, {2, 1}, {}, {}, 1},
      {"size not a multiple of the block size", true, MAT_FILE_CLASSID, 4, 4, 6, lens, cols, vals, 3},
      {"negative row length", false, MAT_FILE_CLASSID, 4, 4, 6, {2, 3, -1, 2}, cols, vals, 1},
      {"column out of range", false, MAT_FILE_CLASSID, 4, 4, 6, lens, {0, 1, 1, 2, 9, 3}, vals, 1},
      {"negative column", false, MAT_FILE_CLASSID, 4, 4, 6, lens, {0, 1, -1, 2, 3, 3}, vals, 1},
    };
    for (const Bad &b : bad) {
      if (!b.generic && !f.validates_input) continue;
      INFO("file: " << b.what);
      PETSC_OK(write_raw(name, b.classid, b.M, b.N, b.nz, b.lens, b.cols, b.vals));
      CHECK(load(&f, b.bs, name, &A) != 0);
      PETSC_OK(MatDestroy(&A));
    }
  }
  std::remove(name.c_str());
}
