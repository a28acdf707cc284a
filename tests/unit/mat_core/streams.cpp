// MatBinBCSRSetStreams: the product sweeps runs of bins side by side. Each lane's sum is the same
// sequence of products for any number of runs, so every product must equal the one-run product up
// to the rounding of the double sums (the compiler may contract multiply-adds into FMAs differently in
// each instantiation: with GCC 12 the hand-written AVX-512 body agrees bit for bit, the portable one at
// bs 3 / bin width 4 in the last bits), on patterns where the bins are not a multiple of the runs, rows
// of one bin differ wildly in length, and unit-stride and gathered slot groups alternate.
#include "support.h"

using namespace mat_core;

namespace
{

struct Products {
  std::vector<PetscScalar> mult, mult_add, mult_add_in_place, mult_dot;
  PetscScalar              dot = 0;
};

Products products(Mat A, const Pattern &p)
{
  Products out;
  Vec      x = make_vec(p.n, 1), z = make_vec(p.m, 2), y;
  REQUIRE(VecDuplicate(z, &y) == 0);
  REQUIRE(MatMult(A, x, y) == 0);
  out.mult = values(y);
  REQUIRE(MatMultAdd(A, x, z, y) == 0);
  out.mult_add = values(y);
  REQUIRE(VecCopy(z, y) == 0);
  REQUIRE(MatMultAdd(A, x, y, y) == 0);
  out.mult_add_in_place = values(y);
  if (p.m == p.n) {
    REQUIRE(MatMultDotLocal(A, x, y, &out.dot) == 0);
    out.mult_dot = values(y);
  }
  VecDestroy(&x);
  VecDestroy(&z);
  VecDestroy(&y);
  return out;
}

void check_streams(const Pattern &p, PetscInt bw, MatBinBCSRPrecision prec)
{
  Mat A = build(p, MATSEQBINBCSR, bw, prec);
  REQUIRE(MatBinBCSRSetStreams(A, 1) == 0);
  const Products one = products(A, p);
  Vec            x   = make_vec(p.n, 1); // the x of products()
  const auto     xv  = values(x);
  /* the stored values are the same for every run count (single storage too): double rounding only */
  const auto bound = mult_bound(p, xv, 0.0, false);
  VecDestroy(&x);
  for (PetscInt streams : {2, 4, 8}) {
    CAPTURE(streams);
    REQUIRE(MatBinBCSRSetStreams(A, streams) == 0);
    const Products got = products(A, p);
    check_close(got.mult, one.mult, bound);
    check_close(got.mult_add, one.mult_add, bound);
    check_close(got.mult_add_in_place, one.mult_add_in_place, bound);
    if (p.m == p.n) {
      check_close(got.mult_dot, one.mult_dot, bound);
      double dbound = 0;
      for (size_t i = 0; i < xv.size(); i++) dbound += std::fabs(xv[i]) * (bound[i] + 64 * DBL_EPSILON * std::fabs(one.mult_dot[i]));
      CHECK(std::fabs(got.dot - one.dot) <= dbound);
    }
  }
  MatDestroy(&A);
}

} // namespace

TEST_CASE("every streams count gives the one-run product bit for bit", "[mat_core][mult][streams]")
{
  const PetscInt            bs   = GENERATE(1, 3);
  const PetscInt            bw   = GENERATE(4, 8, 16, 32);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  check_streams(random_pattern(301, 301, bs, 9, 17 + bs), bw, prec); // bins not a multiple of 2, 4, 8
  check_streams(random_pattern(53, 71, bs, 6, 3 + bs), bw, prec);    // rectangular
  check_streams(wild_pattern(600, bs, 500), bw, prec);              // rows of 1 and 500 blocks
  check_streams(fem_pattern(49, 3, 2, bs), bw, prec);               // unit-stride and gathered groups
}

TEST_CASE("streams: default, option, view, duplicate and bad values", "[mat_core][streams]")
{
  const Pattern p = fem_pattern(6, 5, 4);
  Mat           A = build(p, MATSEQBINBCSR), B, R = build(p, MATSEQAIJ);
  PetscInt      streams;
  REQUIRE(MatBinBCSRGetStreams(A, &streams) == 0);
  CHECK(streams == 4);
  CHECK(info_view(A).find("product: 4 run(s) of bins swept side by side") != std::string::npos);

  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_streams", "2") == 0);
  REQUIRE(MatBinBCSRSetFromOptions(A) == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_streams") == 0);
  REQUIRE(MatBinBCSRGetStreams(A, &streams) == 0);
  CHECK(streams == 2);
  REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &B) == 0);
  REQUIRE(MatBinBCSRGetStreams(B, &streams) == 0);
  CHECK(streams == 2);

  for (PetscInt bad : {0, 3, 16, -1}) {
    CAPTURE(bad);
    CHECK(MatBinBCSRSetStreams(A, bad) == PETSC_ERR_ARG_OUTOFRANGE);
  }
  REQUIRE(MatBinBCSRGetStreams(A, &streams) == 0);
  CHECK(streams == 2);

  // other types: the setter does nothing, the getter answers 1
  REQUIRE(MatBinBCSRSetStreams(R, 8) == 0);
  REQUIRE(MatBinBCSRGetStreams(R, &streams) == 0);
  CHECK(streams == 1);
  MatDestroy(&A);
  MatDestroy(&B);
  MatDestroy(&R);
}
