// Filling a MATSEQBINBCSR: MatSetValues(Blocked) with INSERT/ADD before and after the layout exists,
// the preallocation entry points stock programs use, the COO interface, options, and bad input.
#include "support/mat_support.hpp"
#include <map>

using namespace mat_core;

namespace {

Mat create(PetscInt m, PetscInt n, PetscInt bs, PetscInt bw = 0)
{
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, m, n, m, n) == 0);
  if (bs > 1) REQUIRE(MatSetBlockSize(A, bs) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  if (bw) REQUIRE(MatBinBCSRSetBinWidth(A, bw) == 0);
  return A;
}

void assemble(Mat A)
{
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
}

} // namespace

TEST_CASE("MatSetValues INSERT and ADD, staged and after the layout is frozen", "[mat_core][setvalues]")
{
  const PetscInt            bs   = GENERATE(1, 3);
  const PetscInt            bw   = GENERATE(3, 8);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  const double rel = prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON : 4 * DBL_EPSILON;
  Pattern      p   = random_pattern(19, 19, bs, 5, 7);
  Mat          A   = build(p, MATSEQBINBCSR, bw, prec);
  check_dense(dense(A), dense(p), rel / 2);

  // ADD twice the same values to every entry (staged INSERT put them there once): 3x
  for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, ADD_VALUES) == 0);
  for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, ADD_VALUES) == 0);
  assemble(A);
  Pattern p3 = p;
  for (Entry &e : p3.entries) e.v *= 3;
  check_dense(dense(A), dense(p3), 2 * rel);

  // INSERT after assembly overwrites; a second assembly keeps the layout (same nonzero state)
  PetscObjectState nzstate0, nzstate1;
  REQUIRE(MatGetNonzeroState(A, &nzstate0) == 0);
  for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, -e.v, INSERT_VALUES) == 0);
  assemble(A);
  REQUIRE(MatGetNonzeroState(A, &nzstate1) == 0);
  CHECK(nzstate0 == nzstate1);
  Pattern pm = p;
  for (Entry &e : pm.entries) e.v = -e.v;
  check_dense(dense(A), dense(pm), rel / 2);
  MatDestroy(&A);
}

TEST_CASE("staged ADD sums duplicates; negative indices are ignored; NULL values insert zeros",
          "[mat_core][setvalues]")
{
  Mat               A       = create(6, 6, 1, 4);
  const PetscInt    rows[3] = {0, -1, 5}, cols[3] = {-3, 2, 5};
  const PetscScalar v[9] = {100, 1, 2, 200, 300, 400, 500, 3, 4};
  REQUIRE(MatSetUp(A) == 0);
  REQUIRE(MatSetValues(A, 3, rows, 3, cols, v, ADD_VALUES) == 0);
  REQUIRE(MatSetValues(A, 3, rows, 3, cols, v, ADD_VALUES) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FLUSH_ASSEMBLY) == 0); // PETSc: no INSERT/ADD mix without one
  REQUIRE(MatAssemblyEnd(A, MAT_FLUSH_ASSEMBLY) == 0);
  const PetscInt r1 = 1, c1 = 1;
  REQUIRE(MatSetValues(A, 1, &r1, 1, &c1, nullptr, INSERT_VALUES) == 0);
  assemble(A);
  auto d = dense(A);
  CHECK(d[0 * 6 + 2] == 2.0);
  CHECK(d[0 * 6 + 5] == 4.0);
  CHECK(d[5 * 6 + 2] == 6.0);
  CHECK(d[5 * 6 + 5] == 8.0);
  CHECK(d[1 * 6 + 1] == 0.0);
  MatInfo info;
  REQUIRE(MatGetInfo(A, MAT_LOCAL, &info) == 0);
  CHECK(info.nz_used == 5.0); // the explicit zero at (1,1) is stored
  MatDestroy(&A);
}

TEST_CASE("MatSetValuesBlocked, row- and column-oriented, against seqbaij", "[mat_core][setvalues]")
{
  const PetscInt  bs          = GENERATE(1, 2, 3);
  const PetscBool roworiented = GENERATE(PETSC_TRUE, PETSC_FALSE);
  CAPTURE(bs, roworiented);
  const PetscInt mbs = 11;
  Mat            A   = create(mbs * bs, mbs * bs, bs, 4), B;
  REQUIRE(MatCreateSeqBAIJ(PETSC_COMM_SELF, bs, mbs * bs, mbs * bs, 4, nullptr, &B) == 0);
  REQUIRE(MatSetUp(A) == 0);
  for (Mat M : {A, B}) REQUIRE(MatSetOption(M, MAT_ROW_ORIENTED, roworiented) == 0);
  for (int pass = 0; pass < 2; pass++) { // pass 0 staged (INSERT then ADD), pass 1 frozen (ADD)
    for (PetscInt r = 0; r < mbs; r++) {
      const PetscInt           br[2] = {r, (r * 5 + 1) % mbs}, bc[2] = {(r * 3) % mbs, r};
      std::vector<PetscScalar> v(4 * bs * bs);
      for (size_t k = 0; k < v.size(); k++) v[k] = 1.0 + r + 0.25 * k + pass;
      for (Mat M : {A, B})
        REQUIRE(MatSetValuesBlocked(M, 2, br, 2, bc, v.data(),
                                    (pass == 0 && r % 2 == 0) ? INSERT_VALUES : ADD_VALUES) == 0);
      for (Mat M : {A, B}) {
        REQUIRE(MatAssemblyBegin(M, MAT_FLUSH_ASSEMBLY) == 0);
        REQUIRE(MatAssemblyEnd(M, MAT_FLUSH_ASSEMBLY) == 0);
      }
    }
    assemble(A);
    assemble(B);
    check_dense(dense(A), dense(B), 4 * DBL_EPSILON);
  }
  MatDestroy(&A);
  MatDestroy(&B);
}

TEST_CASE("the preallocation calls of stock programs give a working matrix", "[mat_core][prealloc]")
{
  const Pattern p   = fem_pattern(3, 3, 2);
  const auto    ref = dense(p);
  SECTION("MatXAIJSetPreallocation")
  {
    Mat                   A = create(p.m, p.n, 3);
    std::vector<PetscInt> dnnz(p.m / 3, 27);
    REQUIRE(MatXAIJSetPreallocation(A, 3, dnnz.data(), nullptr, nullptr, nullptr) == 0);
    for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
    assemble(A);
    check_dense(dense(A), ref, 0);
    MatDestroy(&A);
  }
  SECTION("MatSeqAIJSetPreallocation with a type from the options database")
  {
    Mat A;
    REQUIRE(PetscOptionsSetValue(nullptr, "-mat_type", "binbcsr") == 0);
    REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_bin_width", "5") == 0);
    REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
    REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
    REQUIRE(MatSetBlockSize(A, 3) == 0);
    REQUIRE(MatSetFromOptions(A) == 0);
    REQUIRE(PetscOptionsClearValue(nullptr, "-mat_type") == 0);
    REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_bin_width") == 0);
    PetscBool is;
    REQUIRE(PetscObjectTypeCompare((PetscObject)A, MATSEQBINBCSR, &is) == 0);
    CHECK(is);
    PetscInt bw;
    REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
    CHECK(bw == 5);
    REQUIRE(MatSeqAIJSetPreallocation(A, 81, nullptr) == 0);
    for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
    assemble(A);
    check_dense(dense(A), ref, 0);
    MatDestroy(&A);
  }
  SECTION("MatXAIJSetPreallocation, blocks set twice (INSERT then ADD), scalars in between")
  {
    // the staging finds a block once per MatSetValuesBlocked block; scalars go one by one
    Mat                   A = create(p.m, p.n, 3);
    std::vector<PetscInt> dnnz(p.m / 3, 27);
    REQUIRE(MatXAIJSetPreallocation(A, 3, dnnz.data(), nullptr, nullptr, nullptr) == 0);
    std::vector<PetscScalar> ref2(ref.size());
    for (size_t k = 0; k < ref.size(); k++) ref2[k] = 2 * ref[k];
    for (const Entry &e : p.entries) { // the block of each entry, whole, with the entry's value in place
      const PetscInt br = e.i / 3, bc = e.j / 3;
      PetscScalar    blk[9];
      for (PetscInt ii = 0; ii < 3; ii++)
        for (PetscInt jj = 0; jj < 3; jj++)
          blk[3 * ii + jj] = ref[(size_t)((3 * br + ii) * p.n + 3 * bc + jj)];
      REQUIRE(MatSetValuesBlocked(A, 1, &br, 1, &bc, blk, INSERT_VALUES) == 0);
    }
    REQUIRE(MatAssemblyBegin(A, MAT_FLUSH_ASSEMBLY) == 0); // INSERT and ADD are not mixed without one
    REQUIRE(MatAssemblyEnd(A, MAT_FLUSH_ASSEMBLY) == 0);
    for (const Entry &e : p.entries)
      REQUIRE(MatSetValue(A, e.i, e.j, 0.5 * ref[(size_t)(e.i * p.n + e.j)], ADD_VALUES) == 0);
    for (const Entry &e : p.entries)
      REQUIRE(MatSetValue(A, e.i, e.j, 0.5 * ref[(size_t)(e.i * p.n + e.j)], ADD_VALUES) == 0);
    assemble(A);
    check_dense(dense(A), ref2, 4 * DBL_EPSILON);
    MatDestroy(&A);
  }
  SECTION(
    "MatSeqAIJSetPreallocation bounds a block row by its largest point row, and rows grow past what they reserved")
  {
    // 3 scalars per point row: at most 3 blocks per block row (each could hold one of them); the
    // staging reserves one full block and grows to three
    Mat A = create(12, 12, 3);
    REQUIRE(MatSeqAIJSetPreallocation(A, 3, nullptr) == 0);
    REQUIRE(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE) == 0);
    for (PetscInt bc = 0; bc < 3; bc++) {
      const PetscInt br = 0;
      PetscScalar    blk[9];
      for (int k = 0; k < 9; k++) blk[k] = 1 + k + 10 * bc;
      REQUIRE(MatSetValuesBlocked(A, 1, &br, 1, &bc, blk, INSERT_VALUES) == 0);
    }
    CHECK(MatSetValue(A, 0, 9, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE); // a fourth block
    assemble(A);
    PetscScalar    v;
    const PetscInt r = 2, c = 7; // block (0, 2), entry (2, 1)
    REQUIRE(MatGetValues(A, 1, &r, 1, &c, &v) == 0);
    CHECK(v == 1 + 7 + 20);
    MatDestroy(&A);
  }
  SECTION("new blocks ignored (MAT_NEW_NONZERO_LOCATIONS false) before the first assembly")
  {
    Mat A = create(9, 9, 3);
    REQUIRE(MatSeqBAIJSetPreallocation(A, 3, 2, nullptr) == 0);
    const PetscInt br = 1, bc0 = 1, bc1 = 2;
    PetscScalar    blk[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    REQUIRE(MatSetValuesBlocked(A, 1, &br, 1, &bc0, blk, INSERT_VALUES) == 0);
    REQUIRE(MatSetOption(A, MAT_NEW_NONZERO_LOCATIONS, PETSC_FALSE) == 0);
    REQUIRE(MatSetValuesBlocked(A, 1, &br, 1, &bc1, blk, INSERT_VALUES) == 0); // ignored
    REQUIRE(MatAssemblyBegin(A, MAT_FLUSH_ASSEMBLY) == 0);
    REQUIRE(MatAssemblyEnd(A, MAT_FLUSH_ASSEMBLY) == 0);
    REQUIRE(MatSetValuesBlocked(A, 1, &br, 1, &bc0, blk, ADD_VALUES) == 0); // an existing block
    assemble(A);
    MatInfo info;
    REQUIRE(MatGetInfo(A, MAT_LOCAL, &info) == 0);
    CHECK(info.nz_used == 9);
    PetscScalar    v;
    const PetscInt r = 5, c = 4; // block (1, 1), entry (2, 1)
    REQUIRE(MatGetValues(A, 1, &r, 1, &c, &v) == 0);
    CHECK(v == 16);
    MatDestroy(&A);
  }
  SECTION("a negative preallocation is refused, the matrix still usable")
  {
    Mat                   A   = create(9, 9, 3);
    std::vector<PetscInt> bad = {1, -2, 1};
    CHECK(MatSeqBAIJSetPreallocation(A, 3, 0, bad.data()) == PETSC_ERR_ARG_OUTOFRANGE);
    REQUIRE(MatSeqBAIJSetPreallocation(A, 3, 1, nullptr) == 0);
    REQUIRE(MatSetValue(A, 4, 4, 2.0, INSERT_VALUES) == 0);
    assemble(A);
    PetscScalar    v;
    const PetscInt r = 4;
    REQUIRE(MatGetValues(A, 1, &r, 1, &r, &v) == 0);
    CHECK(v == 2.0);
    MatDestroy(&A);
  }
  SECTION("MatSeqBAIJSetPreallocation, then MAT_NEW_NONZERO_ALLOCATION_ERR beyond it")
  {
    Mat A = create(9, 9, 3);
    REQUIRE(MatSeqBAIJSetPreallocation(A, 3, 1, nullptr) == 0);
    REQUIRE(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE) == 0);
    REQUIRE(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
    REQUIRE(MatSetValue(A, 0, 1, 1.0, INSERT_VALUES) == 0); // same block
    CHECK(MatSetValue(A, 0, 3, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    MatDestroy(&A);
  }
  SECTION("no preallocation at all: MatSetUp, or nothing")
  {
    Mat A = create(p.m, p.n, 3), B = create(6, 6, 3);
    REQUIRE(MatSetUp(A) == 0);
    for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, ADD_VALUES) == 0);
    assemble(A);
    check_dense(dense(A), ref, 0);
    assemble(B); // no entries: an empty, usable matrix
    Vec x, y;
    REQUIRE(MatCreateVecs(B, &x, &y) == 0);
    REQUIRE(VecSet(x, 1.0) == 0);
    REQUIRE(MatMult(B, x, y) == 0);
    PetscReal nrm;
    REQUIRE(VecNorm(y, NORM_INFINITY, &nrm) == 0);
    CHECK(nrm == 0.0);
    VecDestroy(&x);
    VecDestroy(&y);
    MatDestroy(&A);
    MatDestroy(&B);
  }
}

TEST_CASE("COO: duplicates summed, negative indices dropped, INSERT and ADD refills", "[mat_core][coo]")
{
  const PetscInt            bs   = GENERATE(1, 3);
  const PetscInt            bw   = GENERATE(4, 8, 7);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  const PetscInt        m = 29 * bs, n = 29 * bs;
  std::mt19937          rng(42 + bs);
  std::vector<PetscInt> ci, cj;
  for (PetscInt k = 0; k < 900; k++) { // many duplicates: few distinct positions
    PetscInt i = (PetscInt)(rng() % m), j = (PetscInt)((i + (rng() % 13) * bs + rng() % bs) % n);
    if (k % 37 == 5) i = -1;
    if (k % 41 == 7) j = -2;
    ci.push_back(i);
    cj.push_back(j);
  }
  for (PetscInt r = 0; r < m; r += 7) { // diagonal entries, also summed with the above
    ci.push_back(r);
    cj.push_back(r);
  }
  const PetscCount ncoo = (PetscCount)ci.size();
  Mat              A    = create(m, n, bs, bw), ref;
  REQUIRE(MatBinBCSRSetPrecision(A, prec) == 0);
  REQUIRE(MatCreateSeqAIJ(PETSC_COMM_SELF, m, n, 0, nullptr, &ref) == 0);
  // PETSc may permute the index arrays: give each matrix its own copy
  {
    std::vector<PetscInt> i1 = ci, j1 = cj, i2 = ci, j2 = cj;
    REQUIRE(MatSetPreallocationCOO(A, ncoo, i1.data(), j1.data()) == 0);
    REQUIRE(MatSetPreallocationCOO(ref, ncoo, i2.data(), j2.data()) == 0);
  }
  std::vector<PetscScalar> v(ncoo);
  const double             unit = prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON : 4 * DBL_EPSILON;
  for (int round = 0; round < 3; round++) {
    for (PetscCount k = 0; k < ncoo; k++) v[k] = std::sin(1.0 + k + 10 * round);
    const InsertMode mode = round == 1 ? ADD_VALUES : INSERT_VALUES;
    REQUIRE(MatSetValuesCOO(A, v.data(), mode) == 0);
    REQUIRE(MatSetValuesCOO(ref, v.data(), mode) == 0);
    // bound: sums of |v| rounded once to float (plus the stored old value for ADD)
    auto   got = dense(A), want = dense(ref);
    size_t bad = 0;
    for (size_t k = 0; k < got.size(); k++)
      if (!(std::fabs(got[k] - want[k]) <=
            unit * (std::fabs(want[k]) + 16.0 * (mode == ADD_VALUES)) * 1.0 + 1e-13))
        bad++;
    CHECK(bad == 0);
  }
  // a matrix filled by COO multiplies like the reference, and a duplicate refills too (the two share
  // their COO maps: each keeps refilling after the other took a new pattern or was destroyed)
  Mat D, D2;
  REQUIRE(MatDuplicate(A, MAT_DO_NOT_COPY_VALUES, &D) == 0);
  REQUIRE(MatSetValuesCOO(D, v.data(), INSERT_VALUES) == 0);
  check_dense(dense(D), dense(A), 0);
  REQUIRE(MatDuplicate(D, MAT_COPY_VALUES, &D2) == 0);
  {
    std::vector<PetscInt> i1 = {0, 1}, j1 = {0, 1}; // A takes another pattern: D's maps stay
    REQUIRE(MatSetPreallocationCOO(A, 2, i1.data(), j1.data()) == 0);
    const PetscScalar two[2] = {5, 7};
    REQUIRE(MatSetValuesCOO(A, two, INSERT_VALUES) == 0);
    PetscScalar a00;
    PetscInt    zero = 0;
    REQUIRE(MatGetValues(A, 1, &zero, 1, &zero, &a00) == 0);
    CHECK(a00 == 5);
  }
  MatDestroy(&A);
  for (PetscCount k = 0; k < ncoo; k++) v[k] = std::cos(2.0 + k);
  REQUIRE(MatSetValuesCOO(ref, v.data(), INSERT_VALUES) == 0);
  const auto refills_like_ref = [&](Mat M) {
    REQUIRE(MatSetValuesCOO(M, v.data(), INSERT_VALUES) == 0);
    auto   got = dense(M), want = dense(ref);
    size_t bad = 0;
    for (size_t k = 0; k < got.size(); k++)
      if (!(std::fabs(got[k] - want[k]) <= unit * std::fabs(want[k]) * 16.0 + 1e-13)) bad++;
    CHECK(bad == 0);
  };
  refills_like_ref(D);
  MatDestroy(&D);
  refills_like_ref(D2); // the last holder of the maps
  MatDestroy(&D2);
  MatDestroy(&ref);
}

TEST_CASE("options and the public setters", "[mat_core][options]")
{
  Mat                 A = create(12, 12, 3);
  PetscInt            bw;
  MatBinBCSRPrecision p;
  REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
  CHECK(bw == 8); // the default for blocks (measured, docs/mat_binbcsr.md)
  {
    Mat S = create(12, 12, 1);
    REQUIRE(MatBinBCSRGetBinWidth(S, &bw) == 0);
    CHECK(bw == 16); // the default for scalars
    REQUIRE(MatSetUp(S) == 0);
    assemble(S);
    REQUIRE(MatBinBCSRGetBinWidth(S, &bw) == 0);
    CHECK(bw == 16);
    MatDestroy(&S);
  }
  REQUIRE(MatBinBCSRGetPrecision(A, &p) == 0);
  CHECK(p == MAT_BINBCSR_PRECISION_DOUBLE);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_precision", "single") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_bin_width", "16") == 0);
  REQUIRE(MatSetFromOptions(A) == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_precision") == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_bin_width") == 0);
  REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
  CHECK(bw == 16);
  REQUIRE(MatBinBCSRGetPrecision(A, &p) == 0);
  CHECK(p == MAT_BINBCSR_PRECISION_SINGLE);
  CHECK(MatBinBCSRSetBinWidth(A, 0) == PETSC_ERR_ARG_OUTOFRANGE);
  REQUIRE(MatSetUp(A) == 0);
  REQUIRE(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
  assemble(A);
  CHECK(MatBinBCSRSetBinWidth(A, 4) == PETSC_ERR_ARG_WRONGSTATE); // the layout exists
  CHECK(MatBinBCSRSetBinWidth(A, 16) == 0);                       // unchanged: fine
  MatDestroy(&A);
}

TEST_CASE("bad input gives PETSc errors", "[mat_core][errors]")
{
  SECTION("indices out of range")
  {
    Mat A = create(6, 6, 3);
    REQUIRE(MatSetUp(A) == 0);
    CHECK(MatSetValue(A, 6, 0, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    CHECK(MatSetValue(A, 0, 6, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    const PetscInt    br = 2, bc = 0;
    const PetscScalar v[9] = {0};
    CHECK(MatSetValuesBlocked(A, 1, &br, 1, &bc, v, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    REQUIRE(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
    assemble(A);
    CHECK(MatSetValue(A, 0, 7, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    MatDestroy(&A);
  }
  SECTION("a new nonzero after the pattern is frozen, unless new locations are switched off")
  {
    Mat A = create(6, 6, 1, 4);
    REQUIRE(MatSetUp(A) == 0);
    REQUIRE(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
    assemble(A);
    CHECK(MatSetValue(A, 1, 3, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    assemble(A);
    REQUIRE(MatSetOption(A, MAT_NEW_NONZERO_LOCATIONS, PETSC_FALSE) == 0);
    CHECK(MatSetValue(A, 1, 3, 1.0, ADD_VALUES) == 0);
    CHECK(MatSetValue(A, 0, 0, 5.0, ADD_VALUES) == 0);
    assemble(A);
    auto d = dense(A);
    CHECK(d[1 * 6 + 3] == 0.0);
    CHECK(d[0] == 6.0);
    MatDestroy(&A);
  }
  SECTION("MAT_NEW_NONZERO_LOCATION_ERR while staging")
  {
    Mat A = create(4, 4, 1);
    REQUIRE(MatSetUp(A) == 0);
    REQUIRE(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
    REQUIRE(MatSetOption(A, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE) == 0);
    CHECK(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
    CHECK(MatSetValue(A, 2, 1, 1.0, INSERT_VALUES) == PETSC_ERR_ARG_OUTOFRANGE);
    MatDestroy(&A);
  }
  SECTION("block size mismatch")
  {
    Mat A, B;
    REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
    REQUIRE(MatSetSizes(A, 9, 6, 9, 6) == 0);
    REQUIRE(MatSetBlockSizes(A, 3, 2) == 0);
    REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
    CHECK(MatSetUp(A) == PETSC_ERR_ARG_INCOMP); // row and column block sizes differ
    MatDestroy(&A);
    A = create(9, 9, 3);
    CHECK(MatSeqBAIJSetPreallocation(A, 2, 1, nullptr) != 0); // 9 rows do not split in 2x2 blocks
    MatDestroy(&A);
    // MatCopy between different block sizes
    A = create(6, 6, 3);
    B = create(6, 6, 2);
    REQUIRE(MatSetUp(A) == 0);
    REQUIRE(MatSetUp(B) == 0);
    REQUIRE(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES) == 0);
    REQUIRE(MatSetValue(B, 0, 0, 1.0, INSERT_VALUES) == 0);
    assemble(A);
    assemble(B);
    CHECK(MatCopy(A, B, SAME_NONZERO_PATTERN) == PETSC_ERR_ARG_INCOMP);
    MatDestroy(&A);
    MatDestroy(&B);
  }
  SECTION("wrong vector sizes")
  {
    Mat A = build(random_pattern(5, 5, 3, 2, 1), MATSEQBINBCSR);
    Vec x, y, bad;
    REQUIRE(MatCreateVecs(A, &x, &y) == 0);
    REQUIRE(VecCreateSeq(PETSC_COMM_SELF, 14, &bad) == 0);
    CHECK(MatMult(A, bad, y) == PETSC_ERR_ARG_SIZ);
    CHECK(MatMult(A, x, bad) == PETSC_ERR_ARG_SIZ);
    CHECK(MatMultTranspose(A, bad, y) == PETSC_ERR_ARG_SIZ);
    CHECK(MatMultAdd(A, x, bad, y) == PETSC_ERR_ARG_SIZ);
    PetscScalar dot;
    CHECK(MatMultDotLocal(A, bad, y, &dot) == PETSC_ERR_ARG_SIZ);
    CHECK(MatMultDotLocal(A, x, bad, &dot) == PETSC_ERR_ARG_SIZ);
    CHECK(MatGetDiagonal(A, bad) == PETSC_ERR_ARG_SIZ);
    VecDestroy(&x);
    VecDestroy(&y);
    VecDestroy(&bad);
    MatDestroy(&A);
  }
  SECTION("COO misuse")
  {
    Mat      A    = create(6, 6, 3);
    PetscInt i[2] = {0, 6}, j[2] = {0, 0};
    CHECK(MatSetPreallocationCOO(A, 2, i, j) == PETSC_ERR_ARG_OUTOFRANGE);
    MatDestroy(&A);
    A                = create(6, 6, 3);
    PetscScalar v[2] = {1, 2};
    REQUIRE(MatSetUp(A) == 0);
    CHECK(MatSetValuesCOO(A, v, INSERT_VALUES) == PETSC_ERR_ARG_WRONGSTATE);
    MatDestroy(&A);
  }
  SECTION("products of an unassembled matrix")
  {
    Mat A = create(6, 6, 3);
    Vec x, y;
    REQUIRE(MatSetUp(A) == 0);
    REQUIRE(MatCreateVecs(A, &x, &y) == 0);
    CHECK(MatMult(A, x, y) == PETSC_ERR_ARG_WRONGSTATE);
    VecDestroy(&x);
    VecDestroy(&y);
    MatDestroy(&A);
  }
}

TEST_CASE("the info view reports the COO refill path and the mirror", "[mat_core][coo][view]")
{
  const PetscInt        mbs = 10, bs = 3, m = mbs * bs;
  std::vector<PetscInt> bi, bj, si, sj; // whole 3x3 blocks (block row r: blocks r and r + 1), and scalars
  for (PetscInt r = 0; r < mbs; r++)
    for (PetscInt c : {r, (r + 1) % mbs})
      for (PetscInt e = 0; e < 9; e++) {
        bi.push_back(r * bs + e / 3);
        bj.push_back(c * bs + e % 3);
      }
  for (PetscInt r = 0; r < m; r++) {
    si.push_back(r);
    sj.push_back(r);
  }
  // the info view of a matrix preallocated with (i, j) and filled once, the mirror on or off (the
  // lists by value: PETSc may permute the arrays it is given)
  auto view_after_refill = [&](std::vector<PetscInt> i, std::vector<PetscInt> j, PetscBool mirror) {
    Mat A = create(m, m, bs, 8);
    REQUIRE(MatBinBCSRSetCOOMirror(A, mirror) == 0);
    REQUIRE(MatSetPreallocationCOO(A, (PetscCount)i.size(), i.data(), j.data()) == 0);
    std::vector<PetscScalar> v(i.size(), 1.0);
    REQUIRE(MatSetValuesCOO(A, v.data(), INSERT_VALUES) == 0);
    const std::string info = info_view(A);
    MatDestroy(&A);
    return info;
  };
  CHECK(view_after_refill(bi, bj, PETSC_FALSE).find("COO: 180 entries, refill by whole blocks\n") !=
        std::string::npos);
  CHECK(view_after_refill(si, sj, PETSC_FALSE)
          .find("COO: 30 entries, refill value by value (the list is not made of whole blocks)") !=
        std::string::npos);
  CHECK(view_after_refill(bi, bj, PETSC_TRUE).find("COO: 180 entries, refill by whole blocks; mirror on") !=
        std::string::npos);
}
