// Bad input to the value operations: a PETSc error code, never a crash or silent garbage.
#include "harness.hpp"

#include <cmath>
#include <limits>

using namespace matops;

namespace {
// The FEM pattern with 3x3 blocks: every row has a diagonal.
const Pattern &fem()
{
  static const Pattern p = patterns().front();
  return p;
}
} // namespace

TEST_CASE("rows out of range in MatZeroRows and MatZeroRowsColumns", "[mat_ops][errors]")
{
  for (const Flavour &f : flavours()) {
    INFO("flavour: " << f.name);
    const Pattern &p = fem();
    Mat            A, R;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    const PetscInt too_large[] = {0, p.m() + 5};
    CHECK(MatZeroRows(A, 2, too_large, 1.0, nullptr, nullptr) != 0);
    CHECK(MatZeroRowsColumns(A, 2, too_large, 1.0, nullptr, nullptr) != 0);
    if (f.validates_input) {
      // seqbaij checks row <= N only, and writes b[-1] before checking: only the checked types here.
      const PetscInt at_end[] = {p.m()}, negative[] = {-1};
      CHECK(MatZeroRows(A, 1, at_end, 1.0, nullptr, nullptr) != 0);
      CHECK(MatZeroRows(A, 1, negative, 1.0, nullptr, nullptr) != 0);
      CHECK(MatZeroRowsColumns(A, 1, negative, 1.0, nullptr, nullptr) != 0);
      // A refused call changes nothing.
      CHECK_CLOSE(compare(A, R, row_abs_sums(R)), f.eps());
    }
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  }
}

TEST_CASE("wrong vector sizes", "[mat_ops][errors]")
{
  for (const Flavour &f : flavours()) {
    INFO("flavour: " << f.name);
    const Pattern &p = fem();
    Mat            A;
    Vec            good, short_vec;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(random_vec(p.m(), 1, &good));
    PETSC_OK(random_vec(p.m() - 1, 2, &short_vec));
    CHECK(MatDiagonalSet(A, short_vec, INSERT_VALUES) != 0);
    if (f.validates_input) {
      const PetscInt rows[] = {0, 4};
      CHECK(MatZeroRows(A, 2, rows, 1.0, short_vec, good) != 0);
      CHECK(MatZeroRows(A, 2, rows, 1.0, good, short_vec) != 0);
      CHECK(MatZeroRowsColumns(A, 2, rows, 1.0, short_vec, good) != 0);
      CHECK(MatZeroRowsColumns(A, 2, rows, 1.0, good, short_vec) != 0);
    }
    PETSC_OK(VecDestroy(&good));
    PETSC_OK(VecDestroy(&short_vec));
    PETSC_OK(MatDestroy(&A));
  }
}

TEST_CASE("MatAXPY of matrices of different sizes or block sizes", "[mat_ops][errors]")
{
  for (const Flavour &f : flavours()) {
    INFO("flavour: " << f.name);
    const std::vector<Pattern> all = patterns();
    Mat                        Y, X;
    PETSC_OK(build(&f, all[0], &Y)); // 60 block rows of 3
    PETSC_OK(build(&f, all[1], &X)); // 105 scalar rows
    CHECK(MatAXPY(Y, 1.0, X, DIFFERENT_NONZERO_PATTERN) != 0);
    PETSC_OK(MatDestroy(&X));
    PETSC_OK(MatDestroy(&Y));
  }
}

TEST_CASE("NaN operands with MatSetErrorIfFailure", "[mat_ops][errors]")
{
  const PetscScalar nan = std::numeric_limits<double>::quiet_NaN();
  for (const Flavour &f : flavours()) {
    if (!f.validates_input) continue;
    INFO("flavour: " << f.name);
    const Pattern &p = fem();
    Mat            A, X, R;
    Vec            D;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(&f, p, &X));
    PETSC_OK(build(nullptr, p, &R));
    PETSC_OK(random_vec(p.m(), 3, &D));
    PETSC_OK(VecSetValue(D, 7, nan, INSERT_VALUES));
    PETSC_OK(VecAssemblyBegin(D));
    PETSC_OK(VecAssemblyEnd(D));
    PETSC_OK(MatSetErrorIfFailure(A, PETSC_TRUE));
    CHECK(MatScale(A, nan) != 0);
    CHECK(MatShift(A, nan) != 0);
    CHECK(MatDiagonalSet(A, D, ADD_VALUES) != 0);
    CHECK(MatAXPY(A, nan, X, SAME_NONZERO_PATTERN) != 0);
    const PetscInt rows[] = {1, 2};
    CHECK(MatZeroRows(A, 2, rows, nan, nullptr, nullptr) != 0);
    CHECK(MatZeroRowsColumns(A, 2, rows, nan, nullptr, nullptr) != 0);
    // Nothing was changed by the refused calls.
    CHECK_CLOSE(compare(A, R, row_abs_sums(R)), f.eps());
    // Without the option, NaN is the caller's business (as in PETSc's release builds).
    PETSC_OK(MatSetErrorIfFailure(A, PETSC_FALSE));
    PETSC_OK(MatScale(A, nan));
    PetscReal nrm;
    PETSC_OK(MatNorm(A, NORM_FROBENIUS, &nrm));
    CHECK(std::isnan(nrm));
    PETSC_OK(VecDestroy(&D));
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&X));
    PETSC_OK(MatDestroy(&R));
  }
}
