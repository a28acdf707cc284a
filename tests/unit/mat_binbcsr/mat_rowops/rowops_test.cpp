// Row, column and whole-matrix operations of -mat_type binbcsr (seqbinbcsr on one rank, mpibinbcsr on
// more; the CTest cases run this program on 1, 2 and 3 ranks) against aij holding the same entries:
// MatDiagonalScale, MatGetRowMaxAbs/Max/Min, MatGetColumnNorms and the column sums/means,
// MatMissingDiagonal, MatEqual, MatGetValues, MatAXPY (same, subset, different patterns), MatTranspose.
// Single precision is compared against aij holding the float-rounded entries, so selections (row
// extremes, their columns) must agree exactly and computed values within a few float roundings of the
// row (or column) scale.
#include "rowops_support.hpp"

#include <algorithm>

using namespace rowops;

namespace {

constexpr double kRoundings = 4.0;

// |got_i - want_i| <= tol * scale_i for all i (collective)
bool vec_close(Vec got, Vec want, const std::vector<double> &scale, double tol)
{
  const PetscScalar *g, *w;
  PetscInt           n;
  int                ok = 1, all;
  REQUIRE(VecGetLocalSize(want, &n) == 0);
  REQUIRE(VecGetArrayRead(got, &g) == 0);
  REQUIRE(VecGetArrayRead(want, &w) == 0);
  for (PetscInt i = 0; i < n; i++)
    if (!(std::fabs(g[i] - w[i]) <= tol * scale[i])) {
      UNSCOPED_INFO("entry " << i << ": got " << g[i] << " want " << w[i]);
      ok = 0;
    }
  REQUIRE(VecRestoreArrayRead(got, &g) == 0);
  REQUIRE(VecRestoreArrayRead(want, &w) == 0);
  REQUIRE(MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD) == 0);
  return all == 1;
}

// sum_j |a_ij| of this rank's rows (1 for a row of zeros)
std::vector<double> row_scales(Mat A)
{
  PetscInt rstart, rend;
  REQUIRE(MatGetOwnershipRange(A, &rstart, &rend) == 0);
  std::vector<double> s;
  for (PetscInt i = rstart; i < rend; i++) {
    PetscInt           n;
    const PetscScalar *v;
    double             sum = 0;
    REQUIRE(MatGetRow(A, i, &n, nullptr, &v) == 0);
    for (PetscInt k = 0; k < n; k++) sum += std::fabs(v[k]);
    REQUIRE(MatRestoreRow(A, i, &n, nullptr, &v) == 0);
    s.push_back(sum > 0 ? sum : 1.0);
  }
  return s;
}

bool all_ranks(bool local)
{
  int l = local ? 1 : 0, a;
  REQUIRE(MPI_Allreduce(&l, &a, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD) == 0);
  return a == 1;
}

PetscMPIInt comm_size()
{
  PetscMPIInt size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  return size;
}

} // namespace

TEST_CASE("MatDiagonalScale matches aij; symmetric storage takes only D A D", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      const double tol = kRoundings * c.eps();
      Vec          l, r, d;
      {
        Pair p(c);
        PETSC_OK(make_vec(p.aij, true, 1, &l));
        PETSC_OK(make_vec(p.aij, false, 2, &r));
        PETSC_OK(make_vec(p.aij, false, 3, &d));
        // D A D with one vector on both sides
        PETSC_OK(MatDiagonalScale(p.bin, d, d));
        PETSC_OK(MatDiagonalScale(p.aij, d, d));
        CHECK(row_error(p.bin, p.aij) <= tol);
        if (c.sym) {
          // a different left and right scaling, or one side only, cannot stay symmetric: refused, unchanged
          PETSC_FAILS_WITH(MatDiagonalScale(p.bin, l, r), PETSC_ERR_SUP);
          PETSC_FAILS_WITH(MatDiagonalScale(p.bin, l, nullptr), PETSC_ERR_SUP);
          PETSC_FAILS_WITH(MatDiagonalScale(p.bin, nullptr, r), PETSC_ERR_SUP);
          CHECK(row_error(p.bin, p.aij) <= tol);
          // two vectors with the same entries are the same scaling
          Vec d2;
          PETSC_OK(VecDuplicate(d, &d2));
          PETSC_OK(VecCopy(d, d2));
          PETSC_OK(MatDiagonalScale(p.bin, d, d2));
          PETSC_OK(MatDiagonalScale(p.aij, d, d2));
          CHECK(row_error(p.bin, p.aij) <= 2 * tol);
          PETSC_OK(VecDestroy(&d2));
        } else {
          PETSC_OK(MatDiagonalScale(p.bin, l, r));
          PETSC_OK(MatDiagonalScale(p.aij, l, r));
          CHECK(row_error(p.bin, p.aij) <= 2 * tol);
          PETSC_OK(MatDiagonalScale(p.bin, nullptr, r));
          PETSC_OK(MatDiagonalScale(p.aij, nullptr, r));
          PETSC_OK(MatDiagonalScale(p.bin, l, nullptr));
          PETSC_OK(MatDiagonalScale(p.aij, l, nullptr));
          CHECK(row_error(p.bin, p.aij) <= 3 * tol);
        }
        // wrong local sizes
        Vec      big;
        PetscInt n;
        PETSC_OK(VecGetLocalSize(d, &n));
        PETSC_OK(VecCreateMPI(PETSC_COMM_WORLD, n + 1, PETSC_DETERMINE, &big));
        PETSC_FAILS_WITH(MatDiagonalScale(p.bin, big, nullptr), PETSC_ERR_ARG_SIZ);
        if (!c.sym) PETSC_FAILS_WITH(MatDiagonalScale(p.bin, nullptr, big), PETSC_ERR_ARG_SIZ);
        PETSC_OK(VecDestroy(&big));
      }
      PETSC_OK(VecDestroy(&l));
      PETSC_OK(VecDestroy(&r));
      PETSC_OK(VecDestroy(&d));
    }
  }
}

TEST_CASE("MatGetRowMaxAbs, MatGetRowMax, MatGetRowMin, MatGetRowMinAbs match aij, columns included",
          "[rowops]")
{
  typedef PetscErrorCode (*RowOp)(Mat, Vec, PetscInt[]);
  const std::pair<const char *, RowOp> ops[] = {{"MatGetRowMaxAbs", MatGetRowMaxAbs},
                                                {"MatGetRowMax", MatGetRowMax},
                                                {"MatGetRowMin", MatGetRowMin},
                                                {"MatGetRowMinAbs", MatGetRowMinAbs}};
  std::vector<Config>                  cases = configs();
  for (Config c : configs()) { // and matrices whose rows reach their extremes in several columns
    c.ties = true;
    cases.push_back(c);
  }
  for (const Config &c : cases) {
    SECTION(c.name() + (c.ties ? " ties" : ""))
    {
      Pair                      p(c);
      const std::vector<double> scale = row_scales(p.aij);
      for (const auto &op : ops) {
        INFO(op.first);
        Vec      vb, va;
        PetscInt m;
        PETSC_OK(MatCreateVecs(p.aij, nullptr, &va));
        PETSC_OK(VecDuplicate(va, &vb));
        PETSC_OK(VecGetLocalSize(va, &m));
        std::vector<PetscInt> ib(m, -7), ia(m, -7);
        PETSC_OK(op.second(p.bin, vb, ib.data()));
        PETSC_OK(op.second(p.aij, va, ia.data()));
        CHECK(vec_close(vb, va, scale, 0.0)); // a selection: the stored values themselves
        CHECK(all_ranks(ib == ia));
        PETSC_OK(op.second(p.bin, vb, nullptr)); // idx is optional
        CHECK(vec_close(vb, va, scale, 0.0));
        Vec big;
        PETSC_OK(VecCreateMPI(PETSC_COMM_WORLD, m + 1, PETSC_DETERMINE, &big));
        PETSC_FAILS_WITH(op.second(p.bin, big, nullptr), PETSC_ERR_ARG_SIZ);
        PETSC_OK(VecDestroy(&big));
        PETSC_OK(VecDestroy(&va));
        PETSC_OK(VecDestroy(&vb));
      }
    }
  }
}

TEST_CASE("MatGetColumnNorms and the column sums and means match aij", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair                   p(c);
      const PetscInt         N = c.mbs() * c.bs;
      std::vector<PetscReal> col_abs(N), got(N), want(N);
      PETSC_OK(MatGetColumnNorms(p.aij, NORM_1, col_abs.data()));
      for (PetscReal &s : col_abs) s = s > 0 ? s : 1.0;
      auto close = [&](double tol) {
        bool ok = true;
        for (PetscInt j = 0; j < N; j++)
          if (!(std::fabs(got[j] - want[j]) <= tol * col_abs[j])) {
            UNSCOPED_INFO("column " << j << ": got " << got[j] << " want " << want[j]);
            ok = false;
          }
        return all_ranks(ok);
      };
      const double tol = kRoundings * c.eps();
      for (NormType t : {NORM_1, NORM_2, NORM_INFINITY}) {
        INFO(NormTypes[t]);
        PETSC_OK(MatGetColumnNorms(p.bin, t, got.data()));
        PETSC_OK(MatGetColumnNorms(p.aij, t, want.data()));
        CHECK(close(t == NORM_INFINITY ? 0.0 : tol));
      }
      PETSC_OK(MatGetColumnSumsRealPart(p.bin, got.data()));
      PETSC_OK(MatGetColumnSumsRealPart(p.aij, want.data()));
      CHECK(close(tol));
      PETSC_OK(MatGetColumnMeansRealPart(p.bin, got.data()));
      PETSC_OK(MatGetColumnMeansRealPart(p.aij, want.data()));
      for (PetscInt j = 0; j < N; j++) col_abs[j] /= N;
      CHECK(close(tol));
      PETSC_OK(MatGetColumnSumsImaginaryPart(p.bin, got.data()));
      CHECK(std::all_of(got.begin(), got.end(), [](PetscReal x) { return x == 0; }));
    }
  }
}

TEST_CASE("MatMissingDiagonal matches aij on every rank", "[rowops]")
{
  for (bool holes : {true, false})
    for (PetscInt bs : {1, 3})
      for (bool sym : {false, true}) {
        Config c;
        c.bs    = bs;
        c.sym   = sym;
        c.holes = holes;
        SECTION(c.name())
        {
          Pair      p(c);
          PetscBool mb, ma;
          PetscInt  db = -1, da = -1;
          PETSC_OK(MatMissingDiagonal(p.bin, &mb, &db));
          PETSC_OK(MatMissingDiagonal(p.aij, &ma, &da));
          CHECK(all_ranks(mb == ma));
          if (ma) CHECK(db == da);
          if (!holes) CHECK(!mb);
          if (holes && comm_size() == 1) CHECK((mb && db == 5 * bs)); // block row 5 is the first empty one
        }
      }
}

TEST_CASE("MatFindZeroDiagonals matches aij (missing and stored zero diagonals)", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair p(c);
      // a stored zero on the diagonal of the first row of block 2 (a present block)
      const PetscInt i = 2 * c.bs;
      PetscInt       rstart, rend;
      PETSC_OK(MatGetOwnershipRange(p.aij, &rstart, &rend));
      for (Mat M : {p.bin, p.aij}) {
        const PetscScalar zero = 0.0;
        if (i >= rstart && i < rend) PETSC_OK(MatSetValues(M, 1, &i, 1, &i, &zero, INSERT_VALUES));
        PETSC_OK(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY));
        PETSC_OK(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY));
      }
      IS        zb, za;
      PetscBool eq;
      PetscInt  n;
      PETSC_OK(MatFindZeroDiagonals(p.bin, &zb));
      PETSC_OK(MatFindZeroDiagonals(p.aij, &za));
      PETSC_OK(ISEqualUnsorted(zb, za, &eq));
      CHECK(eq);
      PETSC_OK(ISGetSize(zb, &n));
      CHECK(n >= 1 + (c.holes ? 3 * c.bs : 0)); // the stored zero, and the empty block rows 5, 12, 19
      PETSC_OK(ISDestroy(&zb));
      PETSC_OK(ISDestroy(&za));
    }
  }
}

TEST_CASE("MatEqual: values and pattern, across bin widths and precisions", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Mat       A, B, D;
      PetscBool eq;
      PETSC_OK(make(c, MATBINBCSR, &A));
      PETSC_OK(MatDuplicate(A, MAT_COPY_VALUES, &D));
      PETSC_OK(MatEqual(A, D, &eq));
      CHECK(eq);
      Config other = c; // another bin width: the same matrix in other bins
      other.bw     = c.bw ? 0 : 3;
      PETSC_OK(make(other, MATBINBCSR, &B));
      PETSC_OK(MatEqual(A, B, &eq));
      CHECK(eq);
      PETSC_OK(MatDestroy(&B));
      { // another precision: equal where the values are (float-representable entries)
        Config dc = c, sc = c;
        dc.float_values = sc.float_values = true;
        dc.prec                           = MAT_BINBCSR_PRECISION_DOUBLE;
        sc.prec                           = MAT_BINBCSR_PRECISION_SINGLE;
        Mat Ad, As;
        PETSC_OK(make(dc, MATBINBCSR, &Ad));
        PETSC_OK(make(sc, MATBINBCSR, &As));
        PETSC_OK(MatEqual(Ad, As, &eq));
        CHECK(eq);
        if (
          c.prec ==
          MAT_BINBCSR_PRECISION_DOUBLE) { /* and a double matrix whose entries are not float-representable is not */
          PETSC_OK(MatEqual(A, As, &eq));
          CHECK(!eq);
        }
        PETSC_OK(MatDestroy(&Ad));
        PETSC_OK(MatDestroy(&As));
      }
      // one entry changed on the last rank only
      PetscInt    rstart, rend;
      PetscMPIInt rank;
      MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
      PETSC_OK(MatGetOwnershipRange(D, &rstart, &rend));
      if (rank == comm_size() - 1) {
        const PetscInt i = rend - 1, j = rend - 1; // the last block row is not a hole (22 % 7, 42 % 7 != 5)
        const PetscScalar v = 1.5;
        PETSC_OK(MatSetValues(D, 1, &i, 1, &j, &v, ADD_VALUES));
      }
      PETSC_OK(MatAssemblyBegin(D, MAT_FINAL_ASSEMBLY));
      PETSC_OK(MatAssemblyEnd(D, MAT_FINAL_ASSEMBLY));
      PETSC_OK(MatEqual(A, D, &eq));
      CHECK(!eq);
      other    = c; // the same change in other bins (compared row by row)
      other.bw = c.bw ? 0 : 3;
      PETSC_OK(make(other, MATBINBCSR, &B));
      PETSC_OK(MatEqual(B, D, &eq));
      CHECK(!eq);
      PETSC_OK(MatDestroy(&B));
      // a different pattern with the same values where both have entries
      Config sub = c;
      sub.drop   = true;
      PETSC_OK(make(sub, MATBINBCSR, &B));
      PETSC_OK(MatEqual(A, B, &eq));
      CHECK(!eq);
      PETSC_OK(MatDestroy(&B));
      PETSC_OK(MatDestroy(&D));
      PETSC_OK(MatDestroy(&A));
    }
  }
}

TEST_CASE("MatGetValues: local rows, columns anywhere, as aij", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair           p(c);
      const PetscInt N = c.mbs() * c.bs;
      PetscInt       rstart, rend;
      PETSC_OK(MatGetOwnershipRange(p.aij, &rstart, &rend));
      std::vector<PetscInt> rows, cols(N);
      for (PetscInt i = rstart; i < rend; i++) rows.push_back(i);
      for (PetscInt j = 0; j < N; j++) cols[j] = N - 1 - j; // any order
      cols.push_back(-1);                                   // negative indices are skipped
      const PetscInt           m = (PetscInt)rows.size(), n = (PetscInt)cols.size();
      std::vector<PetscScalar> vb(m * n, -99.0), va(m * n, -99.0);
      PETSC_OK(MatGetValues(p.bin, m, rows.data(), n, cols.data(), vb.data()));
      PETSC_OK(MatGetValues(p.aij, m, rows.data(), n, cols.data(), va.data()));
      CHECK(all_ranks(vb == va));
      const PetscInt bad = N;
      PETSC_FAILS_WITH(MatGetValues(p.bin, 1, rows.data(), 1, &bad, vb.data()), PETSC_ERR_ARG_OUTOFRANGE);
      if (comm_size() > 1) {
        const PetscInt other = rend < N ? rend : 0;
        PETSC_FAILS_WITH(MatGetValues(p.bin, 1, &other, 1, cols.data(), vb.data()), PETSC_ERR_SUP);
      }
    }
  }
}

TEST_CASE("MatAXPY with the same, a subset and a different pattern keeps the type and its options",
          "[rowops]")
{
  for (const Config &c : configs()) {
    for (MatStructure str : {SAME_NONZERO_PATTERN, SUBSET_NONZERO_PATTERN, DIFFERENT_NONZERO_PATTERN}) {
      SECTION(c.name() + " " + MatStructures[str])
      {
        Config xc     = c;
        xc.value_seed = 2;
        xc.drop       = str != SAME_NONZERO_PATTERN;
        xc.extra      = str == DIFFERENT_NONZERO_PATTERN;
        Pair              y(c), x(xc);
        const PetscScalar a =
          1.25; // positive: the rows of one sign do not cancel (the tolerance follows the result row)
        PetscObjectState nz0;
        PETSC_OK(MatGetNonzeroState(y.bin, &nz0));
        PETSC_OK(MatAXPY(y.bin, a, x.bin, str));
        PETSC_OK(MatAXPY(y.aij, a, x.aij, str));
        CHECK(row_error(y.bin, y.aij) <= 2 * kRoundings * c.eps());
        PetscObjectState nz1;
        PETSC_OK(MatGetNonzeroState(y.bin, &nz1));
        if (str != DIFFERENT_NONZERO_PATTERN) CHECK(nz1 == nz0); // in place
        PetscBool           isbin, sym;
        MatBinBCSRPrecision prec;
        PetscInt            bw;
        PETSC_OK(PetscObjectTypeCompareAny((PetscObject)y.bin, &isbin, MATSEQBINBCSR, MATMPIBINBCSR, ""));
        CHECK(isbin);
        PETSC_OK(MatBinBCSRGetPrecision(y.bin, &prec));
        PETSC_OK(MatBinBCSRGetSymmetricStorage(y.bin, &sym));
        CHECK(prec == c.prec);
        CHECK(bool(sym) == c.sym);
        if (c.bw) {
          PETSC_OK(MatBinBCSRGetBinWidth(y.bin, &bw));
          CHECK(bw == c.bw);
        }
        // X of another type (aij): PETSc's own path, which takes binbcsr's matrix for the union
        // ("MatAXPYGetPreallocation_C") and so keeps the options
        {
          Mat y2;
          PETSC_OK(make(c, MATBINBCSR, &y2));
          PETSC_OK(MatAXPY(y2, a, x.aij, str));
          CHECK(row_error(y2, y.aij) <= 2 * kRoundings * c.eps());
          PETSC_OK(MatBinBCSRGetPrecision(y2, &prec));
          PETSC_OK(MatBinBCSRGetSymmetricStorage(y2, &sym));
          CHECK(prec == c.prec);
          CHECK(bool(sym) == c.sym);
          if (c.bw) {
            PETSC_OK(MatBinBCSRGetBinWidth(y2, &bw));
            CHECK(bw == c.bw);
          }
          PETSC_OK(MatDestroy(&y2));
        }
        // the result is a working matrix: products agree
        Vec u, vb, va;
        PETSC_OK(make_vec(y.aij, false, 5, &u));
        PETSC_OK(MatCreateVecs(y.aij, nullptr, &vb));
        PETSC_OK(VecDuplicate(vb, &va));
        PETSC_OK(MatMult(y.bin, u, vb));
        PETSC_OK(MatMult(y.aij, u, va));
        PETSC_OK(VecAXPY(vb, -1.0, va));
        PetscReal err, ref;
        PETSC_OK(VecNorm(vb, NORM_INFINITY, &err));
        PETSC_OK(VecNorm(va, NORM_INFINITY, &ref));
        CHECK(err <= 1e3 * c.eps() * ref);
        PETSC_OK(VecDestroy(&u));
        PETSC_OK(VecDestroy(&vb));
        PETSC_OK(VecDestroy(&va));
      }
    }
  }
}

TEST_CASE("MatTranspose matches aij; symmetric storage is its own transpose", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair p(c);
      Mat  tb, ta;
      PETSC_OK(MatTranspose(p.bin, MAT_INITIAL_MATRIX, &tb));
      PETSC_OK(MatTranspose(p.aij, MAT_INITIAL_MATRIX, &ta));
      CHECK(row_error(tb, ta) == 0.0);
      PetscBool isbin;
      PETSC_OK(PetscObjectTypeCompareAny((PetscObject)tb, &isbin, MATSEQBINBCSR, MATMPIBINBCSR, ""));
      CHECK(isbin);
      // new values, same pattern: MAT_REUSE_MATRIX refills the transpose
      PETSC_OK(MatScale(p.bin, 2.0));
      PETSC_OK(MatScale(p.aij, 2.0));
      PETSC_OK(MatTranspose(p.bin, MAT_REUSE_MATRIX, &tb));
      PETSC_OK(MatTranspose(p.aij, MAT_REUSE_MATRIX, &ta));
      CHECK(row_error(tb, ta) == 0.0);
      PETSC_OK(MatTranspose(p.bin, MAT_INPLACE_MATRIX, &p.bin));
      CHECK(row_error(p.bin, ta) == 0.0);
      PETSC_OK(MatDestroy(&tb));
      PETSC_OK(MatDestroy(&ta));
    }
  }
}

TEST_CASE("MatPermute matches aij and keeps the type and its options", "[rowops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair           p(c);
      const PetscInt N = c.mbs() * c.bs, mbs = c.mbs(), bs = c.bs;
      PetscInt       rstart, rend;
      PETSC_OK(MatGetOwnershipRange(p.aij, &rstart, &rend));
      // a permutation of whole blocks (7 and 5 are prime to 23 and 43) and one of points (5 is prime to 43, 46, 69)
      std::vector<PetscInt> blocks, points, other;
      for (PetscInt i = rstart; i < rend; i++) {
        blocks.push_back(((i / bs) * 7 + 3) % mbs * bs + i % bs);
        points.push_back((i * 5 + 1) % N);
        other.push_back(((i / bs) * 5 + 2) % mbs * bs + i % bs);
      }
      IS rb, rp, ro;
      PETSC_OK(ISCreateGeneral(PETSC_COMM_WORLD, rend - rstart, blocks.data(), PETSC_COPY_VALUES, &rb));
      PETSC_OK(ISCreateGeneral(PETSC_COMM_WORLD, rend - rstart, points.data(), PETSC_COPY_VALUES, &rp));
      PETSC_OK(ISCreateGeneral(PETSC_COMM_WORLD, rend - rstart, other.data(), PETSC_COPY_VALUES, &ro));
      PETSC_OK(ISSetPermutation(rb));
      PETSC_OK(ISSetPermutation(rp));
      PETSC_OK(ISSetPermutation(ro));
      const std::pair<IS, IS> cases_full[] = {{rb, rb}, {rb, ro}, {rp, rb}},
                              cases_sym[]  = {{rb, rb}, {rp, rp}};
      for (const auto &rc :
           c.sym ? std::vector<std::pair<IS, IS>>(std::begin(cases_sym), std::end(cases_sym))
                 : std::vector<std::pair<IS, IS>>(std::begin(cases_full), std::end(cases_full))) {
        Mat pb, pa;
        PETSC_OK(MatPermute(p.bin, rc.first, rc.second, &pb));
        PETSC_OK(MatPermute(p.aij, rc.first, rc.second, &pa));
        CHECK(row_error(pb, pa) == 0.0);
        PetscBool           isbin, sym;
        MatBinBCSRPrecision prec;
        PetscInt            bw, bw0;
        PETSC_OK(PetscObjectTypeCompareAny((PetscObject)pb, &isbin, MATSEQBINBCSR, MATMPIBINBCSR, ""));
        CHECK(isbin);
        PETSC_OK(MatBinBCSRGetPrecision(pb, &prec));
        PETSC_OK(MatBinBCSRGetSymmetricStorage(pb, &sym));
        PETSC_OK(MatBinBCSRGetBinWidth(pb, &bw));
        PETSC_OK(MatBinBCSRGetBinWidth(p.bin, &bw0));
        CHECK(prec == c.prec);
        CHECK(bool(sym) == c.sym);
        CHECK(bw == bw0);
        PETSC_OK(MatDestroy(&pb));
        PETSC_OK(MatDestroy(&pa));
      }
      if (c.sym) {
        Mat pb = nullptr;
        PETSC_FAILS_WITH(MatPermute(p.bin, rb, ro, &pb), PETSC_ERR_SUP);
      }
      PETSC_OK(ISDestroy(&rb));
      PETSC_OK(ISDestroy(&rp));
      PETSC_OK(ISDestroy(&ro));
    }
  }
}

TEST_CASE("MatIsSymmetric answers as aij, within a tolerance", "[rowops]")
{
  for (Config c : configs()) {
    for (bool full : {false, true}) {
      if (full && !c.sym) continue;
      c.full_storage = full;
      SECTION(c.name() + (full ? " kept in full storage" : ""))
      {
        for (PetscReal tol : {0.0, 1e-3, 1e10}) {
          Pair      p(c);
          PetscBool fb, fa;
          PETSC_OK(MatIsSymmetric(p.bin, tol, &fb));
          PETSC_OK(MatIsSymmetric(p.aij, tol, &fa));
          INFO("tol " << tol);
          CHECK(fb == fa);
          CHECK(bool(fb) == (c.sym || tol == 1e10)); // the scales make some differences exceed 1e-3
        }
      }
    }
  }
}
