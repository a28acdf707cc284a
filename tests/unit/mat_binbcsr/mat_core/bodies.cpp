// Every body set this CPU has (MatBinBCSRSetKernel) against the portable one, the definition, in the
// same program: whole and symmetric storage, bs 1 and 3 (the specialised shapes) and 2 (generic), every
// bin width with a specialised body and every streams count. Then the setter, option, view and bad values.
#include "support/streams_check.hpp"

using namespace mat_core;

namespace {

std::vector<MatBinBCSRKernel> available_sets()
{
  std::vector<MatBinBCSRKernel> sets;
  for (MatBinBCSRKernel k : {MAT_BINBCSR_KERNEL_AVX2, MAT_BINBCSR_KERNEL_AVX512}) {
    PetscBool avail;
    REQUIRE(MatBinBCSRKernelAvailable(k, &avail) == 0);
    if (avail) sets.push_back(k);
  }
  return sets;
}

} // namespace

TEST_CASE("every body set gives the portable product up to rounding", "[mat_core][mult][bodies]")
{
  const PetscInt            bs   = GENERATE(1, 3, 2);
  const PetscInt            bw   = GENERATE(4, 8, 16, 32);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  const PetscBool           sym  = GENERATE(PETSC_FALSE, PETSC_TRUE);
  CAPTURE(bs, bw, prec, sym);
  const Pattern patterns[] = {
    random_pattern(301, 301, bs, 9, 17 + bs), // bins not a multiple of the runs
    wild_pattern(600, bs, 500),               // rows of 1 and 500 blocks
    fem_pattern(49, 3, 2, bs),                // unit-stride and gathered groups
  };
  for (const Pattern &p : patterns) {
    Mat A = create_unfilled(p, MATSEQBINBCSR, bw, prec, sym);
    REQUIRE(MatSetUp(A) == 0);
    for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
    REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
    REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
    Vec x = make_vec(p.n, 1);
    /* the stored values are the same for every body: the double sums' rounding only (the sums are
       the same products in the same order; FMA contraction may differ) */
    Pattern eff = p; /* the matrix A holds: with symmetric storage, the upper block triangle mirrored */
    if (sym) {
      eff.entries.clear();
      for (const Entry &e : p.entries)
        if (e.i / p.bs <= e.j / p.bs) {
          eff.entries.push_back(e);
          if (e.i / p.bs < e.j / p.bs) eff.entries.push_back({e.j, e.i, e.v});
        }
    }
    const auto bound = mult_bound(eff, values(x), 0.0, false);
    VecDestroy(&x);
    for (PetscInt streams : {1, 4}) {
      CAPTURE(streams);
      REQUIRE(MatBinBCSRSetStreams(A, streams) == 0);
      REQUIRE(MatBinBCSRSetKernel(A, MAT_BINBCSR_KERNEL_PORTABLE) == 0);
      MatBinBCSRKernel inuse;
      REQUIRE(MatBinBCSRGetKernel(A, &inuse) == 0);
      CHECK(inuse == MAT_BINBCSR_KERNEL_PORTABLE);
      const Products ref = products(A, p);
      for (MatBinBCSRKernel k : available_sets()) {
        CAPTURE(k);
        REQUIRE(MatBinBCSRSetKernel(A, k) == 0);
        REQUIRE(MatBinBCSRGetKernel(A, &inuse) == 0);
        /* the fixed shapes have a body in every set; bs 2 falls back to the portable one */
        CHECK(inuse == (bs == 2 ? MAT_BINBCSR_KERNEL_PORTABLE : k));
        const Products got = products(A, p);
        check_close(got.mult, ref.mult, bound);
        check_close(got.mult_add, ref.mult_add, bound);
        check_close(got.mult_add_in_place, ref.mult_add_in_place, bound);
        if (p.m == p.n) check_close(got.mult_dot, ref.mult_dot, bound);
      }
    }
    MatDestroy(&A);
  }
}

TEST_CASE("kernel: default, option, view, duplicate and bad values", "[mat_core][bodies]")
{
  const Pattern    p = fem_pattern(6, 5, 4);
  Mat              A = build(p, MATSEQBINBCSR), B, R = build(p, MATSEQAIJ);
  MatBinBCSRKernel k, best = MAT_BINBCSR_KERNEL_PORTABLE;
  for (MatBinBCSRKernel s : available_sets()) best = s;
  REQUIRE(MatBinBCSRGetKernel(A, &k) == 0);
  CHECK(k == best); /* auto: the best set this CPU has (bs 3, bin width 8 has a body in each) */
  CHECK(info_view(A).find(std::string("product body: ") + MatBinBCSRKernels[best] +
                          " (-mat_binbcsr_kernel auto)") != std::string::npos);

  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_kernel", "portable") == 0);
  REQUIRE(MatBinBCSRSetFromOptions(A) == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_kernel") == 0);
  REQUIRE(MatBinBCSRGetKernel(A, &k) == 0);
  CHECK(k == MAT_BINBCSR_KERNEL_PORTABLE);
  CHECK(info_view(A).find("product body: portable (-mat_binbcsr_kernel portable)") != std::string::npos);
  REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &B) == 0);
  REQUIRE(MatBinBCSRGetKernel(B, &k) == 0);
  CHECK(k == MAT_BINBCSR_KERNEL_PORTABLE);

  // an unknown value, and a set the CPU lacks: clear errors, the choice unchanged
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_kernel", "sse9") == 0);
  CHECK(MatBinBCSRSetFromOptions(A) != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_kernel") == 0);
  CHECK(MatBinBCSRSetKernel(A, (MatBinBCSRKernel)7) == PETSC_ERR_ARG_OUTOFRANGE);
  for (MatBinBCSRKernel s : {MAT_BINBCSR_KERNEL_AVX2, MAT_BINBCSR_KERNEL_AVX512}) {
    PetscBool avail;
    REQUIRE(MatBinBCSRKernelAvailable(s, &avail) == 0);
    if (!avail) CHECK(MatBinBCSRSetKernel(A, s) == PETSC_ERR_SUP_SYS);
  }
  REQUIRE(MatBinBCSRGetKernel(A, &k) == 0);
  CHECK(k == MAT_BINBCSR_KERNEL_PORTABLE);

  // other types: the setter does nothing, the getter answers portable
  REQUIRE(MatBinBCSRSetKernel(R, MAT_BINBCSR_KERNEL_AUTO) == 0);
  REQUIRE(MatBinBCSRGetKernel(R, &k) == 0);
  CHECK(k == MAT_BINBCSR_KERNEL_PORTABLE);
  MatDestroy(&A);
  MatDestroy(&B);
  MatDestroy(&R);
}
