// MatMult, MatMultAdd, MatMultTranspose(+Add) and MatMultDotLocal of MATSEQBINBCSR against seqaij, on
// random, FEM-like and wild patterns, several bin widths, block sizes and both precisions.
#include "support/mat_support.hpp"

using namespace mat_core;

namespace {

void check_products(const Pattern &p, PetscInt bw, MatBinBCSRPrecision prec)
{
  Mat ref = build(p, MATSEQAIJ);
  Mat A   = build(p, MATSEQBINBCSR, bw, prec);
  // float storage rounds each value by at most FLT_EPSILON/2 relative
  const double unit = prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON / 2 : 0.0;
  Vec          x = make_vec(p.n, 1), z = make_vec(p.m, 2), y, yref;
  Vec          xt = make_vec(p.m, 3), zt = make_vec(p.n, 4), yt, ytref;
  REQUIRE(VecDuplicate(z, &y) == 0);
  REQUIRE(VecDuplicate(z, &yref) == 0);
  REQUIRE(VecDuplicate(zt, &yt) == 0);
  REQUIRE(VecDuplicate(zt, &ytref) == 0);
  const auto xv = values(x), xtv = values(xt);

  SECTION("mult")
  {
    REQUIRE(MatMult(A, x, y) == 0);
    REQUIRE(MatMult(ref, x, yref) == 0);
    check_close(values(y), values(yref), mult_bound(p, xv, unit, false));
  }
  SECTION("mult add, separate and in place")
  {
    REQUIRE(MatMultAdd(A, x, z, y) == 0);
    REQUIRE(MatMultAdd(ref, x, z, yref) == 0);
    check_close(values(y), values(yref), mult_bound(p, xv, unit, false));
    REQUIRE(VecCopy(z, y) == 0);
    REQUIRE(MatMultAdd(A, x, y, y) == 0);
    check_close(values(y), values(yref), mult_bound(p, xv, unit, false));
  }
  SECTION("transpose")
  {
    REQUIRE(MatMultTranspose(A, xt, yt) == 0);
    REQUIRE(MatMultTranspose(ref, xt, ytref) == 0);
    check_close(values(yt), values(ytref), mult_bound(p, xtv, unit, true));
    REQUIRE(MatMultTransposeAdd(A, xt, zt, yt) == 0);
    REQUIRE(MatMultTransposeAdd(ref, xt, zt, ytref) == 0);
    check_close(values(yt), values(ytref), mult_bound(p, xtv, unit, true));
    REQUIRE(VecCopy(zt, yt) == 0);
    REQUIRE(MatMultTransposeAdd(A, xt, yt, yt) == 0);
    check_close(values(yt), values(ytref), mult_bound(p, xtv, unit, true));
  }
  if (p.m == p.n) {
    SECTION("fused mult and local dot")
    {
      PetscScalar dot = -1, dotref;
      REQUIRE(MatMultDotLocal(A, x, y, &dot) == 0);
      REQUIRE(MatMult(ref, x, yref) == 0);
      const auto yb = mult_bound(p, xv, unit, false);
      check_close(values(y), values(yref), yb);
      REQUIRE(VecDot(yref, x, &dotref) == 0);
      double dbound = 0;
      for (size_t i = 0; i < xv.size(); i++)
        dbound += std::fabs(xv[i]) * yb[i] + 1e-14 * std::fabs(xv[i] * values(yref)[i]);
      CHECK(std::fabs(dot - dotref) <= dbound + 1e-12);
    }
  }
  VecDestroy(&x);
  VecDestroy(&z);
  VecDestroy(&y);
  VecDestroy(&yref);
  VecDestroy(&xt);
  VecDestroy(&zt);
  VecDestroy(&yt);
  VecDestroy(&ytref);
  MatDestroy(&A);
  MatDestroy(&ref);
}

} // namespace

TEST_CASE("products on random patterns, bs 1 and 3, bin widths, both precisions", "[mat_core][mult]")
{
  const PetscInt            bs   = GENERATE(1, 3, 2);
  const PetscInt            bw   = GENERATE(1, 3, 4, 8, 16, 32);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  check_products(random_pattern(37, 37, bs, 9, 11 + bs), bw, prec); // 37: not a multiple of any width
  check_products(random_pattern(23, 41, bs, 6, 5 + bs), bw, prec);  // rectangular
}

TEST_CASE("products on a FEM-like 3x3 block stencil", "[mat_core][mult]")
{
  const PetscInt            bw   = GENERATE(4, 8, 16);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bw, prec);
  check_products(fem_pattern(5, 4, 3), bw, prec);
}

// Grids numbered along their rows give slot groups whose lanes read consecutive block columns; the
// products load x there instead of gathering it. nx = 48: every bin inside a grid row; nx = 49: bins
// straddle grid rows, so unit-stride and gathered groups alternate.
TEST_CASE("products on structured grids (slot groups over consecutive columns), bs 1 and 3",
          "[mat_core][mult]")
{
  const PetscInt            bs   = GENERATE(1, 3);
  const PetscInt            bw   = GENERATE(4, 8, 16);
  const PetscInt            nx   = GENERATE(48, 49);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, nx, prec);
  const Pattern p = fem_pattern(nx, 2, 1, bs);
  check_products(p, bw, prec);
  Mat               A    = build(p, MATSEQBINBCSR, bw, prec);
  const std::string info = info_view(A);
  const size_t      at   = info.find("slot groups over consecutive block columns (x read without gathers): ");
  REQUIRE(at != std::string::npos);
  long unit = -1, groups = -1;
  REQUIRE(std::sscanf(info.c_str() + at,
                      "slot groups over consecutive block columns (x read without gathers): %ld of %ld",
                      &unit, &groups) == 2);
  CHECK(groups > 0);
  if (nx == 48) CHECK(unit >= groups / 4); // boundary bins of the grid are the exceptions
  else CHECK(unit > 0);
  MatDestroy(&A);
}

TEST_CASE("a matrix flagged symmetric multiplies its transpose through the vectorised product",
          "[mat_core][mult]")
{
  const Pattern p = fem_pattern(4, 3, 3);
  Mat           A = build(p, MATSEQBINBCSR), R = build(p, MATSEQAIJ);
  REQUIRE(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE) == 0);
  Vec x = make_vec(p.n, 5), z = make_vec(p.n, 6), y, yref;
  REQUIRE(VecDuplicate(x, &y) == 0);
  REQUIRE(VecDuplicate(x, &yref) == 0);
  REQUIRE(MatMultTranspose(A, x, y) == 0);
  REQUIRE(MatMultTranspose(R, x, yref) == 0);
  check_close(values(y), values(yref), mult_bound(p, values(x), 0.0, true));
  REQUIRE(MatMultTransposeAdd(A, x, z, y) == 0);
  REQUIRE(MatMultTransposeAdd(R, x, z, yref) == 0);
  check_close(values(y), values(yref), mult_bound(p, values(x), 0.0, true));
  VecDestroy(&x);
  VecDestroy(&z);
  VecDestroy(&y);
  VecDestroy(&yref);
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("products with rows of 1 and 500 blocks in one bin, a single row, an empty matrix",
          "[mat_core][mult]")
{
  const PetscInt bs = GENERATE(1, 3);
  const PetscInt bw = GENERATE(4, 8, 5);
  CAPTURE(bs, bw);
  check_products(wild_pattern(600, bs, 500), bw, MAT_BINBCSR_PRECISION_DOUBLE);
  check_products(wild_pattern(600, bs, 500), bw, MAT_BINBCSR_PRECISION_SINGLE);
  check_products(random_pattern(1, 1, bs, 1, 3), bw, MAT_BINBCSR_PRECISION_DOUBLE);
  Pattern empty;
  empty.m = empty.n = 4 * bs;
  empty.bs          = bs;
  check_products(empty, bw, MAT_BINBCSR_PRECISION_DOUBLE);
}
