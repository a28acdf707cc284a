// MatBinBCSRSetStreams on whole storage (streams_check.h says what is checked), on patterns where the
// bins are not a multiple of the runs, rows of one bin differ wildly in length, and unit-stride and
// gathered slot groups alternate; and the setter, option, view and bad values.
#include "support/streams_check.hpp"

using namespace mat_core;

TEST_CASE("every streams count gives the one-run product up to rounding", "[mat_core][mult][streams]")
{
  const PetscInt            bs   = GENERATE(1, 3);
  const PetscInt            bw   = GENERATE(4, 8, 16, 32);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  const Pattern patterns[] = {
    random_pattern(301, 301, bs, 9, 17 + bs), // bins not a multiple of 2, 4, 8
    random_pattern(53, 71, bs, 6, 3 + bs),    // rectangular
    wild_pattern(600, bs, 500),               // rows of 1 and 500 blocks
    fem_pattern(49, 3, 2, bs),                // unit-stride and gathered groups
  };
  for (const Pattern &p : patterns) {
    Mat A = build(p, MATSEQBINBCSR, bw, prec);
    check_streams(A, p);
    MatDestroy(&A);
  }
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
