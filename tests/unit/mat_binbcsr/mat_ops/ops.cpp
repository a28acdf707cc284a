// Each value operation on every flavour and pattern, against seqaij.
#include "harness.hpp"

#include <cmath>
#include <random>

using namespace matops;

namespace {

template <class Body> void for_all(Body body)
{
  for (const Flavour &f : flavours()) {
    for (const Pattern &p : patterns()) {
      INFO("flavour: " << f.name << ", pattern: " << p.name);
      body(f, p);
    }
  }
}

// Point rows to zero: about a quarter of them, unsorted, only rows holding a diagonal entry when
// the zeroed rows must receive one.
std::vector<PetscInt> rows_to_zero(const Pattern &p, bool need_diagonal, unsigned seed)
{
  std::mt19937                       rng(seed);
  std::uniform_int_distribution<int> pct(0, 99);
  std::vector<PetscInt>              rows;
  for (PetscInt i = p.m() - 1; i >= 0; i--) {
    const bool has_diag =
      std::binary_search(p.cols.begin() + p.rowptr[i], p.cols.begin() + p.rowptr[i + 1], i);
    if ((has_diag || !need_diagonal) && (pct(rng) < 25 || p.m() == 1)) rows.push_back(i);
  }
  return rows;
}

std::vector<double> zeros(PetscInt m) { return std::vector<double>(m, 0.0); }

} // namespace

TEST_CASE("MatZeroEntries keeps the pattern and zeroes the values", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    Mat A, R;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    MatInfo before, after;
    PETSC_OK(MatGetInfo(A, MAT_LOCAL, &before));
    PETSC_OK(MatZeroEntries(A));
    PETSC_OK(MatGetInfo(A, MAT_LOCAL, &after));
    CHECK(after.nz_used == before.nz_used);
    Mat Z;
    PETSC_OK(MatDuplicate(R, MAT_COPY_VALUES, &Z));
    PETSC_OK(MatZeroEntries(Z));
    CHECK_CLOSE(compare(A, Z, zeros(p.m())), f.eps());
    // Refilling by adding gives the matrix again.
    PETSC_OK(fill(p, A, ADD_VALUES));
    CHECK_CLOSE(compare(A, R, row_abs_sums(R)), f.eps());
    PETSC_OK(MatDestroy(&Z));
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}

TEST_CASE("MatZeroEntries on a preallocated matrix before its first assembly", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    Mat A, R;
    PETSC_OK(preallocate(&f, p, &A));
    PETSC_OK(MatZeroEntries(A));
    PETSC_OK(fill(p, A, ADD_VALUES));
    PETSC_OK(build(nullptr, p, &R));
    CHECK_CLOSE(compare(A, R, row_abs_sums(R)), f.eps());
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}

TEST_CASE("MatScale", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    Mat               A, R;
    const PetscScalar a = -2.5;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    const std::vector<double> scale = scaled(row_abs_sums(R), a);
    PETSC_OK(MatScale(A, a));
    PETSC_OK(MatScale(R, a));
    CHECK_CLOSE(compare(A, R, scale), f.eps());
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}

TEST_CASE("MatShift", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    Mat               A, R;
    const PetscScalar a = 3.25;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    if (f.fixed_pattern && !p.has_full_diagonal()) {
      // The shift would need a diagonal entry the frozen pattern lacks.
      CHECK(MatShift(A, a) != 0);
    } else {
      const std::vector<double> scale = plus(row_abs_sums(R), std::vector<double>(p.m(), std::abs(a)));
      PETSC_OK(MatShift(A, a));
      PETSC_OK(MatShift(R, a));
      CHECK_CLOSE(compare(A, R, scale), f.eps());
    }
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}

TEST_CASE("MatDiagonalSet with INSERT_VALUES and ADD_VALUES", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    for (InsertMode mode : {INSERT_VALUES, ADD_VALUES}) {
      INFO("mode " << (mode == INSERT_VALUES ? "INSERT_VALUES" : "ADD_VALUES"));
      Mat A, R;
      Vec D;
      PETSC_OK(build(&f, p, &A));
      PETSC_OK(build(nullptr, p, &R));
      PETSC_OK(random_vec(p.m(), 11, &D));
      if (f.fixed_pattern && !p.has_full_diagonal()) {
        CHECK(MatDiagonalSet(A, D, mode) != 0);
      } else {
        const std::vector<double> scale = plus(row_abs_sums(R), std::vector<double>(p.m(), 1.0));
        PETSC_OK(MatDiagonalSet(A, D, mode));
        PETSC_OK(MatDiagonalSet(R, D, mode));
        CHECK_CLOSE(compare(A, R, scale), f.eps());
      }
      PETSC_OK(VecDestroy(&D));
      PETSC_OK(MatDestroy(&A));
      PETSC_OK(MatDestroy(&R));
    }
  });
}

TEST_CASE("MatAXPY with the same, a subset and a different pattern", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    const PetscScalar a    = -0.75;
    const Pattern     same = revalue(p, 21), other = other_pattern(p, 22);
    struct Case {
      const char    *name;
      const Pattern *x;
      MatStructure   str;
      bool           x_reference_type; // X stored as seqaij instead of the flavour
    } cases[] = {
      {"same pattern, SAME_NONZERO_PATTERN", &same, SAME_NONZERO_PATTERN, false},
      {"same pattern, UNKNOWN_NONZERO_PATTERN", &same, UNKNOWN_NONZERO_PATTERN, false},
      {"same pattern, SUBSET_NONZERO_PATTERN", &same, SUBSET_NONZERO_PATTERN, false},
      {"other pattern, DIFFERENT_NONZERO_PATTERN", &other, DIFFERENT_NONZERO_PATTERN, false},
      {"other pattern, UNKNOWN_NONZERO_PATTERN", &other, UNKNOWN_NONZERO_PATTERN, false},
      {"X seqaij, same pattern, SUBSET_NONZERO_PATTERN", &same, SUBSET_NONZERO_PATTERN, true},
      {"X seqaij, other pattern, DIFFERENT_NONZERO_PATTERN", &other, DIFFERENT_NONZERO_PATTERN, true},
    };
    for (const Case &c : cases) {
      INFO("case: " << c.name);
      Mat Y, X, RY, RX;
      PETSC_OK(build(&f, p, &Y));
      PETSC_OK(build(c.x_reference_type ? nullptr : &f, *c.x, &X));
      PETSC_OK(build(nullptr, p, &RY));
      PETSC_OK(build(nullptr, *c.x, &RX));
      const std::vector<double> scale = plus(row_abs_sums(RY), scaled(row_abs_sums(RX), a));
      PETSC_OK(MatAXPY(Y, a, X, c.str));
      PETSC_OK(MatAXPY(RY, a, RX, DIFFERENT_NONZERO_PATTERN));
      CHECK_CLOSE(compare(Y, RY, scale), f.eps());
      // Still a usable matrix of the same type.
      PetscBool same_type;
      PETSC_OK(PetscObjectTypeCompare((PetscObject)Y, f.type, &same_type));
      CHECK(same_type);
      Vec x, y, ry;
      PETSC_OK(random_vec(p.m(), 5, &x));
      PETSC_OK(VecDuplicate(x, &y));
      PETSC_OK(VecDuplicate(x, &ry));
      PETSC_OK(MatMult(Y, x, y));
      PETSC_OK(MatMult(RY, x, ry));
      // A sum of n products in another order: the classic bound n * eps * sum |a_ij x_j|.
      std::vector<double> product_scale(scale);
      for (PetscInt i = 0; i < p.m(); i++)
        product_scale[i] *= (double)(p.rowptr[i + 1] - p.rowptr[i] + c.x->rowptr[i + 1] - c.x->rowptr[i] + 1);
      CHECK_CLOSE(compare(y, ry, product_scale), f.eps());
      PETSC_OK(VecDestroy(&x));
      PETSC_OK(VecDestroy(&y));
      PETSC_OK(VecDestroy(&ry));
      PETSC_OK(MatDestroy(&Y));
      PETSC_OK(MatDestroy(&X));
      PETSC_OK(MatDestroy(&RY));
      PETSC_OK(MatDestroy(&RX));
    }
  });
}

TEST_CASE("MatAXPY between binbcsr matrices of different precision", "[mat_ops][binbcsr]")
{
  std::vector<Flavour> bins;
  for (const Flavour &f : flavours())
    if (f.is_binbcsr()) bins.push_back(f);
  for (const Flavour &fy : bins) {
    for (const Flavour &fx : bins) {
      for (const Pattern &p : patterns()) {
        INFO("Y: " << fy.name << ", X: " << fx.name << ", pattern: " << p.name);
        const PetscScalar a  = 1.5;
        const Pattern     xp = revalue(p, 31);
        Mat               Y, X, RY, RX;
        PETSC_OK(build(&fy, p, &Y));
        PETSC_OK(build(&fx, xp, &X));
        PETSC_OK(build(nullptr, p, &RY));
        PETSC_OK(build(nullptr, xp, &RX));
        const std::vector<double> scale = plus(row_abs_sums(RY), scaled(row_abs_sums(RX), a));
        PETSC_OK(MatAXPY(Y, a, X, SAME_NONZERO_PATTERN));
        PETSC_OK(MatAXPY(RY, a, RX, SAME_NONZERO_PATTERN));
        CHECK_CLOSE(compare(Y, RY, scale), std::max(fy.eps(), fx.eps()));
        PETSC_OK(MatDestroy(&Y));
        PETSC_OK(MatDestroy(&X));
        PETSC_OK(MatDestroy(&RY));
        PETSC_OK(MatDestroy(&RX));
      }
    }
  }
}

TEST_CASE("MatZeroRows with a diagonal value and the right-hand side fix", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    for (PetscScalar diag : {0.0, 2.0}) {
      for (bool vecs : {false, true}) {
        INFO("diag " << diag << (vecs ? ", with x and b" : ""));
        const std::vector<PetscInt> rows = rows_to_zero(p, diag != 0.0, 41);
        Mat                         A, R;
        Vec                         x = nullptr, b = nullptr, rb = nullptr;
        PETSC_OK(build(&f, p, &A));
        PETSC_OK(build(nullptr, p, &R));
        if (vecs) {
          PETSC_OK(random_vec(p.m(), 42, &x));
          PETSC_OK(random_vec(p.m(), 43, &b));
          PETSC_OK(VecDuplicate(b, &rb));
          PETSC_OK(VecCopy(b, rb));
        }
        const std::vector<double> scale = plus(row_abs_sums(R), std::vector<double>(p.m(), std::abs(diag)));
        PETSC_OK(MatZeroRows(A, (PetscInt)rows.size(), rows.data(), diag, x, b));
        PETSC_OK(MatZeroRows(R, (PetscInt)rows.size(), rows.data(), diag, x, rb));
        CHECK_CLOSE(compare(A, R, scale), f.eps());
        if (vecs) CHECK_CLOSE(compare(b, rb, plus(std::vector<double>(p.m(), 1.0), scale)), DBL_EPSILON);
        PETSC_OK(VecDestroy(&x));
        PETSC_OK(VecDestroy(&b));
        PETSC_OK(VecDestroy(&rb));
        PETSC_OK(MatDestroy(&A));
        PETSC_OK(MatDestroy(&R));
      }
    }
  });
}

TEST_CASE("MatZeroRowsColumns with a diagonal value and the right-hand side fix", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    for (PetscScalar diag : {0.0, 1.0, -3.0}) {
      for (bool vecs : {false, true}) {
        INFO("diag " << diag << (vecs ? ", with x and b" : ""));
        const std::vector<PetscInt> rows = rows_to_zero(p, diag != 0.0, 51);
        Mat                         A, R;
        Vec                         x = nullptr, b = nullptr, rb = nullptr;
        PETSC_OK(build(&f, p, &A));
        PETSC_OK(build(nullptr, p, &R));
        const std::vector<double> rowsum = row_abs_sums(R);
        std::vector<double>       btol(p.m());
        if (vecs) {
          PETSC_OK(random_vec(p.m(), 52, &x));
          PETSC_OK(random_vec(p.m(), 53, &b));
          PETSC_OK(VecDuplicate(b, &rb));
          PETSC_OK(VecCopy(b, rb));
          // b_i -= sum over zeroed columns of a_ij x_j, with |x_j| <= 1.
          for (PetscInt i = 0; i < p.m(); i++) btol[i] = 1.0 + rowsum[i] + std::abs(diag);
        }
        PETSC_OK(MatZeroRowsColumns(A, (PetscInt)rows.size(), rows.data(), diag, x, b));
        PETSC_OK(MatZeroRowsColumns(R, (PetscInt)rows.size(), rows.data(), diag, x, rb));
        CHECK_CLOSE(compare(A, R, plus(rowsum, std::vector<double>(p.m(), std::abs(diag)))), f.eps());
        if (vecs) CHECK_CLOSE(compare(b, rb, btol), f.eps());
        PETSC_OK(VecDestroy(&x));
        PETSC_OK(VecDestroy(&b));
        PETSC_OK(VecDestroy(&rb));
        PETSC_OK(MatDestroy(&A));
        PETSC_OK(MatDestroy(&R));
      }
    }
  });
}

TEST_CASE("MatZeroRows on a row without a stored diagonal", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    if (p.has_full_diagonal()) return;
    std::vector<PetscInt> rows = rows_to_zero(p, false, 61);
    Mat                   A, R;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    // Without a diagonal value every format just zeroes the rows.
    PETSC_OK(MatZeroRows(A, (PetscInt)rows.size(), rows.data(), 0.0, nullptr, nullptr));
    PETSC_OK(MatZeroRows(R, (PetscInt)rows.size(), rows.data(), 0.0, nullptr, nullptr));
    CHECK_CLOSE(compare(A, R, row_abs_sums(R)), f.eps());
    if (f.fixed_pattern) {
      // A diagonal value needs an entry the frozen pattern lacks: a clear error, not a crash.
      PetscInt empty = -1;
      for (PetscInt i = 0; i < p.m() && empty < 0; i++)
        if (!std::binary_search(p.cols.begin() + p.rowptr[i], p.cols.begin() + p.rowptr[i + 1], i)) empty = i;
      CHECK(MatZeroRows(A, 1, &empty, 1.0, nullptr, nullptr) != 0);
      CHECK(MatZeroRowsColumns(A, 1, &empty, 1.0, nullptr, nullptr) != 0);
    }
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}

TEST_CASE("MatNorm: Frobenius, 1 and infinity", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    Mat A, R;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    for (NormType t : {NORM_FROBENIUS, NORM_1, NORM_INFINITY}) {
      INFO("norm " << NormTypes[t]);
      PetscReal got, want;
      PETSC_OK(MatNorm(A, t, &got));
      PETSC_OK(MatNorm(R, t, &want));
      // Each stored entry is within eps/2 of the true one, relatively, and so is any of these norms;
      // the sums of k positive terms in another order add up to (k - 1) double roundings.
      const double terms = t == NORM_FROBENIUS ? (double)p.cols.size() : (double)p.m();
      CHECK(std::abs(got - want) <= (kRoundings * f.eps() + terms * DBL_EPSILON) * want);
    }
    PetscReal two;
    CHECK(MatNorm(A, NORM_2, &two) != 0);
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}

TEST_CASE("MatGetInfo", "[mat_ops]")
{
  for_all([](const Flavour &f, const Pattern &p) {
    Mat A, R;
    PETSC_OK(build(&f, p, &A));
    PETSC_OK(build(nullptr, p, &R));
    MatInfo got, want;
    PETSC_OK(MatGetInfo(A, MAT_LOCAL, &got));
    PETSC_OK(MatGetInfo(R, MAT_LOCAL, &want));
    // PETSc's BAIJ convention: block_size holds bs^2, the values per stored block.
    CHECK(got.block_size == (PetscLogDouble)(p.bs * p.bs));
    CHECK(got.nz_used == want.nz_used);
    CHECK(got.nz_allocated >= got.nz_used);
    CHECK(got.nz_unneeded == got.nz_allocated - got.nz_used);
    CHECK(got.assemblies >= 1);
    CHECK(got.mallocs == 0);
    if (f.is_binbcsr()) {
      // The bin layout is the allocation: values and indices take at least the used entries' bytes.
      const double value_bytes = f.precision == MAT_BINBCSR_PRECISION_SINGLE ? 4 : 8;
      CHECK(got.memory >= got.nz_used * value_bytes);
    }
    PETSC_OK(MatDestroy(&A));
    PETSC_OK(MatDestroy(&R));
  });
}
