// MatSOR of MATSEQBINBCSR (whole and symmetric storage, bs 1, 2, 3, double and single values) against
// a dense block-SOR reference computed here, against seqaij's MatSOR for bs 1, through PCSOR in CG,
// and its errors.
#include "support_sym.hpp"
#include <algorithm>
#include <petscksp.h>

using namespace mat_sym;

namespace {

// x_r += omega (D_r + shift I)^-1 (b_r - (A x)_r - shift x_r), rows in sweep order, on the dense matrix.
std::vector<double> reference_sor(const Pattern &p, const std::vector<double> &b, std::vector<double> x,
                                  double omega, double shift, int flag, int sweeps)
{
  const std::vector<PetscScalar> A = dense(p);
  const PetscInt                 n = p.m, bs = p.bs, mbs = n / bs;
  const bool                     fwd = flag & (SOR_FORWARD_SWEEP | SOR_LOCAL_FORWARD_SWEEP),
             bwd                     = flag & (SOR_BACKWARD_SWEEP | SOR_LOCAL_BACKWARD_SWEEP);
  if (flag & SOR_ZERO_INITIAL_GUESS) std::fill(x.begin(), x.end(), 0.0);
  auto update = [&](PetscInt r) {
    std::vector<double> D(bs * bs), res(bs);
    for (PetscInt i = 0; i < bs; i++) {
      double s = b[r * bs + i] - shift * x[r * bs + i];
      for (PetscInt j = 0; j < n; j++) s -= A[(size_t)(r * bs + i) * n + j] * x[j];
      res[i] = s;
      for (PetscInt j = 0; j < bs; j++)
        D[i * bs + j] = A[(size_t)(r * bs + i) * n + r * bs + j] + (i == j ? shift : 0.0);
    }
    for (PetscInt c = 0; c < bs; c++) { // Gaussian elimination with partial pivoting: D d = res
      PetscInt piv = c;
      for (PetscInt i = c + 1; i < bs; i++)
        if (std::fabs(D[i * bs + c]) > std::fabs(D[piv * bs + c])) piv = i;
      for (PetscInt j = 0; j < bs; j++) std::swap(D[c * bs + j], D[piv * bs + j]);
      std::swap(res[c], res[piv]);
      for (PetscInt i = c + 1; i < bs; i++) {
        const double f = D[i * bs + c] / D[c * bs + c];
        for (PetscInt j = c; j < bs; j++) D[i * bs + j] -= f * D[c * bs + j];
        res[i] -= f * res[c];
      }
    }
    for (PetscInt i = bs - 1; i >= 0; i--) {
      double s = res[i];
      for (PetscInt j = i + 1; j < bs; j++) s -= D[i * bs + j] * res[j];
      res[i] = s / D[i * bs + i];
    }
    for (PetscInt i = 0; i < bs; i++) x[r * bs + i] += omega * res[i];
  };
  for (int it = 0; it < sweeps; it++) {
    if (fwd)
      for (PetscInt r = 0; r < mbs; r++) update(r);
    if (bwd)
      for (PetscInt r = mbs - 1; r >= 0; r--) update(r);
  }
  return x;
}

Pattern rounded_to_float(Pattern p)
{
  for (Entry &e : p.entries) e.v = (double)(float)e.v;
  return p;
}

std::vector<PetscScalar> run_sor(Mat A, Vec b, const std::vector<double> &x0, double omega, double shift,
                                 int flag, PetscInt its, PetscInt lits)
{
  Vec x;
  REQUIRE(VecDuplicate(b, &x) == 0);
  PetscScalar *xa;
  REQUIRE(VecGetArray(x, &xa) == 0);
  std::copy(x0.begin(), x0.end(), xa);
  REQUIRE(VecRestoreArray(x, &xa) == 0);
  REQUIRE(MatSOR(A, b, omega, (MatSORType)flag, shift, its, lits, x) == 0);
  std::vector<PetscScalar> out = values(x);
  VecDestroy(&x);
  return out;
}

void check_near(const std::vector<PetscScalar> &got, const std::vector<double> &ref, double rel)
{
  REQUIRE(got.size() == ref.size());
  double scale = 0;
  for (double v : ref) scale = std::max(scale, std::fabs(v));
  size_t bad = 0;
  for (size_t i = 0; i < got.size(); i++)
    if (!(std::fabs(got[i] - ref[i]) <= rel * (scale + 1e-300))) {
      if (bad < 5) UNSCOPED_INFO("entry " << i << ": got " << got[i] << " ref " << ref[i]);
      bad++;
    }
  CHECK(bad == 0);
}

} // namespace

TEST_CASE(
  "MatSOR: binbcsr sweeps equal dense block SOR (whole/symmetric storage, bs 1/2/3, omega, shift, flags)",
  "[mat_sym][sor]")
{
  const Pattern cases[] = {fem_pattern(4, 3, 5, 3), fem_pattern(5, 4, 3, 1), fem_pattern(3, 3, 3, 2),
                           end_rows_pattern(21, 3)};
  const int     flags[] = {SOR_FORWARD_SWEEP | SOR_ZERO_INITIAL_GUESS,
                           SOR_BACKWARD_SWEEP,
                           SOR_BACKWARD_SWEEP | SOR_ZERO_INITIAL_GUESS,
                           SOR_FORWARD_SWEEP,
                           SOR_SYMMETRIC_SWEEP,
                           SOR_LOCAL_SYMMETRIC_SWEEP | SOR_ZERO_INITIAL_GUESS};
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    for (MatBinBCSRPrecision prec : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE}) {
      const Pattern &p  = cases[c];
      const Pattern  pr = prec == MAT_BINBCSR_PRECISION_SINGLE ? rounded_to_float(p) : p; // what is stored
      Vec            b  = make_vec(p.m, 7 + (unsigned)c);
      const auto     bv = values(b);
      std::vector<double> x0(p.m);
      for (PetscInt i = 0; i < p.m; i++) x0[i] = 0.1 * std::sin(1.0 + i);
      for (bool sym : {false, true})
        for (PetscInt bw : {4, 8, 16}) { // 3x3 blocks: each width has its own compiled sweep
          Mat A = build_sym(p, bw, prec, sym);
          for (double omega : {1.0, 1.4})
            for (double shift : {0.0, 0.3})
              for (int flag : flags) {
                INFO("case " << c << " precision " << (int)prec << " symmetric " << sym << " bw " << bw
                             << " omega " << omega << " shift " << shift << " flag " << flag);
                // its x lits sweeps in all (a sequential matrix has no outer/inner distinction)
                check_near(run_sor(A, b, x0, omega, shift, flag, 2, 1),
                           reference_sor(pr, bv, x0, omega, shift, flag, 2), 1e-12);
                check_near(run_sor(A, b, x0, omega, shift, flag, 1, 3),
                           reference_sor(pr, bv, x0, omega, shift, flag, 3), 1e-12);
              }
          // new values (a new object state) invert the diagonal again
          REQUIRE(MatScale(A, 2.0) == 0);
          Pattern p2 = pr;
          for (Entry &e : p2.entries) e.v *= 2.0;
          check_near(run_sor(A, b, x0, 1.2, 0.0, SOR_SYMMETRIC_SWEEP, 1, 1),
                     reference_sor(p2, bv, x0, 1.2, 0.0, SOR_SYMMETRIC_SWEEP, 1), 1e-12);
          MatDestroy(&A);
        }
      VecDestroy(&b);
    }
  }
}

TEST_CASE("MatSOR: bs 1 binbcsr equals seqaij's MatSOR", "[mat_sym][sor]")
{
  const Pattern p   = fem_pattern(5, 4, 3, 1);
  Mat           aij = build(p, MATSEQAIJ), bin = build_sym(p, 8, MAT_BINBCSR_PRECISION_DOUBLE, false),
      sym               = build_sym(p, 8, MAT_BINBCSR_PRECISION_DOUBLE, true);
  Vec                 b = make_vec(p.m, 3);
  std::vector<double> x0(p.m, 0.25);
  for (double omega : {1.0, 0.8, 1.5})
    for (double shift : {0.0, 1.0})
      for (int flag : {(int)SOR_FORWARD_SWEEP, SOR_BACKWARD_SWEEP | SOR_ZERO_INITIAL_GUESS,
                       (int)SOR_SYMMETRIC_SWEEP, SOR_LOCAL_SYMMETRIC_SWEEP | SOR_ZERO_INITIAL_GUESS}) {
        INFO("omega " << omega << " shift " << shift << " flag " << flag);
        const auto ref = run_sor(aij, b, x0, omega, shift, flag, 2, 1);
        check_near(run_sor(bin, b, x0, omega, shift, flag, 2, 1), ref, 1e-12);
        check_near(run_sor(sym, b, x0, omega, shift, flag, 2, 1), ref, 1e-12);
      }
  MatDestroy(&aij);
  MatDestroy(&bin);
  MatDestroy(&sym);
  VecDestroy(&b);
}

TEST_CASE(
  "PCSOR (SSOR) in CG: binbcsr takes the iterations of aij (bs 1) and of itself in both storages (bs 3)",
  "[mat_sym][sor]")
{
  auto solve = [](Mat A, Vec b, PetscInt *its, KSPConvergedReason *reason) {
    KSP ksp;
    PC  pc;
    Vec x;
    REQUIRE(VecDuplicate(b, &x) == 0);
    REQUIRE(KSPCreate(PETSC_COMM_SELF, &ksp) == 0);
    REQUIRE(KSPSetOperators(ksp, A, A) == 0);
    REQUIRE(KSPSetType(ksp, KSPCG) == 0);
    REQUIRE(KSPGetPC(ksp, &pc) == 0);
    REQUIRE(PCSetType(pc, PCSOR) == 0);
    REQUIRE(PCSORSetSymmetric(pc, SOR_SYMMETRIC_SWEEP) == 0);
    REQUIRE(KSPSetTolerances(ksp, 1e-10, PETSC_DEFAULT, PETSC_DEFAULT, 500) == 0);
    REQUIRE(KSPSolve(ksp, b, x) == 0);
    REQUIRE(KSPGetIterationNumber(ksp, its) == 0);
    REQUIRE(KSPGetConvergedReason(ksp, reason) == 0);
    std::vector<PetscScalar> out = values(x);
    KSPDestroy(&ksp);
    VecDestroy(&x);
    return out;
  };
  for (PetscInt bs : {1, 3}) {
    INFO("bs " << bs);
    const Pattern p   = fem_pattern(6, 5, 4, bs);
    Mat           ref = bs == 1 ? build(p, MATSEQAIJ) : build_sym(p, 8, MAT_BINBCSR_PRECISION_DOUBLE, false);
    Mat           sym = build_sym(p, 8, MAT_BINBCSR_PRECISION_DOUBLE, true),
        whole         = build_sym(p, 4, MAT_BINBCSR_PRECISION_DOUBLE, false);
    Vec                b = make_vec(p.m, 5);
    PetscInt           its_ref, its_sym, its_whole;
    KSPConvergedReason r_ref, r_sym, r_whole;
    const auto         x_ref = solve(ref, b, &its_ref, &r_ref);
    check_near(solve(sym, b, &its_sym, &r_sym), x_ref, 1e-8);
    check_near(solve(whole, b, &its_whole, &r_whole), x_ref, 1e-8);
    CHECK(r_ref > 0);
    CHECK(r_sym > 0);
    CHECK(r_whole > 0);
    CHECK(its_sym == its_ref);
    CHECK(its_whole == its_ref);
    MatDestroy(&ref);
    MatDestroy(&sym);
    MatDestroy(&whole);
    VecDestroy(&b);
  }
}

TEST_CASE("MatSOR errors: apply lower, mixed apply upper, a singular diagonal block, no sweep",
          "[mat_sym][sor]")
{
  Pattern p = fem_pattern(3, 3, 2, 3);
  Mat     A = build_sym(p, 4, MAT_BINBCSR_PRECISION_DOUBLE, true);
  Vec     b = make_vec(p.m, 1), x;
  REQUIRE(VecDuplicate(b, &x) == 0);
  // (Eisenstat and SOR_APPLY_UPPER work: tests/unit/mat_binbcsr/pc/eisenstat_test.cpp)
  CHECK(MatSOR(A, b, 1.0, SOR_APPLY_LOWER, 0.0, 1, 1, x) == PETSC_ERR_SUP);
  CHECK(MatSOR(A, b, 1.0, (MatSORType)(SOR_APPLY_UPPER | SOR_FORWARD_SWEEP), 0.0, 1, 1, x) ==
        PETSC_ERR_ARG_WRONG);
  CHECK(MatSOR(A, b, 1.0, SOR_ZERO_INITIAL_GUESS, 0.0, 1, 1, x) == PETSC_ERR_ARG_WRONG);
  // block row 4's diagonal block made singular: (60, .5/(1+i+j)) -> its first column zeroed
  for (PetscInt i = 0; i < 3; i++) REQUIRE(MatSetValue(A, 4 * 3 + i, 4 * 3 + 0, 0.0, INSERT_VALUES) == 0);
  for (PetscInt j = 0; j < 3; j++) REQUIRE(MatSetValue(A, 4 * 3 + 0, 4 * 3 + j, 0.0, INSERT_VALUES) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  CHECK(MatSOR(A, b, 1.0, SOR_SYMMETRIC_SWEEP, 0.0, 1, 1, x) == PETSC_ERR_MAT_LU_ZRPVT);
  CHECK(MatSOR(A, b, 1.0, SOR_EISENSTAT, 0.0, 1, 1, x) == PETSC_ERR_MAT_LU_ZRPVT);
  // a shift that makes it regular again is accepted
  CHECK(MatSOR(A, b, 1.0, SOR_SYMMETRIC_SWEEP, 1.0, 1, 1, x) == 0);
  MatDestroy(&A);
  VecDestroy(&b);
  VecDestroy(&x);
}
