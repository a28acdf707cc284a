// The layout tuner (-mat_binbcsr_tune): it chooses among the candidates, the products and stored
// values stay exactly those of a fixed configuration, explicit settings win, the first products
// decide the x load, bad values give errors (the cache file: tune_cache.cpp). The cache lives in a
// folder of the test run (XDG_CACHE_HOME, set by CTest; each case here points it at its own folder).
#include "tune_support.hpp"
#include "mat_binbcsr/seq/binbcsr.h" // BINBCSR_XLOAD_TRIAL

using namespace mat_core;

TEST_CASE("tuning chooses among the candidates; products and values stay exact", "[tune]")
{
  Restore r;
  fresh_cache("tune_exact");
  Opts o(false);
  for (PetscInt bs : {1, 3})
    for (auto prec : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE})
      for (bool sym : {false, true}) {
        CAPTURE(bs, (int)prec, sym);
        const Pattern p   = sym_pattern(bs == 1 ? 12 : 7, bs);
        Mat           A   = build_tuned(p, prec, sym, MAT_BINBCSR_TUNE_AUTO);
        Mat           R   = build_tuned(p, prec, sym, MAT_BINBCSR_TUNE_OFF, bs == 1 ? 16 : 8, 4);
        const auto    txt = info_view(A);
        CAPTURE(txt);
        CHECK(txt.find("tuning (-mat_binbcsr_tune): bin width") != std::string::npos);
        CHECK(txt.find("measured on block rows") != std::string::npos);
        const PetscInt bw = bin_width(A), k = streams(A);
        CHECK((bw == 4 || bw == 8 || bw == 16 || (bw == 32 && bs == 1)));
        CHECK((k == 1 || k == 2 || k == 4 || k == 8));
        // every candidate was timed (the budget admits them all on a matrix this small)
        CHECK(txt.find("left out by the budget") == std::string::npos);
        CHECK(txt.find(" 4/") != std::string::npos);
        CHECK(txt.find(" 16/") != std::string::npos);
        PetscBool avx2;
        REQUIRE(MatBinBCSRKernelAvailable(MAT_BINBCSR_KERNEL_AVX2, &avx2) == 0);
        if (avx2) CHECK(txt.find("/portable ") != std::string::npos); // the other body sets were timed too
        // and the prefetch distances other than the default
        CHECK(txt.find("/pf0 ") != std::string::npos);
        CHECK(txt.find("/pf1024 ") != std::string::npos);
        PetscInt pf = -1;
        REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
        CHECK((pf == 0 || pf == 1024 || pf == 4096));
        check_same(A, R, p);
        Mat D;
        REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &D) == 0);
        CHECK(bin_width(D) == bw);
        CHECK(streams(D) == k);
        check_same(D, R, p);
        MatDestroy(&D);
        CHECK(info_view(R).find("tuning (-mat_binbcsr_tune): off") != std::string::npos);
        MatDestroy(&A);
        MatDestroy(&R);
      }
}

TEST_CASE("tuning through COO assembly keeps the values exact", "[tune]")
{
  Restore r;
  fresh_cache("tune_coo");
  Opts                     o(false);
  const Pattern            p = fem_pattern(7, 7, 7, 3);
  std::vector<PetscInt>    ii, jj;
  std::vector<PetscScalar> vv;
  for (const Entry &e : p.entries) ii.push_back(e.i), jj.push_back(e.j), vv.push_back(e.v);
  Mat A, R = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_OFF, 8, 4);
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, 3) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  REQUIRE(MatSetFromOptions(A) == 0);
  REQUIRE(MatSetPreallocationCOO(A, (PetscCount)ii.size(), ii.data(), jj.data()) == 0);
  REQUIRE(MatSetValuesCOO(A, vv.data(), INSERT_VALUES) == 0);
  CHECK(info_view(A).find("measured on block rows") != std::string::npos);
  check_same(A, R, p);
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("tuning: explicit settings win", "[tune]")
{
  Restore r;
  fresh_cache("tune_explicit");
  Opts          o(false);
  const Pattern p = fem_pattern(7, 7, 7, 3);
  {
    Mat A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 16, 0);
    CHECK(bin_width(A) == 16);
    const auto txt = info_view(A);
    CHECK(txt.find(" 16/1 ") != std::string::npos); // only the streams were timed
    CHECK(txt.find(" 4/") == std::string::npos);
    MatDestroy(&A);
  }
  {
    Mat A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 0, 2);
    CHECK(streams(A) == 2);
    CHECK(info_view(A).find("/1 ") == std::string::npos); // only the widths, at streams 2
    MatDestroy(&A);
  }
  {
    // the kernel set explicitly: kept, and only it is timed
    o.set("-mat_binbcsr_kernel", "portable");
    Mat              A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    MatBinBCSRKernel k;
    REQUIRE(MatBinBCSRGetKernel(A, &k) == 0);
    CHECK(k == MAT_BINBCSR_KERNEL_PORTABLE);
    CHECK(info_view(A).find("/avx") == std::string::npos);
    MatDestroy(&A);
  }
  {
    // width, streams and kernel set: only the prefetch distance is timed
    o.set("-mat_binbcsr_bin_width", "4");
    o.set("-mat_binbcsr_streams", "8");
    Mat A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    CHECK(bin_width(A) == 4);
    CHECK(streams(A) == 8);
    auto txt = info_view(A);
    CAPTURE(txt);
    CHECK(txt.find("nothing to tune") == std::string::npos);
    CHECK(txt.find(" 4/8/pf0 ") != std::string::npos);
    CHECK(txt.find(" 4/8/pf1024 ") != std::string::npos);
    CHECK(txt.find(" 8/") == std::string::npos);
    MatDestroy(&A);
    // and with the distance set too, nothing is
    o.set("-mat_binbcsr_prefetch", "1024");
    A           = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    PetscInt pf = -1;
    REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
    CHECK(pf == 1024);
    CHECK(info_view(A).find("nothing to tune") != std::string::npos);
    MatDestroy(&A);
  }
  {
    // only the distance set: kept, the rest tuned at it
    for (const char *n : {"-mat_binbcsr_bin_width", "-mat_binbcsr_streams", "-mat_binbcsr_kernel"})
      REQUIRE(PetscOptionsClearValue(nullptr, n) == 0);
    o.set("-mat_binbcsr_prefetch", "0");
    Mat      A  = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    PetscInt pf = -1;
    REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
    CHECK(pf == 0);
    const auto txt = info_view(A);
    CHECK(txt.find("measured on block rows") != std::string::npos);
    CHECK(txt.find("/pf1024 ") == std::string::npos); // no other distance timed
    CHECK(txt.find("/pf4096 ") == std::string::npos);
    MatDestroy(&A);
  }
}

TEST_CASE("tuning: a precision change times the streams again, at the layout's width", "[tune]")
{
  Restore r;
  fresh_cache("tune_precision");
  Opts o(false);
  for (bool sym : {false, true}) {
    CAPTURE(sym);
    const Pattern  p  = sym_pattern(7, 3);
    Mat            A  = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, sym, MAT_BINBCSR_TUNE_AUTO);
    const PetscInt bw = bin_width(A);
    REQUIRE(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_SINGLE) == 0);
    const auto txt = info_view(A);
    CAPTURE(txt);
    CHECK(txt.find("after the precision change, at the layout's bin width: bin width " +
                   std::to_string(bw)) != std::string::npos);
    CHECK(bin_width(A) == bw);
    const PetscInt k = streams(A);
    CHECK((k == 1 || k == 2 || k == 4 || k == 8));
    Mat R = build_tuned(p, MAT_BINBCSR_PRECISION_SINGLE, sym, MAT_BINBCSR_TUNE_OFF, bw, k);
    check_same(A, R, p); // the values converted once, the products those of the fixed configuration
    MatDestroy(&R);
    MatDestroy(&A);
    // explicit streams, kernel and prefetch distance: nothing is timed again
    o.set("-mat_binbcsr_kernel", "portable");
    o.set("-mat_binbcsr_prefetch", "4096");
    A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, sym, MAT_BINBCSR_TUNE_AUTO, 0, 2);
    REQUIRE(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_SINGLE) == 0);
    CHECK(info_view(A).find("after the precision change") == std::string::npos);
    CHECK(streams(A) == 2);
    MatDestroy(&A);
    PetscOptionsClearValue(nullptr, "-mat_binbcsr_kernel");
  }
}

TEST_CASE("tuning: the first products decide the x load", "[tune][xload]")
{
  Restore   r;
  PetscBool avx512;
  REQUIRE(MatBinBCSRKernelAvailable(MAT_BINBCSR_KERNEL_AVX512, &avx512) == 0);
  if (!avx512) return; // the x load is read by the AVX-512 body only
  fresh_cache("tune_xload_trial");
  Opts o(false);
  o.set("-mat_binbcsr_kernel", "avx512");
  const Pattern p = fem_pattern(7, 7, 7, 3);
  Mat           A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 8);
  Mat           R = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_OFF, 8, 1);
  // every product of the trial, in either x load, is R's to the bit; its end is reported
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL + 1; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products: loads ") != std::string::npos);
  MatBinBCSRXLoad x;
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK((x == MAT_BINBCSR_XLOAD_LOADS || x == MAT_BINBCSR_XLOAD_GATHER));
  MatDestroy(&A);
  // a body that does not read the x load, set after the tuner's: its products do not count
  A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 8);
  check_same(A, R, p); // the trial's untimed first product, with the AVX-512 body
  REQUIRE(MatBinBCSRSetKernel(A, MAT_BINBCSR_KERNEL_PORTABLE) == 0);
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products") == std::string::npos);
  REQUIRE(MatBinBCSRSetKernel(A, MAT_BINBCSR_KERNEL_AVX512) == 0);
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL - 1; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products: loads ") != std::string::npos);
  MatDestroy(&A);
  // an x load set explicitly: no trial
  o.set("-mat_binbcsr_xload", "gather");
  A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 8);
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL + 1; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products") == std::string::npos);
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_GATHER);
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("tuning: bad values give clear errors", "[tune]")
{
  Restore r;
  fresh_cache("tune_bad");
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, 6, 6, 6, 6) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  CHECK(MatBinBCSRSetTune(A, (MatBinBCSRTune)7) == PETSC_ERR_ARG_OUTOFRANGE);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune", "sometimes") == 0);
  CHECK(MatSetFromOptions(A) != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune_cache", "perhaps") == 0);
  CHECK(MatSetFromOptions(A) != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune_cache") == 0);
  MatBinBCSRTune t;
  REQUIRE(MatBinBCSRGetTune(A, &t) == 0);
  CHECK(t == MAT_BINBCSR_TUNE_AUTO); // the default
  MatDestroy(&A);
  // read at the layout build when MatSetFromOptions was not called
  const Pattern p = fem_pattern(4, 4, 4, 3);
  // an empty assembly of p's sizes: where the layout build reads the options
  auto assemble = [&]() {
    Mat B;
    REQUIRE(MatCreate(PETSC_COMM_SELF, &B) == 0);
    REQUIRE(MatSetSizes(B, p.m, p.n, p.m, p.n) == 0);
    REQUIRE(MatSetBlockSize(B, 3) == 0);
    REQUIRE(MatSetType(B, MATSEQBINBCSR) == 0);
    REQUIRE(MatSetUp(B) == 0);
    REQUIRE(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY) == 0);
    const PetscErrorCode ierr = MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY);
    MatDestroy(&B);
    return ierr;
  };
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune", "never") == 0);
  CHECK(assemble() != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune") == 0);
  // the benchmark knobs: sizes and budgets must be positive
  for (const char *knob : {"-mat_binbcsr_tune_sample_mib", "-mat_binbcsr_tune_budget_ms"}) {
    CAPTURE(knob);
    Opts o(false);
    o.set(knob, "0");
    CHECK(assemble() == PETSC_ERR_ARG_OUTOFRANGE);
  }
  // other types: no-ops
  REQUIRE(MatCreateSeqAIJ(PETSC_COMM_SELF, 4, 4, 1, nullptr, &A) == 0);
  CHECK(MatBinBCSRSetTune(A, MAT_BINBCSR_TUNE_AUTO) == 0);
  REQUIRE(MatBinBCSRGetTune(A, &t) == 0);
  CHECK(t == MAT_BINBCSR_TUNE_OFF);
  MatDestroy(&A);
}
