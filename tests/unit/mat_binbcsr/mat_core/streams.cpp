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
    check_prefetch(A, p);
    check_xload(A, p);
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

TEST_CASE("x load: default, option, view, duplicate and bad values", "[mat_core][xload]")
{
  const Pattern   p = fem_pattern(6, 5, 4);
  Mat             A = build(p, MATSEQBINBCSR, 8), B, R = build(p, MATSEQAIJ);
  MatBinBCSRXLoad x;
  PetscBool       avx512;
  REQUIRE(MatBinBCSRKernelAvailable(MAT_BINBCSR_KERNEL_AVX512, &avx512) == 0);
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_LOADS); // the untuned default
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_xload", "gather") == 0);
  REQUIRE(MatBinBCSRSetFromOptions(A) == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_xload") == 0);
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_GATHER);
  // named where it applies: whole storage, 3x3 blocks, width 8, the AVX-512 body
  if (avx512) CHECK(info_view(A).find("-mat_binbcsr_xload gather") != std::string::npos);
  REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &B) == 0);
  REQUIRE(MatBinBCSRGetXLoad(B, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_GATHER);
  CHECK(MatBinBCSRSetXLoad(A, (MatBinBCSRXLoad)2) == PETSC_ERR_ARG_OUTOFRANGE);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_xload", "scatter") == 0);
  CHECK(MatBinBCSRSetFromOptions(A) != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_xload") == 0);
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_GATHER);
  // other types: the setter does nothing, the getter answers loads
  REQUIRE(MatBinBCSRSetXLoad(R, MAT_BINBCSR_XLOAD_GATHER) == 0);
  REQUIRE(MatBinBCSRGetXLoad(R, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_LOADS);
  MatDestroy(&A);
  MatDestroy(&B);
  MatDestroy(&R);
}

TEST_CASE("prefetch: default, option, view, duplicate and bad values", "[mat_core][prefetch]")
{
  const Pattern p = fem_pattern(6, 5, 4);
  Mat           A = build(p, MATSEQBINBCSR), B, R = build(p, MATSEQAIJ);
  PetscInt      pf;
  REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
  CHECK(pf == 4096); // the untuned default (build() leaves a matrix this small untuned)
  CHECK(info_view(A).find("product: values prefetched 4096 bytes ahead") != std::string::npos);

  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_prefetch", "0") == 0);
  REQUIRE(MatBinBCSRSetFromOptions(A) == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_prefetch") == 0);
  REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
  CHECK(pf == 0);
  CHECK(info_view(A).find("prefetched 0 bytes ahead (no software prefetch)") != std::string::npos);
  REQUIRE(MatBinBCSRSetPrefetch(A, 1024) == 0);
  REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &B) == 0);
  REQUIRE(MatBinBCSRGetPrefetch(B, &pf) == 0);
  CHECK(pf == 1024);

  for (PetscInt bad : {-64, -1, 100, 65600, 1 << 20}) {
    CAPTURE(bad);
    CHECK(MatBinBCSRSetPrefetch(A, bad) == PETSC_ERR_ARG_OUTOFRANGE);
  }
  REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
  CHECK(pf == 1024);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_prefetch", "1000") == 0);
  CHECK(MatBinBCSRSetFromOptions(A) == PETSC_ERR_ARG_OUTOFRANGE);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_prefetch") == 0);

  // other types: the setter does nothing, the getter answers 0
  REQUIRE(MatBinBCSRSetPrefetch(R, 4096) == 0);
  REQUIRE(MatBinBCSRGetPrefetch(R, &pf) == 0);
  CHECK(pf == 0);
  MatDestroy(&A);
  MatDestroy(&B);
  MatDestroy(&R);
}
