// MatGetDiagonal, MatInvertBlockDiagonal, MatGetRow, MatDuplicate, MatCopy, MatConvert (both ways),
// precision switching and MatView of MATSEQBINBCSR against seqaij/seqbaij.
#include "support/mat_support.hpp"
#include <algorithm>
#include <petsc/private/matimpl.h>
#include <cstdio>
#include <fstream>
#include <sstream>

using namespace mat_core;

TEST_CASE("diagonal and inverted block diagonal against seqbaij", "[mat_core][diag]")
{
  const PetscInt            bs   = GENERATE(1, 2, 3);
  const PetscInt            bw   = GENERATE(4, 8, 3);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  Pattern p = random_pattern(21, 21, bs, 4, 3);
  for (Entry &e : p.entries) // every row needs its diagonal block for the inverse
    if (e.i / bs == e.j / bs && e.i == e.j) e.v += 10;
  for (PetscInt r = 0; r < 21; r++)
    for (PetscInt i = 0; i < bs; i++) p.entries.push_back({r * bs + i, r * bs + i, 0.0});
  // dedupe: keep the first of each position (the diagonal bump lives there)
  std::sort(p.entries.begin(), p.entries.end(), [](const Entry &a, const Entry &b) {
    return a.i < b.i || (a.i == b.i && (a.j < b.j || (a.j == b.j && a.v > b.v)));
  });
  p.entries.erase(std::unique(p.entries.begin(), p.entries.end(),
                              [](const Entry &a, const Entry &b) { return a.i == b.i && a.j == b.j; }),
                  p.entries.end());
  for (Entry &e : p.entries)
    if (e.i == e.j && e.v == 0.0) e.v = 3.0 + e.i % 5;
  Mat A = build(p, MATSEQBINBCSR, bw, prec), B = build(p, MATSEQBAIJ);
  // the values A holds (float-rounded in single precision)
  const double unit = prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON : 4 * DBL_EPSILON;

  Vec d, dref;
  REQUIRE(MatCreateVecs(A, nullptr, &d) == 0);
  REQUIRE(MatCreateVecs(B, nullptr, &dref) == 0);
  REQUIRE(MatGetDiagonal(A, d) == 0);
  REQUIRE(MatGetDiagonal(B, dref) == 0);
  check_close(values(d), values(dref), std::vector<double>(p.m, unit * 1e2));

  const PetscScalar *inv, *invref;
  REQUIRE(MatInvertBlockDiagonal(A, &inv) == 0);
  REQUIRE(MatInvertBlockDiagonal(B, &invref) == 0);
  // blocks are diagonally dominant (condition number < 10): the inverse error is a few units of
  // the storage rounding
  size_t bad = 0;
  for (PetscInt k = 0; k < 21 * bs * bs; k++)
    if (!(std::fabs(inv[k] - invref[k]) <= 50 * unit * (std::fabs(invref[k]) + 0.1))) bad++;
  CHECK(bad == 0);
  VecDestroy(&d);
  VecDestroy(&dref);
  MatDestroy(&A);
  MatDestroy(&B);
}

TEST_CASE("a zero diagonal block gives a zero-pivot error", "[mat_core][diag]")
{
  Pattern p = random_pattern(6, 6, 3, 0, 1, false); // no blocks at all
  p.entries.push_back({0, 3, 1.0});
  Mat A = build(p, MATSEQBINBCSR);
  REQUIRE(MatSetErrorIfFailure(A, PETSC_TRUE) == 0);
  const PetscScalar *inv;
  CHECK(MatInvertBlockDiagonal(A, &inv) == PETSC_ERR_MAT_LU_ZRPVT);
  MatDestroy(&A);
}

TEST_CASE("MatGetRow against seqaij", "[mat_core][getrow]")
{
  const PetscInt bs = GENERATE(1, 3);
  const PetscInt bw = GENERATE(1, 8);
  Pattern        p  = random_pattern(17, 13, bs, 5, 9);
  Mat            A = build(p, MATSEQBINBCSR, bw), R = build(p, MATSEQAIJ);
  for (PetscInt r = 0; r < p.m; r++) {
    PetscInt           n, nr;
    const PetscInt    *c, *cr;
    const PetscScalar *v, *vr;
    REQUIRE(MatGetRow(R, r, &nr, &cr, &vr) == 0);
    std::vector<PetscInt>    colsref(cr, cr + nr);
    std::vector<PetscScalar> valsref(vr, vr + nr);
    REQUIRE(MatRestoreRow(R, r, &nr, &cr, &vr) == 0); // (sets nr to 0)
    REQUIRE(MatGetRow(A, r, &n, &c, &v) == 0);
    CAPTURE(r, bs, bw);
    REQUIRE(n == (PetscInt)colsref.size()); // whole blocks are stored, as in the AIJ reference
    for (PetscInt k = 0; k < n; k++) {
      CHECK(c[k] == colsref[k]);
      CHECK(v[k] == valsref[k]);
    }
    REQUIRE(MatRestoreRow(A, r, &n, &c, &v) == 0);
  }
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("MatDuplicate and MatCopy", "[mat_core][copy]")
{
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  Pattern                   p    = fem_pattern(4, 3, 2);
  Mat                       A    = build(p, MATSEQBINBCSR, 4, prec), D, Z;
  const auto                ref  = dense(A);
  REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &D) == 0);
  check_dense(dense(D), ref, 0);
  REQUIRE(MatDuplicate(A, MAT_DO_NOT_COPY_VALUES, &Z) == 0);
  for (PetscScalar v : dense(Z)) CHECK(v == 0.0);
  PetscInt bw;
  REQUIRE(MatBinBCSRGetBinWidth(Z, &bw) == 0);
  CHECK(bw == 4);
  // same pattern fast path, both structure flags
  REQUIRE(MatCopy(A, Z, SAME_NONZERO_PATTERN) == 0);
  check_dense(dense(Z), ref, 0);
  REQUIRE(MatCopy(A, Z, DIFFERENT_NONZERO_PATTERN) == 0);
  check_dense(dense(Z), ref, 0);
  // into a matrix of the other precision
  REQUIRE(MatBinBCSRSetPrecision(Z, prec == MAT_BINBCSR_PRECISION_DOUBLE
                                      ? MAT_BINBCSR_PRECISION_SINGLE
                                      : MAT_BINBCSR_PRECISION_DOUBLE) == 0);
  REQUIRE(MatCopy(A, Z, SAME_NONZERO_PATTERN) == 0);
  check_dense(dense(Z), ref, FLT_EPSILON / 2);
  // into seqaij with a larger pattern, and into a binbcsr with a different (superset) pattern
  Mat R = build(p, MATSEQAIJ);
  REQUIRE(MatCopy(A, R, DIFFERENT_NONZERO_PATTERN) == 0);
  check_dense(dense(R), ref, 0);
  Pattern big = p;
  big.entries.push_back({0, p.n - 1, 0.0});
  big.entries.push_back({p.n - 1, 0, 0.0});
  Mat Big = build(big, MATSEQBINBCSR, 8);
  REQUIRE(MatCopy(A, Big, DIFFERENT_NONZERO_PATTERN) == 0);
  check_dense(dense(Big), ref, 0);
  // a smaller pattern cannot take A
  Pattern small = p;
  small.entries.resize(p.entries.size() / 2);
  Mat Small = build(small, MATSEQBINBCSR);
  CHECK(MatCopy(A, Small, DIFFERENT_NONZERO_PATTERN) == PETSC_ERR_ARG_OUTOFRANGE);
  for (Mat *M : {&A, &D, &Z, &R, &Big, &Small}) MatDestroy(M);
}

TEST_CASE("MatConvert to and from seqaij and seqbaij", "[mat_core][convert]")
{
  const PetscInt bs  = GENERATE(1, 3);
  Pattern        p   = random_pattern(14, 14, bs, 4, 21);
  const auto     ref = dense(p);
  Mat            A   = build(p, MATSEQBINBCSR, 4);
  for (MatType t : {MATSEQAIJ, MATSEQBAIJ, MATAIJ}) {
    Mat       B;
    PetscBool is;
    CAPTURE(t);
    REQUIRE(MatConvert(A, t, MAT_INITIAL_MATRIX, &B) == 0);
    check_dense(dense(B), ref, 0);
    PetscInt bbs;
    REQUIRE(MatGetBlockSize(B, &bbs) == 0);
    CHECK(bbs == bs);
    {
      // the new matrix is a whole one: its own product, and new values through a reuse
      Vec x, y, yr;
      REQUIRE(MatCreateVecs(A, &x, &y) == 0);
      REQUIRE(VecDuplicate(y, &yr) == 0);
      REQUIRE(VecSetRandom(x, nullptr) == 0);
      REQUIRE(MatMult(A, x, yr) == 0);
      REQUIRE(MatMult(B, x, y) == 0);
      PetscReal err, norm;
      REQUIRE(VecAXPY(y, -1.0, yr) == 0);
      REQUIRE(VecNorm(y, NORM_INFINITY, &err) == 0);
      REQUIRE(VecNorm(yr, NORM_INFINITY, &norm) == 0);
      CHECK(err <= 1e-14 * norm);
      Mat A3;
      REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &A3) == 0);
      REQUIRE(MatScale(A3, 3.0) == 0);
      REQUIRE(MatConvert(A3, t, MAT_REUSE_MATRIX, &B) == 0);
      auto ref3 = ref;
      for (auto &v : ref3) v *= 3;
      check_dense(dense(B), ref3, 0);
      REQUIRE(MatConvert(A, t, MAT_REUSE_MATRIX, &B) == 0);
      check_dense(dense(B), ref, 0);
      for (Vec *v : {&x, &y, &yr}) VecDestroy(v);
      MatDestroy(&A3);
    }
    // and back, through the target's convertfrom
    Mat C;
    REQUIRE(MatConvert(B, MATBINBCSR, MAT_INITIAL_MATRIX, &C) == 0);
    REQUIRE(PetscObjectTypeCompare((PetscObject)C, MATSEQBINBCSR, &is) == 0);
    CHECK(is);
    CHECK(C->preallocated); // MatView refuses matrices that are not
    check_dense(dense(C), ref, 0);
    REQUIRE(MatGetBlockSize(C, &bbs) == 0);
    CHECK(bbs == bs);
    // reuse: same pattern, new values
    REQUIRE(MatScale(B, 2.0) == 0);
    REQUIRE(MatConvert(B, MATSEQBINBCSR, MAT_REUSE_MATRIX, &C) == 0);
    auto ref2 = ref;
    for (auto &v : ref2) v *= 2;
    check_dense(dense(C), ref2, 0);
    MatDestroy(&C);
    // in place
    REQUIRE(MatConvert(B, MATSEQBINBCSR, MAT_INPLACE_MATRIX, &B) == 0);
    REQUIRE(PetscObjectTypeCompare((PetscObject)B, MATSEQBINBCSR, &is) == 0);
    CHECK(is);
    check_dense(dense(B), ref2, 0);
    MatDestroy(&B);
  }
  {
    // single storage: the rounded values, converted exactly
    Mat S;
    REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &S) == 0);
    REQUIRE(MatBinBCSRSetPrecision(S, MAT_BINBCSR_PRECISION_SINGLE) == 0);
    auto rounded = ref;
    for (auto &v : rounded) v = (double)(float)v;
    for (MatType t : {MATSEQAIJ, MATSEQBAIJ}) {
      Mat B;
      CAPTURE(t);
      REQUIRE(MatConvert(S, t, MAT_INITIAL_MATRIX, &B) == 0);
      check_dense(dense(B), rounded, 0);
      MatDestroy(&B);
    }
    MatDestroy(&S);
  }
  Mat B = nullptr;
  REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &B) == 0);
  REQUIRE(MatConvert(B, MATSEQAIJ, MAT_INPLACE_MATRIX, &B) == 0);
  PetscBool is;
  REQUIRE(PetscObjectTypeCompare((PetscObject)B, MATSEQAIJ, &is) == 0);
  CHECK(is);
  check_dense(dense(B), ref, 0);
  MatDestroy(&B);
  MatDestroy(&A);
}

TEST_CASE("switching precision converts the stored values", "[mat_core][precision]")
{
  Pattern p = fem_pattern(3, 3, 3);
  for (Entry &e : p.entries) e.v *= 1.0 + 1e-9; // not representable in float
  Mat A = build(p, MATSEQBINBCSR);
  check_dense(dense(A), dense(p), 0);
  REQUIRE(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_SINGLE) == 0);
  auto single = dense(A);
  check_dense(single, dense(p), FLT_EPSILON / 2);
  for (size_t k = 0; k < single.size(); k++) CHECK(single[k] == (double)(float)dense(p)[k]);
  REQUIRE(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_DOUBLE) == 0);
  check_dense(dense(A), single, 0); // back in double: the float values, exactly
  MatDestroy(&A);
}

TEST_CASE("MatView: ASCII info and entries", "[mat_core][view]")
{
  Pattern     p      = fem_pattern(3, 2, 2);
  Mat         A      = build(p, MATSEQBINBCSR, 4, MAT_BINBCSR_PRECISION_SINGLE);
  char        name[] = "/tmp/mat_core_view_XXXXXX";
  const int   fd     = mkstemp(name);
  PetscViewer v;
  REQUIRE(fd >= 0);
  REQUIRE(PetscViewerASCIIOpen(PETSC_COMM_SELF, name, &v) == 0);
  REQUIRE(PetscViewerPushFormat(v, PETSC_VIEWER_ASCII_INFO) == 0);
  REQUIRE(MatView(A, v) == 0);
  REQUIRE(PetscViewerPopFormat(v) == 0);
  REQUIRE(MatView(A, v) == 0);
  REQUIRE(PetscViewerDestroy(&v) == 0);
  std::ifstream     in(name);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string out = ss.str();
  std::remove(name);
  CHECK(out.find("BIN-BCSR, block size 3, bin width 4, values in single precision") != std::string::npos);
  CHECK(out.find("bins 3, stored blocks") != std::string::npos);
  CHECK(out.find("padding overhead") != std::string::npos);
  CHECK(out.find("row 0: (0, 60.) ") != std::string::npos);
  CHECK(out.find("row 35:") != std::string::npos);
  MatDestroy(&A);
}
