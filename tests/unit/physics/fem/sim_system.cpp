// BlockSystem (src/sim/sim_system): COO blocks with duplicates, refill in place, the same
// solution for every Mat type, clear errors for bad input and for GPU types this PETSc lacks.
#include <catch2/catch.hpp>
#include <petscbinbcsr.h>

#include "sim/sim_system.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

// A 1D chain of n nodes, each element (i, i+1) listing its 4 blocks: a symmetric positive definite
// block-tridiagonal matrix whose diagonal blocks are sums of duplicates.
struct Chain {
  std::vector<PetscInt>    rows, cols;
  std::vector<PetscScalar> values;
};

Chain make_chain(PetscInt n, double scale)
{
  Chain c;
  for (PetscInt e = 0; e + 1 < n; ++e) {
    const PetscInt nodes[2] = {e, e + 1};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        c.rows.push_back(nodes[a]);
        c.cols.push_back(nodes[b]);
        for (int r = 0; r < 3; ++r)
          for (int q = 0; q < 3; ++q) {
            double v = 0;
            if (a == b) v = (r == q ? 2.0 : 0.1) * scale;
            else v = (r == q ? -0.5 : 0.0) * scale;
            c.values.push_back(v);
          }
      }
  }
  return c;
}

std::vector<PetscScalar> solve_with(const char *mat_type, const Chain &c, PetscInt n, PetscErrorCode *err)
{
  BlockSystem              sys;
  SolveStats               stats;
  std::vector<PetscScalar> rhs(3 * n), sol(3 * n, 0.0);
  for (PetscInt i = 0; i < 3 * n; ++i) rhs[i] = std::sin(0.7 * i) + 1.0;
  *err = PetscOptionsSetValue(nullptr, "-mat_type", mat_type);
  if (!*err) *err = PetscOptionsSetValue(nullptr, "-ksp_rtol", "1e-12");
  if (!*err) *err = BlockSystemCreate(PETSC_COMM_SELF, n, PETSC_DECIDE, c.rows, c.cols, &sys);
  PetscOptionsClearValue(nullptr, "-mat_type");
  PetscOptionsClearValue(nullptr, "-ksp_rtol");
  if (*err) return {};
  // Refill twice: the second fill must replace, not add to, the first.
  *err = BlockSystemSetValues(&sys, c.values.data());
  if (!*err) *err = BlockSystemSetValues(&sys, c.values.data());
  if (!*err) *err = BlockSystemSolve(&sys, rhs.data(), sol.data(), &stats);
  if (!*err) {
    CHECK(stats.reason > 0);
    CHECK(stats.iterations > 0);
  }
  BlockSystemDestroy(&sys);
  return sol;
}

// Reference: dense assembly of the same chain, A x checked against rhs.
double residual(const Chain &c, PetscInt n, const std::vector<PetscScalar> &x)
{
  std::vector<double> ax(3 * n, 0.0);
  for (size_t k = 0; k < c.rows.size(); ++k)
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) ax[3 * c.rows[k] + r] += c.values[9 * k + 3 * r + q] * x[3 * c.cols[k] + q];
  double m = 0;
  for (PetscInt i = 0; i < 3 * n; ++i) m = std::fmax(m, std::fabs(ax[i] - (std::sin(0.7 * i) + 1.0)));
  return m;
}

} // namespace

TEST_CASE("BlockSystem: same solution for aij, baij, sbaij and sell; duplicates summed; refill replaces",
          "[fem][sim_system]")
{
  const PetscInt n = 40;
  const Chain    c = make_chain(n, 3.0);
  PetscErrorCode err;
  const auto     ref = solve_with("aij", c, n, &err);
  REQUIRE(err == 0);
  CHECK(residual(c, n, ref) < 1e-9);
  for (const char *type : {"baij", "sbaij", "sell"}) {
    INFO(type);
    const auto x = solve_with(type, c, n, &err);
    REQUIRE(err == 0);
    for (PetscInt i = 0; i < 3 * n; ++i) CHECK(x[i] == Approx(ref[i]).epsilon(1e-9));
  }
}

TEST_CASE("BlockSystem: a GPU matrix type on this PETSc is a clear error", "[fem][sim_system]")
{
  const Chain    c = make_chain(4, 1.0);
  PetscErrorCode err;
  solve_with("aijcusparse", c, 4, &err);
#if !defined(PETSC_HAVE_CUDA)
  CHECK(err == PETSC_ERR_SUP);
#endif
}

TEST_CASE("BlockSystem: out-of-range block indices are rejected", "[fem][sim_system]")
{
  BlockSystem sys;
  CHECK(BlockSystemCreate(PETSC_COMM_SELF, 2, PETSC_DECIDE, {0, 2}, {0, 0}, &sys) ==
        PETSC_ERR_ARG_OUTOFRANGE);
  CHECK(BlockSystemCreate(PETSC_COMM_SELF, 2, PETSC_DECIDE, {0, 1}, {0}, &sys) == PETSC_ERR_ARG_SIZ);
}

TEST_CASE("BlockSystem: matrix dump loads back as the same aij matrix", "[fem][sim_system]")
{
  const PetscInt n = 6;
  const Chain    c = make_chain(n, 2.0);
  BlockSystem    sys;
  REQUIRE(BlockSystemCreate(PETSC_COMM_SELF, n, PETSC_DECIDE, c.rows, c.cols, &sys) == 0);
  REQUIRE(BlockSystemSetValues(&sys, c.values.data()) == 0);
  const std::string path = "sim_system_dump_test.bin";
  REQUIRE(BlockSystemDumpMatrix(&sys, path.c_str()) == 0);
  Mat         B;
  PetscViewer v;
  REQUIRE(PetscViewerBinaryOpen(PETSC_COMM_SELF, path.c_str(), FILE_MODE_READ, &v) == 0);
  REQUIRE(MatCreate(PETSC_COMM_SELF, &B) == 0);
  REQUIRE(MatSetType(B, MATAIJ) == 0);
  REQUIRE(MatLoad(B, v) == 0);
  PetscBool eq = PETSC_FALSE;
  REQUIRE(MatEqual(B, sys.A, &eq) == 0);
  CHECK(eq);
  PetscInt nnz = 0;
  REQUIRE(BlockSystemGetInfo(&sys, &nnz, nullptr, nullptr) == 0);
  CHECK(nnz == 9 * (n + 2 * (n - 1)));
  MatDestroy(&B);
  PetscViewerDestroy(&v);
  BlockSystemDestroy(&sys);
  std::remove(path.c_str());
  std::remove((path + ".info").c_str());
}

TEST_CASE(
  "BlockSystem with the binbcsr COO mirror: upper blocks give the whole matrix, lower ones are refused",
  "[fem][system]")
{
  const PetscInt n    = 12;
  const Chain    full = make_chain(n, 1.0);
  Chain          upper;
  for (size_t k = 0; k < full.rows.size(); ++k)
    if (full.rows[k] <= full.cols[k]) {
      upper.rows.push_back(full.rows[k]);
      upper.cols.push_back(full.cols[k]);
      upper.values.insert(upper.values.end(), full.values.begin() + 9 * k, full.values.begin() + 9 * k + 9);
    }
  PetscErrorCode err;
  PetscBool      upper_only = PETSC_FALSE, offrank_full = PETSC_TRUE, mirrored = PETSC_FALSE;
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_coo_mirror", "1") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_type", "binbcsr") == 0);
  err = BlockSystemStoredTriangle(PETSC_COMM_SELF, &upper_only, &offrank_full, nullptr, &mirrored);
  PetscOptionsClearValue(nullptr, "-mat_type");
  REQUIRE(err == 0);
  CHECK(!upper_only); // the whole matrix is stored ...
  CHECK(!offrank_full);
  CHECK(mirrored); // ... from the upper blocks
  const std::vector<PetscScalar> x = solve_with("binbcsr", upper, n, &err);
  REQUIRE(err == 0);
  CHECK(residual(full, n, x) < 1e-9);
  // a driver that lists both triangles would get its off-diagonal blocks twice: refused
  solve_with("binbcsr", full, n, &err);
  CHECK(err == PETSC_ERR_ARG_WRONG);
  PetscOptionsClearValue(nullptr, "-mat_binbcsr_coo_mirror");
}

TEST_CASE("BlockSystem: -initial_guess_scaled starts no further from b than zero or the guess",
          "[fem][sim_system][guess]")
{
  const PetscInt n = 20;
  const Chain    c = make_chain(n, 1.0);
  // A x of the chain, densely (the reference).
  const auto apply = [&](const std::vector<double> &x) {
    std::vector<double> ax(3 * n, 0.0);
    for (size_t k = 0; k < c.rows.size(); ++k)
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q)
          ax[3 * c.rows[k] + r] += c.values[9 * k + 3 * r + q] * x[3 * c.cols[k] + q];
    return ax;
  };
  std::vector<double> rhs(3 * n);
  for (PetscInt i = 0; i < 3 * n; ++i) rhs[i] = std::sin(0.7 * i) + 1.0;
  const auto norm_residual = [&](const std::vector<double> &x) {
    const std::vector<double> ax = apply(x);
    double                    s  = 0;
    for (PetscInt i = 0; i < 3 * n; ++i) s += (rhs[i] - ax[i]) * (rhs[i] - ax[i]);
    return std::sqrt(s);
  };
  double norm_b = 0;
  for (double v : rhs) norm_b += v * v;
  norm_b = std::sqrt(norm_b);
  REQUIRE(PetscOptionsSetValue(nullptr, "-ksp_initial_guess_nonzero", "1") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-ksp_rtol", "1e-12") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-initial_guess_scaled", "1") == 0);
  for (const char *mat_type : {"aij", "binbcsr"}) {
    REQUIRE(PetscOptionsSetValue(nullptr, "-mat_type", mat_type) == 0);
    BlockSystem sys;
    REQUIRE(BlockSystemCreate(PETSC_COMM_SELF, n, PETSC_DECIDE, c.rows, c.cols, &sys) == 0);
    REQUIRE(BlockSystemSetValues(&sys, c.values.data()) == 0);
    // a guess far off (the wrong sign, too large), a fair one, and zero
    for (double kind : {-3.0, 0.5, 0.0}) {
      CAPTURE(mat_type, kind);
      std::vector<double> guess(3 * n);
      for (PetscInt i = 0; i < 3 * n; ++i) guess[i] = kind * (0.6 + 0.1 * std::cos(1.3 * i));
      const std::vector<double> ag = apply(guess);
      double                    bx = 0, xx = 0;
      for (PetscInt i = 0; i < 3 * n; ++i) bx += rhs[i] * ag[i], xx += ag[i] * ag[i];
      const double        a = xx > 0 ? bx / xx : 0; // the minimiser of ||b - a A x||
      std::vector<double> scaled(3 * n), sol = guess;
      for (PetscInt i = 0; i < 3 * n; ++i) scaled[i] = a * guess[i];
      CHECK(norm_residual(scaled) <= norm_b * (1 + 1e-14));
      CHECK(norm_residual(scaled) <= norm_residual(guess) * (1 + 1e-14));
      SolveStats stats;
      REQUIRE(BlockSystemSolve(&sys, rhs.data(), sol.data(), &stats) == 0);
      CHECK(stats.guess_scale == Approx(a).margin(1e-14)); // the solve started from a x
      CHECK(stats.reason > 0);
      CHECK(norm_residual(sol) <= 1e-10 * norm_b);
    }
    BlockSystemDestroy(&sys);
  }
  for (const char *o : {"-mat_type", "-ksp_initial_guess_nonzero", "-ksp_rtol", "-initial_guess_scaled"})
    PetscOptionsClearValue(nullptr, o);
}
