// MATSEQBINBCSR with symmetric storage (upper triangle, colour-ordered bins): every operation against
// seqaij (and seqbaij/seqsbaij where they define the operation) on symmetric patterns.
#include "support_sym.hpp"
#include <cstdio>
#include <cstring>
#include <unistd.h>

using namespace mat_sym;

namespace {

Pattern sym_case(int which)
{
  switch (which) {
  case 0:
    return symmetrize(random_pattern(37, 37, 1, 6, 11));
  case 1:
    return symmetrize(random_pattern(29, 29, 3, 5, 12));
  case 2:
    return fem_pattern(4, 3, 5, 3);
  case 3:
    return fem_pattern(5, 4, 3, 1);
  case 4:
    return symmetrize(wild_pattern(503, 3, 500));
  case 6:
    return symmetrize(random_pattern(17, 17, 2, 4, 13)); // generic block size: the per-lane kernel
  case 7: // grids numbered along their rows: slot groups over consecutive columns (x, y without gathers)
    return fem_pattern(48, 2, 2, 3);
  case 8:
    return fem_pattern(48, 2, 1, 1);
  default:
    return end_rows_pattern(21, 3);
  }
}

Mat build_ref(const Pattern &p, MatType type)
{
  Mat A = build(p, type);
  REQUIRE(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE) == 0);
  return A;
}

double unit_of(MatBinBCSRPrecision prec)
{
  return prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON / 2 : DBL_EPSILON / 2;
}

// |a - b| <= tol * scale for two value lists
void check_rows_close(const std::vector<PetscScalar> &got, const std::vector<PetscScalar> &ref, double tol)
{
  REQUIRE(got.size() == ref.size());
  size_t bad = 0;
  for (size_t i = 0; i < got.size(); i++)
    if (!(std::fabs(got[i] - ref[i]) <= tol * (1.0 + std::fabs(ref[i])))) {
      if (bad < 5) UNSCOPED_INFO("entry " << i << ": got " << got[i] << " ref " << ref[i]);
      bad++;
    }
  CHECK(bad == 0);
}

} // namespace

TEST_CASE("symmetric storage: products against seqaij", "[mat_sym][mult]")
{
  const int                 which = GENERATE(0, 1, 2, 3, 4, 5, 6, 7, 8);
  const PetscInt            bw    = GENERATE(0, 3, 8, 16);
  const MatBinBCSRPrecision prec  = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(which, bw, prec);
  const Pattern p   = sym_case(which);
  Mat           R   = build_ref(p, MATSEQAIJ);
  Mat           A   = build_sym(p, bw, prec);
  PetscBool     sym = PETSC_FALSE;
  REQUIRE(MatBinBCSRGetSymmetricStorage(A, &sym) == 0);
  CHECK(sym);
  check_colouring(A);
  check_dense(dense(A), dense(p), unit_of(prec));
  if (which >= 7 && bw != 3) { // the grids take the contiguous path in most slot groups
    const std::string info = info_view(A);
    const size_t      at =
      info.find("slot groups over consecutive block columns (x and y read without gathers): ");
    REQUIRE(at != std::string::npos);
    long unit = -1, groups = -1;
    REQUIRE(
      std::sscanf(info.c_str() + at,
                  "slot groups over consecutive block columns (x and y read without gathers): %ld of %ld",
                  &unit, &groups) == 2);
    CHECK(unit >= groups / 4);
  }

  Vec x = make_vec(p.n, 1), z = make_vec(p.m, 2), y, yr;
  REQUIRE(VecDuplicate(z, &y) == 0);
  REQUIRE(VecDuplicate(z, &yr) == 0);
  const auto          xv = values(x), zv = values(z);
  auto                bound = mult_bound(p, xv, unit_of(prec), false);
  std::vector<double> bound_add(bound);
  for (size_t i = 0; i < bound_add.size(); i++) bound_add[i] += 2 * DBL_EPSILON * std::fabs(zv[i]);

  REQUIRE(MatMult(R, x, yr) == 0);
  REQUIRE(MatMult(A, x, y) == 0);
  check_close(values(y), values(yr), bound);
  REQUIRE(MatMultTranspose(A, x, y) == 0);
  check_close(values(y), values(yr), bound);

  PetscScalar dot = 0, dotref = 0;
  REQUIRE(MatMultDotLocal(A, x, y, &dot) == 0);
  check_close(values(y), values(yr), bound);
  REQUIRE(VecDot(yr, x, &dotref) == 0);
  {
    double dbound = 0;
    for (size_t i = 0; i < xv.size(); i++)
      dbound += std::fabs(xv[i]) * (bound[i] + std::fabs(values(yr)[i]) * 4 * DBL_EPSILON * xv.size());
    CHECK(std::fabs(dot - dotref) <= dbound + 1e-300);
  }

  REQUIRE(MatMultAdd(R, x, z, yr) == 0);
  REQUIRE(MatMultAdd(A, x, z, y) == 0);
  check_close(values(y), values(yr), bound_add);
  REQUIRE(MatMultTransposeAdd(A, x, z, y) == 0);
  check_close(values(y), values(yr), bound_add);
  REQUIRE(VecCopy(z, y) == 0);
  REQUIRE(MatMultAdd(A, x, y, y) == 0); // z aliases y
  check_close(values(y), values(yr), bound_add);

  VecDestroy(&x);
  VecDestroy(&z);
  VecDestroy(&y);
  VecDestroy(&yr);
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("symmetric storage: the colouring is conflict-free and adds no padding on the stencil",
          "[mat_sym][colouring]")
{
  const PetscInt bw = GENERATE(4, 8, 16);
  CAPTURE(bw);
  const Pattern         p = fem_pattern(9, 8, 7, 3);
  Mat                   A = build_sym(p, bw, MAT_BINBCSR_PRECISION_DOUBLE);
  const Mat_SeqBinBCSR *a = (const Mat_SeqBinBCSR *)A->data;
  check_colouring(A);
  size_t extra = 0;
  for (PetscInt b = 0; b < a->nbins; b++) {
    PetscInt longest = 0;
    for (PetscInt r = b * bw; r < PetscMin(a->mbs, (b + 1) * bw); r++)
      longest = PetscMax(longest, a->row_nz[r]);
    extra += (size_t)((a->bin_start[b + 1] - a->bin_start[b]) / bw -
                      longest); // slot groups beyond the longest upper row
  }
  CHECK(extra == 0);
  // stored blocks: the upper triangle of the 27-point stencil
  PetscInt upper = 0;
  for (const Entry &e : p.entries)
    if (e.j / 3 >= e.i / 3 && e.i % 3 == 0 && e.j % 3 == 0) upper++;
  CHECK(a->nz == upper);
  MatDestroy(&A);

  // the end rows: one column in every lane of the last bin, lanes of 2 or 3 blocks: the bin needs
  // one slot group per lane that holds that column, and still no conflict
  Mat E = build_sym(end_rows_pattern(21, 3), 8, MAT_BINBCSR_PRECISION_DOUBLE);
  check_colouring(E);
  const Mat_SeqBinBCSR *e = (const Mat_SeqBinBCSR *)E->data;
  // rows 16..19 hold column 20 off the diagonal, their upper rows have at most 3 blocks: 4 groups
  CHECK((e->bin_start[e->nbins] - e->bin_start[e->nbins - 1]) / 8 == 4);
  CHECK(e->max_row_nz == 3);
  MatDestroy(&E);
}

TEST_CASE("symmetric storage: value operations against seqaij", "[mat_sym][ops]")
{
  const int                 which = GENERATE(0, 1, 2, 5, 6);
  const MatBinBCSRPrecision prec  = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(which, prec);
  const Pattern p        = sym_case(which);
  const bool    all_diag = which == 2 || which == 5; // the random patterns lack some diagonal blocks
  const double  tol      = 8 * unit_of(prec) * 64;
  Mat           R        = build_ref(p, MATSEQAIJ);
  Mat           A        = build_sym(p, 3, prec);

  SECTION("diagonal and block diagonal inverse")
  {
    Mat B = build_ref(p, MATSEQBAIJ);
    Vec d, dr;
    REQUIRE(MatCreateVecs(A, &d, nullptr) == 0);
    REQUIRE(VecDuplicate(d, &dr) == 0);
    REQUIRE(MatGetDiagonal(A, d) == 0);
    REQUIRE(MatGetDiagonal(R, dr) == 0);
    check_rows_close(values(d), values(dr), tol);
    if (all_diag) {
      const PetscScalar *ia, *ib;
      REQUIRE(MatInvertBlockDiagonal(A, &ia) == 0);
      REQUIRE(MatInvertBlockDiagonal(B, &ib) == 0);
      std::vector<PetscScalar> va(ia, ia + p.m * p.bs), vb(ib, ib + p.m * p.bs);
      check_rows_close(va, vb, 1e3 * tol);
    }
    VecDestroy(&d);
    VecDestroy(&dr);
    MatDestroy(&B);
  }
  SECTION("rows, values, norms, info")
  {
    for (PetscInt i = 0; i < p.m; i++) {
      PetscInt           na, nr;
      const PetscInt    *ca, *cr;
      const PetscScalar *va, *vr;
      REQUIRE(MatGetRow(A, i, &na, &ca, &va) == 0);
      std::vector<PetscInt>    cav(ca, ca + na);
      std::vector<PetscScalar> vav(va, va + na);
      REQUIRE(MatRestoreRow(A, i, &na, &ca, &va) == 0);
      REQUIRE(MatGetRow(R, i, &nr, &cr, &vr) == 0);
      std::vector<PetscInt>    crv(cr, cr + nr);
      std::vector<PetscScalar> vrv(vr, vr + nr);
      REQUIRE(MatRestoreRow(R, i, &nr, &cr, &vr) == 0);
      REQUIRE(cav == crv);
      check_rows_close(vav, vrv, tol);
    }
    for (NormType t : {NORM_FROBENIUS, NORM_1, NORM_INFINITY}) {
      PetscReal na, nr;
      REQUIRE(MatNorm(A, t, &na) == 0);
      REQUIRE(MatNorm(R, t, &nr) == 0);
      CHECK(std::fabs(na - nr) <= tol * nr);
    }
    MatInfo info;
    REQUIRE(MatGetInfo(A, MAT_LOCAL, &info) == 0);
    PetscInt upper = 0;
    for (const Entry &e : p.entries)
      if (e.j / p.bs >= e.i / p.bs) upper++;
    CHECK(info.nz_used == (double)upper);
  }
  SECTION("scale, shift, diagonal set, AXPY, duplicate, copy, transpose")
  {
    Vec D;
    REQUIRE(MatCreateVecs(A, &D, nullptr) == 0);
    REQUIRE(VecSet(D, 0.25) == 0);
    for (Mat M : {A, R}) {
      REQUIRE(MatScale(M, 2.5) == 0);
      if (all_diag) {
        REQUIRE(MatShift(M, 1.5) == 0);
        REQUIRE(MatDiagonalSet(M, D, ADD_VALUES) == 0);
      }
    }
    check_dense(dense(A), dense(R), tol);
    Mat A2, R2;
    REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &A2) == 0);
    check_dense(dense(A2), dense(R), tol);
    REQUIRE(MatAXPY(A, -0.5, A2, SAME_NONZERO_PATTERN) == 0); // same layout: slot by slot
    REQUIRE(MatDuplicate(R, MAT_COPY_VALUES, &R2) == 0);
    REQUIRE(MatAXPY(R, -0.5, R2, SAME_NONZERO_PATTERN) == 0);
    check_dense(dense(A), dense(R), tol);
    REQUIRE(MatAXPY(A, 2.0, R2, DIFFERENT_NONZERO_PATTERN) == 0); // seqaij X: through its rows
    REQUIRE(MatAXPY(R, 2.0, R2, SAME_NONZERO_PATTERN) == 0);
    check_dense(dense(A), dense(R), tol);
    REQUIRE(MatZeroEntries(A2) == 0);
    REQUIRE(MatCopy(A, A2, SAME_NONZERO_PATTERN) == 0);
    check_dense(dense(A2), dense(R), tol);
    Mat T;
    REQUIRE(MatTranspose(A, MAT_INITIAL_MATRIX, &T) == 0);
    check_dense(dense(T), dense(R), tol);
    MatDestroy(&T);
    MatDestroy(&A2);
    MatDestroy(&R2);
    VecDestroy(&D);
  }
  SECTION("MatSetValues after the layout: the lower triangle given is ignored")
  {
    for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, ADD_VALUES) == 0);
    REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
    REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
    REQUIRE(MatScale(R, 2.0) == 0);
    check_dense(dense(A), dense(R), tol);
  }
  SECTION("zero rows and columns with x and b; zero rows alone is refused")
  {
    std::vector<PetscInt> rows;
    for (PetscInt i = 0; i < p.m; i += 4) rows.push_back(i);
    Vec x = make_vec(p.m, 5), b = make_vec(p.m, 6), br;
    REQUIRE(VecDuplicate(b, &br) == 0);
    REQUIRE(VecCopy(b, br) == 0);
    const PetscScalar diag = all_diag ? 3.0 : 0.0;
    REQUIRE(MatZeroRowsColumns(A, (PetscInt)rows.size(), rows.data(), diag, x, b) == 0);
    REQUIRE(MatZeroRowsColumns(R, (PetscInt)rows.size(), rows.data(), diag, x, br) == 0);
    check_dense(dense(A), dense(R), tol);
    check_rows_close(values(b), values(br), tol);
    CHECK(MatZeroRows(A, 1, rows.data(), 1.0, nullptr, nullptr) == PETSC_ERR_SUP);
    VecDestroy(&x);
    VecDestroy(&b);
    VecDestroy(&br);
  }
  SECTION("conversions to and from seqaij, seqbaij, seqsbaij")
  {
    for (MatType t : {MATSEQAIJ, MATSEQBAIJ}) {
      Mat C;
      REQUIRE(MatConvert(A, t, MAT_INITIAL_MATRIX, &C) == 0);
      check_dense(dense(C), dense(R), tol);
      MatDestroy(&C);
    }
    REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_symmetric_storage", "1") == 0);
    for (MatType t : {MATSEQAIJ, MATSEQBAIJ, MATSEQSBAIJ}) {
      if (!all_diag && !std::strcmp(t, MATSEQSBAIJ)) continue; // sbaij needs every diagonal block
      Mat S, C;
      REQUIRE(MatConvert(R, t, MAT_INITIAL_MATRIX, &S) == 0);
      REQUIRE(MatConvert(S, MATSEQBINBCSR, MAT_INITIAL_MATRIX, &C) == 0);
      PetscBool sym;
      REQUIRE(MatBinBCSRGetSymmetricStorage(C, &sym) == 0);
      CHECK(sym);
      check_dense(dense(C), dense(R), 0.0);
      MatDestroy(&C);
      MatDestroy(&S);
    }
    REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_symmetric_storage") == 0);
    PetscBool sym = PETSC_TRUE;
    REQUIRE(MatBinBCSRGetSymmetricStorage(R, &sym) == 0); // another type: false, no error
    CHECK(!sym);
  }
  SECTION("views: ASCII info and a binary file that seqaij loads")
  {
    PetscViewer v;
    CHECK(info_view(A).find("symmetric storage: upper triangle") != std::string::npos);

    char name[] = "/tmp/mat_sym_XXXXXX";
    int  fd     = mkstemp(name);
    REQUIRE(fd >= 0);
    close(fd);
    REQUIRE(PetscViewerBinaryOpen(PETSC_COMM_SELF, name, FILE_MODE_WRITE, &v) == 0);
    REQUIRE(MatView(A, v) == 0);
    REQUIRE(PetscViewerDestroy(&v) == 0);
    Mat L;
    REQUIRE(MatCreate(PETSC_COMM_SELF, &L) == 0);
    REQUIRE(MatSetType(L, MATSEQAIJ) == 0);
    REQUIRE(PetscViewerBinaryOpen(PETSC_COMM_SELF, name, FILE_MODE_READ, &v) == 0);
    REQUIRE(MatLoad(L, v) == 0);
    REQUIRE(PetscViewerDestroy(&v) == 0);
    check_dense(dense(L), dense(R), tol);
    MatDestroy(&L);
    // and back into binbcsr with symmetric storage
    Mat L2;
    REQUIRE(MatCreate(PETSC_COMM_SELF, &L2) == 0);
    REQUIRE(MatSetBlockSize(L2, p.bs) == 0);
    REQUIRE(MatSetType(L2, MATSEQBINBCSR) == 0);
    REQUIRE(MatBinBCSRSetSymmetricStorage(L2, PETSC_TRUE) == 0);
    REQUIRE(PetscViewerBinaryOpen(PETSC_COMM_SELF, name, FILE_MODE_READ, &v) == 0);
    REQUIRE(MatLoad(L2, v) == 0);
    REQUIRE(PetscViewerDestroy(&v) == 0);
    check_dense(dense(L2), dense(R), tol);
    MatDestroy(&L2);
    std::remove(name);
    std::string info = std::string(name) + ".info";
    std::remove(info.c_str());
  }
  MatDestroy(&A);
  MatDestroy(&R);
}

// Two symmetric layouts can hold as many slots (the same bin width, the same longest upper row per bin)
// with other patterns, so other counts of stored blocks. MatEqual and MatAXPY compare layouts before
// going slot by slot, and that comparison read the slot map of one over the other's block count, past
// its end (found by AddressSanitizer on 2 ranks). The answers must be seqaij's either way.
TEST_CASE("symmetric storage: equal slot counts, different patterns", "[mat_sym][ops]")
{
  // 16 rows of bs 1, bin width 8: row 0 holds columns 0..9, rows 1..14 their diagonal (of the upper
  // triangle); `wide`: rows 1..7 also the next 9 columns; `last_diagonal`: row 15 its diagonal
  auto pattern = [](bool wide, bool last_diagonal) {
    Pattern p;
    p.m = p.n = 16;
    p.bs      = 1;
    for (PetscInt r = 0; r < 16; r++)
      for (PetscInt c = r; c < 16; c++) {
        const bool keep =
          (c == r && (r < 15 || last_diagonal)) || (r == 0 && c <= 9) || (wide && r < 8 && c <= r + 9);
        if (!keep) continue;
        const PetscScalar v = c == r ? 20.0 + r : -0.5 - 0.01 * (r + 2 * c);
        p.entries.push_back({r, c, v});
        if (c != r) p.entries.push_back({c, r, v});
      }
    return p;
  };
  // W holds N's blocks and more, in as many slots (8 x 10 + 8 x 1): 87 blocks against 24 (the slot
  // maps differ early), and 25 against 24 (N's slot map is the first 24 entries of W's, so even a
  // comparison that stops at the first difference, as valgrind's memcmp does, reads past N's)
  const bool wide = GENERATE(true, false);
  CAPTURE(wide);
  const Pattern pw = pattern(wide, true), pn = pattern(false, false);
  Mat W = build_sym(pw, 8, MAT_BINBCSR_PRECISION_DOUBLE), N = build_sym(pn, 8, MAT_BINBCSR_PRECISION_DOUBLE);
  Mat RW = build_ref(pw, MATSEQAIJ), RN = build_ref(pn, MATSEQAIJ);
  {
    const Mat_SeqBinBCSR *w = (const Mat_SeqBinBCSR *)W->data, *n = (const Mat_SeqBinBCSR *)N->data;
    REQUIRE(w->nslots == n->nslots); // the case this test is about
    REQUIRE(w->nz == (wide ? 87 : 25));
    REQUIRE(n->nz == 24);
    if (!wide) CHECK(std::equal(n->real_slot, n->real_slot + n->nz, w->real_slot));
  }
  PetscBool eq;
  REQUIRE(MatEqual(W, N, &eq) == 0);
  CHECK(!eq);
  REQUIRE(MatEqual(N, W, &eq) == 0);
  CHECK(!eq);
  Mat W2, RW2;
  REQUIRE(MatDuplicate(W, MAT_COPY_VALUES, &W2) == 0);
  REQUIRE(MatEqual(W2, W, &eq) == 0);
  CHECK(eq);
  // W2 += -0.5 N (a subset) and N += 2 W (a superset): as seqaij
  REQUIRE(MatDuplicate(RW, MAT_COPY_VALUES, &RW2) == 0);
  REQUIRE(MatAXPY(W2, -0.5, N, SUBSET_NONZERO_PATTERN) == 0);
  REQUIRE(MatAXPY(RW2, -0.5, RN, SUBSET_NONZERO_PATTERN) == 0);
  check_dense(dense(W2), dense(RW2), 4 * DBL_EPSILON);
  REQUIRE(MatAXPY(N, 2.0, W, DIFFERENT_NONZERO_PATTERN) == 0);
  REQUIRE(MatAXPY(RN, 2.0, RW, DIFFERENT_NONZERO_PATTERN) == 0);
  check_dense(dense(N), dense(RN), 4 * DBL_EPSILON);
  MatDestroy(&W2);
  MatDestroy(&RW2);
  MatDestroy(&W);
  MatDestroy(&N);
  MatDestroy(&RW);
  MatDestroy(&RN);
}

TEST_CASE("symmetric storage: COO with both triangles and duplicates", "[mat_sym][coo]")
{
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  const Pattern             p    = fem_pattern(4, 4, 3, 3);
  std::vector<PetscInt>     ci, cj;
  std::vector<PetscScalar>  cv;
  for (const Entry &e : p.entries) { // every entry twice (halves), plus dropped negative entries
    for (int t = 0; t < 2; t++) {
      ci.push_back(e.i);
      cj.push_back(e.j);
      cv.push_back(e.v / 2);
    }
  }
  ci.push_back(-1);
  cj.push_back(0);
  cv.push_back(1e9);
  Mat A, R;
  for (Mat *M : {&A, &R}) {
    REQUIRE(MatCreate(PETSC_COMM_SELF, M) == 0);
    REQUIRE(MatSetSizes(*M, p.m, p.m, p.m, p.m) == 0);
    REQUIRE(MatSetBlockSize(*M, 3) == 0);
    REQUIRE(MatSetType(*M, M == &A ? MATSEQBINBCSR : MATSEQAIJ) == 0);
    REQUIRE(MatBinBCSRSetPrecision(*M, prec) == 0);
    REQUIRE(MatBinBCSRSetSymmetricStorage(*M, PETSC_TRUE) == 0);
    REQUIRE(MatSetPreallocationCOO(*M, (PetscCount)ci.size(), ci.data(), cj.data()) == 0);
    REQUIRE(MatSetValuesCOO(*M, cv.data(), INSERT_VALUES) == 0);
  }
  check_colouring(A);
  const double tol = 4 * unit_of(prec);
  check_dense(dense(A), dense(R), tol);
  REQUIRE(MatSetValuesCOO(A, cv.data(), ADD_VALUES) == 0);
  REQUIRE(MatSetValuesCOO(R, cv.data(), ADD_VALUES) == 0);
  check_dense(dense(A), dense(R), tol);
  CHECK(MatBinBCSRSetSymmetricStorage(A, PETSC_FALSE) == PETSC_ERR_ARG_WRONGSTATE); // frozen
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("symmetric storage: CG and MCG take as many iterations as with seqaij", "[mat_sym][ksp]")
{
  const Pattern p = fem_pattern(7, 6, 5, 3);
  Mat           R = build_ref(p, MATSEQAIJ), A = build_sym(p, 0, MAT_BINBCSR_PRECISION_DOUBLE);
  Vec           b = make_vec(p.m, 9), xr, xa;
  REQUIRE(VecDuplicate(b, &xr) == 0);
  REQUIRE(VecDuplicate(b, &xa) == 0);
  for (KSPType kt : {KSPCG, KSPMCG}) {
    PetscInt its[2];
    int      k = 0;
    for (Mat M : {R, A}) {
      KSP ksp;
      PC  pc;
      REQUIRE(KSPCreate(PETSC_COMM_SELF, &ksp) == 0);
      REQUIRE(KSPSetOperators(ksp, M, M) == 0);
      REQUIRE(KSPSetType(ksp, kt) == 0);
      REQUIRE(KSPGetPC(ksp, &pc) == 0);
      REQUIRE(PCSetType(pc, PCJACOBI) == 0);
      REQUIRE(KSPSetTolerances(ksp, 1e-10, 1e-50, PETSC_DEFAULT, 1000) == 0);
      REQUIRE(KSPSolve(ksp, b, M == R ? xr : xa) == 0);
      KSPConvergedReason reason;
      REQUIRE(KSPGetConvergedReason(ksp, &reason) == 0);
      CHECK(reason > 0);
      REQUIRE(KSPGetIterationNumber(ksp, &its[k++]) == 0);
      KSPDestroy(&ksp);
    }
    CAPTURE(kt);
    CHECK(its[0] == its[1]);
    check_rows_close(values(xa), values(xr), 1e-8);
  }
  VecDestroy(&b);
  VecDestroy(&xr);
  VecDestroy(&xa);
  MatDestroy(&R);
  MatDestroy(&A);
}

TEST_CASE("symmetric storage: bad input", "[mat_sym][errors]")
{
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, 6, 9, 6, 9) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  CHECK(MatBinBCSRSetSymmetricStorage(A, PETSC_TRUE) == PETSC_ERR_ARG_SIZ); // not square
  MatDestroy(&A);
  Mat B = build_sym(fem_pattern(3, 3, 2, 3), 0, MAT_BINBCSR_PRECISION_DOUBLE, false);
  CHECK(MatBinBCSRSetSymmetricStorage(B, PETSC_TRUE) == PETSC_ERR_ARG_WRONGSTATE); // after the layout
  MatDestroy(&B);
}
