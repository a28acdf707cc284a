// The benchmark matrix and the bandwidth reference that spmv_bench and the solver benchmarks share.
#include <catch2/catch.hpp>
#include <petscmat.h>

#include "sim/bench_util.h"
#include "sim/stencil.h"
#include "sim/stream.h"

#include <cmath>
#include <fstream>
#include <vector>

namespace {

Mat Stencil(const StencilGrid &g, MatType type)
{
  Mat A = nullptr;
  REQUIRE(CreateStencilMatrix(PETSC_COMM_WORLD, g, type, nullptr, &A) == 0);
  return A;
}

// || A x - B x ||_inf for a deterministic x.
double MultDifference(Mat A, Mat B)
{
  Vec x, ya, yb;
  REQUIRE(MatCreateVecs(A, &x, &ya) == 0);
  REQUIRE(VecDuplicate(ya, &yb) == 0);
  PetscInt lo, hi;
  REQUIRE(VecGetOwnershipRange(x, &lo, &hi) == 0);
  for (PetscInt i = lo; i < hi; ++i) REQUIRE(VecSetValue(x, i, std::sin(0.37 * i) + 0.1, INSERT_VALUES) == 0);
  REQUIRE(VecAssemblyBegin(x) == 0);
  REQUIRE(VecAssemblyEnd(x) == 0);
  REQUIRE(MatMult(A, x, ya) == 0);
  REQUIRE(MatMult(B, x, yb) == 0);
  REQUIRE(VecAXPY(yb, -1.0, ya) == 0);
  PetscReal d;
  REQUIRE(VecNorm(yb, NORM_INFINITY, &d) == 0);
  VecDestroy(&x);
  VecDestroy(&ya);
  VecDestroy(&yb);
  return d;
}

} // namespace

TEST_CASE("stencil block rows: counts, symmetry, strict diagonal dominance", "[bench][stencil]")
{
  StencilGrid g;
  g.nx = 4;
  g.ny = 3;
  g.nz = 5;
  PetscInt    cols[27], ncols;
  PetscScalar vals[27 * 9];
  // Corner, edge, face and interior nodes have 8, 12, 18, 27 blocks.
  StencilBlockRow(g, 0, &ncols, cols, vals);
  CHECK(ncols == 8);
  StencilBlockRow(g, 1, &ncols, cols, vals);
  CHECK(ncols == 12);
  StencilBlockRow(g, 1 + 4 * 1, &ncols, cols, vals);
  CHECK(ncols == 18);
  StencilBlockRow(g, 1 + 4 * (1 + 3 * 1), &ncols, cols, vals);
  CHECK(ncols == 27);

  for (PetscInt node = 0; node < g.nodes(); ++node) {
    StencilBlockRow(g, node, &ncols, cols, vals);
    for (PetscInt c = 1; c < ncols; ++c) REQUIRE(cols[c] > cols[c - 1]);
    for (int a = 0; a < 3; ++a) {
      double diag = 0, off = 0;
      for (PetscInt c = 0; c < ncols; ++c)
        for (int b = 0; b < 3; ++b) {
          const double v = PetscRealPart(vals[a * 3 * ncols + 3 * c + b]);
          if (cols[c] == node && a == b) diag = v;
          else off += std::fabs(v);
        }
      REQUIRE(diag > off);
      // The margin is exactly shift * c_p, c_p in [1, 1.5] (up to rounding of the sum).
      REQUIRE(diag - off >= g.shift * (1 - 1e-9));
      REQUIRE(diag - off <= 1.5 * g.shift * (1 + 1e-9));
    }
    // Block (node, q) equals block (q, node) transposed.
    for (PetscInt c = 0; c < ncols; ++c) {
      PetscInt    ncols_q, cols_q[27];
      PetscScalar vals_q[27 * 9];
      StencilBlockRow(g, cols[c], &ncols_q, cols_q, vals_q);
      PetscInt back = -1;
      for (PetscInt e = 0; e < ncols_q; ++e)
        if (cols_q[e] == node) back = e;
      REQUIRE(back >= 0);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          REQUIRE(vals[a * 3 * ncols + 3 * c + b] == vals_q[b * 3 * ncols_q + 3 * back + a]);
    }
  }
}

TEST_CASE("stencil matrix: same operator in aij, baij, sbaij, sell", "[bench][stencil]")
{
  StencilGrid g;
  g.nx         = 5;
  g.ny         = 4;
  g.nz         = 3;
  Mat      aij = Stencil(g, MATAIJ);
  PetscInt m, n, bs;
  REQUIRE(MatGetSize(aij, &m, &n) == 0);
  CHECK(m == 3 * 60);
  CHECK(n == 3 * 60);
  REQUIRE(MatGetBlockSize(aij, &bs) == 0);
  CHECK(bs == 3);
  MatInfo info;
  REQUIRE(MatGetInfo(aij, MAT_GLOBAL_SUM, &info) == 0);
  // nnz = 9 * (product over directions of (3 n - 2)).
  CHECK(info.nz_used == Approx(9.0 * (3 * 5 - 2) * (3 * 4 - 2) * (3 * 3 - 2)));
  PetscBool symmetric = PETSC_FALSE;
  REQUIRE(MatIsSymmetric(aij, 0.0, &symmetric) == 0);
  CHECK(symmetric);

  for (MatType t : {MATBAIJ, MATSBAIJ, MATSELL}) {
    Mat B = Stencil(g, t);
    CHECK(MultDifference(aij, B) < 1e-12);
    MatDestroy(&B);
  }
  MatDestroy(&aij);
}

TEST_CASE("stencil matrix: type from the options, bad grids refused", "[bench][stencil]")
{
  StencilGrid g;
  g.nx = g.ny = g.nz = 3;
  REQUIRE(PetscOptionsSetValue(nullptr, "-bt_mat_type", "baij") == 0);
  Mat A = nullptr;
  REQUIRE(CreateStencilMatrix(PETSC_COMM_WORLD, g, nullptr, "bt_", &A) == 0);
  PetscBool isbaij = PETSC_FALSE;
  REQUIRE(PetscObjectTypeCompareAny((PetscObject)A, &isbaij, MATSEQBAIJ, MATMPIBAIJ, "") == 0);
  CHECK(isbaij);
  MatDestroy(&A);
  REQUIRE(PetscOptionsClearValue(nullptr, "-bt_mat_type") == 0);

  g.ny    = 0;
  Mat bad = nullptr;
  CHECK(CreateStencilMatrix(PETSC_COMM_WORLD, g, MATAIJ, nullptr, &bad) != 0);
  g.ny    = 3;
  g.shift = 0;
  CHECK(CreateStencilMatrix(PETSC_COMM_WORLD, g, MATAIJ, nullptr, &bad) != 0);
}

TEST_CASE("stream triad reports a plausible bandwidth", "[bench][stream]")
{
  StreamResult r;
  REQUIRE(MeasureStreamTriad(PETSC_COMM_WORLD, 1 << 20, 3, &r) == 0);
  CHECK(r.best_GBs > 0.1);
  CHECK(r.best_GBs < 10000);
  CHECK(r.median_GBs <= r.best_GBs);
  CHECK(r.elements_per_rank == (1 << 20));
}

TEST_CASE("the last-level cache is read from sysfs or not claimed", "[bench][stream]")
{
  // Some virtual machines have no /sys/devices/system/cpu/cpu0/cache (a Zen 5 EPYC VM, whose CPUID
  // cache leaves are empty too): the size is then 0, "not claimed", never a guess.
  std::ifstream size_file("/sys/devices/system/cpu/cpu0/cache/index0/size");
  if (size_file.good()) CHECK(LastLevelCacheBytes() > 0);
  else CHECK(LastLevelCacheBytes() == 0);
}

TEST_CASE("the benchmarks' single and symmetric copies take the -mat_binbcsr_* options", "[bench][stencil]")
{
  // The copies were once built without the options: a bin width or stream count given to spmv_bench
  // applied to its binbcsr matrix but not to binbcsr_single or the _sym formats.
  StencilGrid g;
  g.nx = g.ny = g.nz = 4;
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_bin_width", "16") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_streams", "2") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_precision", "double") == 0);
  for (PetscBool sym : {PETSC_FALSE, PETSC_TRUE}) {
    Mat A = Stencil(g, MATAIJ), ref = Stencil(g, MATAIJ);
    REQUIRE(ReplaceWithBinBCSR(&A, sym, MAT_BINBCSR_PRECISION_SINGLE) == 0);
    PetscInt            bw = 0, streams = 0;
    PetscBool           stored_sym = PETSC_FALSE;
    MatBinBCSRPrecision p;
    REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
    REQUIRE(MatBinBCSRGetStreams(A, &streams) == 0);
    REQUIRE(MatBinBCSRGetPrecision(A, &p) == 0);
    REQUIRE(MatBinBCSRGetSymmetricStorage(A, &stored_sym) == 0);
    CHECK(bw == 16);
    CHECK(streams == 2);
    CHECK(p == MAT_BINBCSR_PRECISION_SINGLE); // the copy's own precision wins over the option
    CHECK(stored_sym == sym);
    CHECK(MultDifference(ref, A) < 1e-5 * 26);
    MatDestroy(&A);
    MatDestroy(&ref);
  }
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_bin_width") == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_streams") == 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_precision") == 0);
}
