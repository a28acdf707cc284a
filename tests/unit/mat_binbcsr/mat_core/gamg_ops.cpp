// What PCGAMG asks of a MATSEQBINBCSR operator beyond products with vectors, made from the blocks:
// MatCreateGraph (its strength graph) against PETSc's own graph of the same values in a SeqAIJ matrix,
// entry for entry, and MatPtAP (its coarse operators) against PETSc's AIJ product, also reused.
#include "support/mat_support.hpp"
#include "petsc_compat.h" // MatCreateGraph's arguments
#include <random>

using namespace mat_core;

namespace {
// A binbcsr (whole or upper-triangle storage) from the pattern's COO list.
Mat build_coo(const Pattern &p, PetscInt bw, MatBinBCSRPrecision prec, PetscBool sym)
{
  std::vector<PetscInt>    ci, cj;
  std::vector<PetscScalar> cv;
  for (const Entry &e : p.entries) ci.push_back(e.i), cj.push_back(e.j), cv.push_back(e.v);
  Mat A = create_unfilled(p, MATSEQBINBCSR, bw, prec, sym);
  REQUIRE(MatSetPreallocationCOO(A, (PetscCount)ci.size(), ci.data(), cj.data()) == 0);
  REQUIRE(MatSetValuesCOO(A, cv.data(), INSERT_VALUES) == 0);
  return A;
}
} // namespace

TEST_CASE("MatCreateGraph from the blocks equals PETSc's graph of the AIJ copy", "[mat_core][graph]")
{
  const PetscInt            bs   = GENERATE(2, 3);
  const PetscInt            bw   = GENERATE(8, 3);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  // 0: whole storage, unsymmetric with empty rows; 1: whole storage, flagged symmetric (MatCreateGraph
  // then skips the symmetrisation); 2: upper-triangle storage (symmetric by construction)
  const int kind = GENERATE(0, 1, 2);
  CAPTURE(bs, bw, prec, kind);
  const PetscBool sym = kind == 2 ? PETSC_TRUE : PETSC_FALSE;
  const Pattern   p   = kind ? fem_pattern(5, 4, 3, bs) : random_pattern(37, 37, bs, 6, 11);
  Mat             A   = build_coo(p, bw, prec, sym), S;
  if (kind == 1) REQUIRE(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE) == 0);
  // the values A holds (single: rounded), in an AIJ matrix of A's block size: PETSc's reference graph
  REQUIRE(MatConvert(A, MATSEQAIJ, MAT_INITIAL_MATRIX, &S) == 0);
  REQUIRE(MatSetBlockSize(S, bs) == 0);
  struct {
    PetscBool symmetrize, scale;
    PetscReal filter;
  } const cases[] = {{PETSC_TRUE, PETSC_TRUE, -1},
                     {PETSC_TRUE, PETSC_TRUE, 0.05},
                     {PETSC_FALSE, PETSC_FALSE, -1},
                     {PETSC_FALSE, PETSC_TRUE, 0.0},
                     {PETSC_TRUE, PETSC_FALSE, 0.1}};
  for (const auto &c : cases) {
    CAPTURE(c.symmetrize, c.scale, c.filter);
    Mat G, Gref;
    REQUIRE(MatCreateGraph(A, c.symmetrize, c.scale, c.filter BINBCSR_CREATEGRAPH_NO_INDEX, &G) == 0);
    REQUIRE(MatCreateGraph(S, c.symmetrize, c.scale, c.filter BINBCSR_CREATEGRAPH_NO_INDEX, &Gref) == 0);
    PetscInt m, n, mref, nref;
    REQUIRE(MatGetSize(G, &m, &n) == 0);
    REQUIRE(MatGetSize(Gref, &mref, &nref) == 0);
    CHECK(m == mref);
    CHECK(n == nref);
    CHECK(m == p.m / bs);
    MatInfo info, inforef;
    REQUIRE(MatGetInfo(G, MAT_LOCAL, &info) == 0);
    REQUIRE(MatGetInfo(Gref, MAT_LOCAL, &inforef) == 0);
    CHECK(info.nz_used == inforef.nz_used);
    CHECK(info.nz_used > 0);
    PetscBool eq;
    REQUIRE(MatEqual(G, Gref, &eq) == 0); // values exactly, pattern included
    CHECK(eq);
    MatDestroy(&G);
    MatDestroy(&Gref);
  }
  MatDestroy(&S);
  MatDestroy(&A);
}

namespace {
// |X - Y|_F / |Y|_F of two AIJ matrices of equal sizes (any patterns)
double rel_diff(Mat X, Mat Y)
{
  Mat       D;
  PetscReal d, y;
  REQUIRE(MatDuplicate(X, MAT_COPY_VALUES, &D) == 0);
  REQUIRE(MatAXPY(D, -1.0, Y, DIFFERENT_NONZERO_PATTERN) == 0);
  REQUIRE(MatNorm(D, NORM_FROBENIUS, &d) == 0);
  REQUIRE(MatNorm(Y, NORM_FROBENIUS, &y) == 0);
  MatDestroy(&D);
  return y > 0 ? d / y : d;
}
} // namespace

TEST_CASE("MatPtAP of binbcsr and an AIJ P equals PETSc's AIJ product, also reused after new values",
          "[mat_core][ptap]")
{
  const PetscInt            bs   = GENERATE(1, 2, 3);
  const PetscInt            bw   = GENERATE(8, 3);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  const PetscBool           sym  = GENERATE(PETSC_FALSE, PETSC_TRUE);
  CAPTURE(bs, bw, prec, sym);
  // B + B^T: symmetric (symmetric storage needs it) with unsymmetric blocks, so that a lower block read
  // untransposed would show; empty block rows included
  const PetscInt mbs = 41;
  Pattern        p   = random_pattern(mbs, mbs, bs, 5, 7);
  { // COO sums the duplicates. Appended one by one: GCC 14 warns (-Wstringop-overflow, falsely) on
    // inserting a range at the end
    const size_t n = p.entries.size();
    p.entries.reserve(2 * n);
    for (size_t k = 0; k < n; ++k) {
      const Entry e = p.entries[k];
      p.entries.push_back({e.j, e.i, e.v});
    }
  }
  Mat A = build_coo(p, bw, prec, sym), R, P, C, CR;
  REQUIRE(MatConvert(A, MATSEQAIJ, MAT_INITIAL_MATRIX, &R) == 0); // the values A holds
  // P: a tentative prolongator's shape, two entries per row into 11 coarse columns, one empty row
  const PetscInt nc = 11;
  REQUIRE(MatCreateSeqAIJ(PETSC_COMM_SELF, mbs * bs, nc, 2, nullptr, &P) == 0);
  std::mt19937 rng(3);
  for (PetscInt i = 0; i < mbs * bs; i++) {
    if (i == 5) continue;
    const PetscInt    cols[2] = {(i / bs) % nc, (PetscInt)(rng() % nc)};
    const PetscScalar vals[2] = {1.0 + 0.1 * (i % 3), 0.25 - 0.01 * (PetscScalar)(rng() % 50)};
    REQUIRE(MatSetValues(P, 1, &i, cols[0] == cols[1] ? 1 : 2, cols, vals, ADD_VALUES) == 0);
  }
  REQUIRE(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatPtAP(A, P, MAT_INITIAL_MATRIX, 2.0, &C) == 0);
  REQUIRE(MatPtAP(R, P, MAT_INITIAL_MATRIX, 2.0, &CR) == 0);
  PetscBool aij;
  REQUIRE(PetscObjectTypeCompare((PetscObject)C, MATSEQAIJ, &aij) == 0);
  CHECK(aij);
  CHECK(rel_diff(C, CR) < 1e-14);
  // new values of A (a refill through its COO maps), then of P: the reused product follows both
  {
    std::vector<PetscScalar> cv;
    for (size_t k = 0; k < p.entries.size(); k++) cv.push_back(std::cos(0.3 * (double)k));
    REQUIRE(MatSetValuesCOO(A, cv.data(), INSERT_VALUES) == 0);
    REQUIRE(MatConvert(A, MATSEQAIJ, MAT_REUSE_MATRIX, &R) == 0);
  }
  REQUIRE(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &C) == 0);
  REQUIRE(MatPtAP(R, P, MAT_REUSE_MATRIX, 2.0, &CR) == 0);
  CHECK(rel_diff(C, CR) < 1e-14);
  REQUIRE(MatScale(P, 0.5) == 0);
  REQUIRE(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &C) == 0);
  REQUIRE(MatPtAP(R, P, MAT_REUSE_MATRIX, 2.0, &CR) == 0);
  CHECK(rel_diff(C, CR) < 1e-14);
  // the product the user calls (MatProductNumeric) as well, and a P with another pattern is an error
  REQUIRE(MatProductNumeric(C) == 0);
  CHECK(rel_diff(C, CR) < 1e-14);
  {
    const PetscInt    i = 5, c = 3;
    const PetscScalar v = 1;
    REQUIRE(MatSetOption(P, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE) == 0);
    REQUIRE(MatSetValues(P, 1, &i, 1, &c, &v, INSERT_VALUES) == 0); // row 5 was empty: a new nonzero
    REQUIRE(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY) == 0);
    REQUIRE(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY) == 0);
    REQUIRE(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr) == 0);
    CHECK(MatPtAP(A, P, MAT_REUSE_MATRIX, 2.0, &C) == PETSC_ERR_ARG_INCOMP);
    REQUIRE(PetscPopErrorHandler() == 0);
  }
  MatDestroy(&C);
  MatDestroy(&CR);
  MatDestroy(&P);
  MatDestroy(&R);
  MatDestroy(&A);
}
