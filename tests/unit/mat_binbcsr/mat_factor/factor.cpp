// MATSEQBINBCSR factorisations (src/mat_binbcsr/seq/binbcsr_factor.cpp): ICC/Cholesky through a seqsbaij
// shadow, ILU/LU through a seqbaij one. The factor must be PETSc's own, so the reference is the same PC
// on seqsbaij/seqbaij built from the same entries: same iteration counts, same solution to rounding,
// and the residual checked against the binbcsr matrix itself. Written for any communicator size: the
// serial cases run on PETSC_COMM_SELF, the block-Jacobi case on PETSC_COMM_WORLD (CTest runs this
// program on 1 and 2 ranks).
#include "support/mat_support.hpp"
#include <petscksp.h>
#include <cstring>

using namespace mat_core;

namespace {

struct Solution {
  PetscInt                 its    = -1;
  KSPConvergedReason       reason = KSP_CONVERGED_ITERATING;
  std::vector<PetscScalar> x;
  double                   relres = -1; // ||b - A x|| / ||b|| with the matrix that was solved
};

// A seqbinbcsr from the pattern, with or without symmetric (upper) storage and in either precision.
Mat build_bin(const Pattern &p, bool sym, MatBinBCSRPrecision prec = MAT_BINBCSR_PRECISION_DOUBLE)
{
  Mat A = nullptr;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, p.bs) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  REQUIRE(MatBinBCSRSetPrecision(A, prec) == 0);
  if (sym) REQUIRE(MatBinBCSRSetSymmetricStorage(A, PETSC_TRUE) == 0);
  REQUIRE(MatSetUp(A) == 0);
  for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  return A;
}

Mat build_sbaij(const Pattern &p)
{
  Mat B = build(p, MATSEQBAIJ), S = nullptr;
  REQUIRE(MatConvert(B, MATSEQSBAIJ, MAT_INITIAL_MATRIX, &S) == 0);
  REQUIRE(MatDestroy(&B) == 0);
  return S;
}

double relative_residual(Mat A, Vec b, Vec x)
{
  Vec       r;
  PetscReal nr, nb;
  REQUIRE(VecDuplicate(b, &r) == 0);
  REQUIRE(MatMult(A, x, r) == 0);
  REQUIRE(VecAYPX(r, -1.0, b) == 0);
  REQUIRE(VecNorm(r, NORM_2, &nr) == 0);
  REQUIRE(VecNorm(b, NORM_2, &nb) == 0);
  REQUIRE(VecDestroy(&r) == 0);
  return nr / nb;
}

// One solve with an existing KSP (so a second call refactors the changed matrix).
Solution solve_with(KSP ksp, Mat A, Vec b)
{
  Solution s;
  Vec      x;
  REQUIRE(VecDuplicate(b, &x) == 0);
  REQUIRE(KSPSetOperators(ksp, A, A) == 0);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  REQUIRE(KSPGetIterationNumber(ksp, &s.its) == 0);
  REQUIRE(KSPGetConvergedReason(ksp, &s.reason) == 0);
  s.relres = relative_residual(A, b, x);
  PetscInt           n;
  const PetscScalar *xa;
  REQUIRE(VecGetLocalSize(x, &n) == 0);
  REQUIRE(VecGetArrayRead(x, &xa) == 0);
  s.x.assign(xa, xa + n);
  REQUIRE(VecRestoreArrayRead(x, &xa) == 0);
  REQUIRE(VecDestroy(&x) == 0);
  return s;
}

KSP make_ksp(MPI_Comm comm, KSPType type, PCType pc, double rtol)
{
  KSP k;
  PC  p;
  REQUIRE(KSPCreate(comm, &k) == 0);
  REQUIRE(KSPSetType(k, type) == 0);
  REQUIRE(KSPGetPC(k, &p) == 0);
  REQUIRE(PCSetType(p, pc) == 0);
  REQUIRE(KSPSetTolerances(k, rtol, 1e-50, PETSC_DEFAULT, 500) == 0);
  return k;
}

Solution solve(Mat A, KSPType type, PCType pc, Vec b, double rtol = 1e-10)
{
  KSP      k = make_ksp(PetscObjectComm((PetscObject)A), type, pc, rtol);
  Solution s = solve_with(k, A, b);
  REQUIRE(KSPDestroy(&k) == 0);
  return s;
}

void check_same(const Solution &got, const Solution &ref, double rtol)
{
  REQUIRE(got.reason > 0);
  REQUIRE(ref.reason > 0);
  CHECK(got.its == ref.its);
  CHECK(got.relres < rtol);
  REQUIRE(got.x.size() == ref.x.size());
  double diff = 0, norm = 0;
  for (size_t i = 0; i < got.x.size(); i++) {
    diff = std::max(diff, std::abs(got.x[i] - ref.x[i]));
    norm = std::max(norm, std::abs(ref.x[i]));
  }
  // the same factor and the same Krylov steps; the products differ in summation order only
  CHECK(diff <= 1e-8 * norm);
}

} // namespace

TEST_CASE("ICC, Cholesky, ILU and LU on binbcsr equal PETSc's on seqsbaij/seqbaij", "[mat_factor]")
{
  for (PetscInt bs : {1, 2, 3}) // 2: the generic block-size path of the copy
    for (bool sym : {false, true}) {
      CAPTURE(bs, sym);
      const Pattern p    = fem_pattern(5, 4, 3, bs);
      Mat           A    = build_bin(p, sym);
      Mat           Aref = build(p, MATSEQBAIJ);
      Mat           Sref = build_sbaij(p);
      Vec           b    = make_vec(p.m, 7);

      check_same(solve(A, KSPCG, PCICC, b), solve(Sref, KSPCG, PCICC, b), 1e-10);
      check_same(solve(A, KSPGMRES, PCILU, b), solve(Aref, KSPGMRES, PCILU, b), 1e-10);
      // direct: one application of the factor solves the system
      const Solution chol = solve(A, KSPPREONLY, PCCHOLESKY, b);
      CHECK(chol.relres < 1e-13);
      const Solution lu = solve(A, KSPPREONLY, PCLU, b);
      CHECK(lu.relres < 1e-13);
      // IC(0) is not exact on a 3-D stencil (this diagonally dominant one takes 3-4 iterations to 1e-10),
      // so the equal iteration counts above compare real Krylov runs
      CHECK(solve(A, KSPCG, PCICC, b).its >= 3);

      REQUIRE(VecDestroy(&b) == 0);
      REQUIRE(MatDestroy(&A) == 0);
      REQUIRE(MatDestroy(&Aref) == 0);
      REQUIRE(MatDestroy(&Sref) == 0);
    }
}

namespace {
// A factorisation through PCFactor with an ordering (nullptr: the factor's preferred one) and fill
// levels (ILU/ICC; 0: PETSc's default); LU and Cholesky are direct solves (preonly), ILU and ICC
// precondition GMRES. Returns the solution and the factor's stored nonzeros, which show which ordering
// was applied.
Solution factor_solve(Mat A, PCType pc, const char *ordering, Vec b, double *factor_nz, PetscInt levels = 0)
{
  const bool direct = !strcmp(pc, PCLU) || !strcmp(pc, PCCHOLESKY);
  KSP        k      = make_ksp(PETSC_COMM_SELF, direct ? KSPPREONLY : KSPGMRES, pc, 1e-10);
  PC         p;
  REQUIRE(KSPGetPC(k, &p) == 0);
  if (ordering) REQUIRE(PCFactorSetMatOrderingType(p, ordering) == 0);
  if (levels) REQUIRE(PCFactorSetLevels(p, levels) == 0);
  Solution s = solve_with(k, A, b);
  Mat      F;
  MatInfo  info;
  REQUIRE(PCFactorGetMatrix(p, &F) == 0);
  REQUIRE(MatGetInfo(F, MAT_LOCAL, &info) == 0);
  *factor_nz = info.nz_used;
  REQUIRE(KSPDestroy(&k) == 0);
  return s;
}
} // namespace

TEST_CASE("LU and ILU take PETSc's orderings as seqbaij does; LU defaults to nested dissection",
          "[mat_factor]")
{
  for (PetscInt bs : {1, 3})
    for (bool sym : {false, true}) {
      const Pattern p    = fem_pattern(6, 5, 4, bs);
      Mat           A    = build_bin(p, sym);
      Mat           Aref = build(p, MATSEQBAIJ);
      Vec           b    = make_vec(p.m, 11);
      for (const char *ordering : {(const char *)nullptr, MATORDERINGNATURAL, MATORDERINGND, MATORDERINGRCM,
                                   MATORDERINGQMD, MATORDERING1WD}) {
        CAPTURE(bs, sym, ordering ? ordering : "default");
        double         nz = 0, nzref = 0;
        const Solution lu    = factor_solve(A, PCLU, ordering, b, &nz),
                       luref = factor_solve(Aref, PCLU, ordering, b, &nzref);
        CHECK(lu.relres < 1e-13);
        CHECK(nz == nzref); // the same ordering gives the same fill
        check_same(lu, luref, 1e-13);
        const Solution ilu    = factor_solve(A, PCILU, ordering, b, &nz),
                       iluref = factor_solve(Aref, PCILU, ordering, b, &nzref);
        CHECK(nz == nzref);
        check_same(ilu, iluref, 1e-10);
      }
      // nested dissection by default: less fill than the natural order on this 3-D mesh
      double nz_default = 0, nz_natural = 0;
      factor_solve(A, PCLU, nullptr, b, &nz_default);
      factor_solve(A, PCLU, MATORDERINGNATURAL, b, &nz_natural);
      CHECK(nz_default < 0.9 * nz_natural);
      REQUIRE(VecDestroy(&b) == 0);
      REQUIRE(MatDestroy(&A) == 0);
      REQUIRE(MatDestroy(&Aref) == 0);
    }
}

namespace {
// The pattern renumbered by a block permutation (new block row i is old block row perm[i]), and a
// vector moved the same way: the reference for a factorisation in that ordering is the one of the
// renumbered matrix in natural order.
Pattern permuted(const Pattern &p, const std::vector<PetscInt> &perm)
{
  std::vector<PetscInt> iperm(perm.size());
  for (size_t i = 0; i < perm.size(); i++) iperm[perm[i]] = (PetscInt)i;
  Pattern q = p;
  for (Entry &e : q.entries) {
    e.i = iperm[e.i / p.bs] * p.bs + e.i % p.bs;
    e.j = iperm[e.j / p.bs] * p.bs + e.j % p.bs;
  }
  return q;
}

std::vector<PetscScalar> permuted(const std::vector<PetscScalar> &x, const std::vector<PetscInt> &perm,
                                  PetscInt bs)
{
  std::vector<PetscScalar> y(x.size());
  for (size_t i = 0; i < perm.size(); i++)
    for (PetscInt d = 0; d < bs; d++) y[i * bs + d] = x[perm[i] * bs + d];
  return y;
}

std::vector<PetscInt> block_ordering(Mat A, const char *ordering)
{
  IS              rp, cp;
  const PetscInt *idx;
  PetscInt        n;
  REQUIRE(MatGetOrdering(A, ordering, &rp, &cp) == 0);
  REQUIRE(ISGetLocalSize(rp, &n) == 0);
  REQUIRE(ISGetIndices(rp, &idx) == 0);
  std::vector<PetscInt> perm(idx, idx + n);
  REQUIRE(ISRestoreIndices(rp, &idx) == 0);
  REQUIRE(ISDestroy(&rp) == 0);
  REQUIRE(ISDestroy(&cp) == 0);
  return perm;
}

} // namespace

TEST_CASE(
  "ICC and Cholesky take PETSc's orderings (the permuted matrix factored); Cholesky defaults to nested dissection",
  "[mat_factor]")
{
  for (PetscInt bs : {1, 3})
    for (bool sym : {false, true}) {
      const Pattern p = fem_pattern(6, 5, 4, bs);
      Mat           A = build_bin(p, sym);
      Vec           b = make_vec(p.m, 13);
      for (const char *ordering : {MATORDERINGRCM, MATORDERINGND, MATORDERINGQMD, MATORDERING1WD}) {
        CAPTURE(bs, sym, ordering);
        // the reference: the matrix renumbered by that ordering, factored in natural order (the same
        // factor, so the same fill, iterations and solution, moved back)
        const std::vector<PetscInt> perm = block_ordering(A, ordering);
        REQUIRE((PetscInt)perm.size() == p.m / bs);
        Mat                Aperm = build_bin(permuted(p, perm), sym);
        Vec                bperm;
        const PetscScalar *ba;
        REQUIRE(VecDuplicate(b, &bperm) == 0);
        REQUIRE(VecGetArrayRead(b, &ba) == 0);
        const std::vector<PetscScalar> bv = permuted(std::vector<PetscScalar>(ba, ba + p.m), perm, bs);
        REQUIRE(VecRestoreArrayRead(b, &ba) == 0);
        std::vector<PetscInt> rows(p.m);
        for (PetscInt i = 0; i < p.m; i++) rows[i] = i;
        REQUIRE(VecSetValues(bperm, p.m, rows.data(), bv.data(), INSERT_VALUES) == 0);
        for (PCType pc : {PCICC, PCCHOLESKY}) {
          CAPTURE(pc);
          const bool     chol = !strcmp(pc, PCCHOLESKY);
          double         nz = 0, nzref = 0;
          const Solution got = factor_solve(A, pc, ordering, b, &nz);
          const Solution ref = factor_solve(Aperm, pc, MATORDERINGNATURAL, bperm, &nzref);
          CHECK(nz == nzref);
          CHECK(got.relres < (chol ? 1e-13 : 1e-9));
          Solution moved = got;
          moved.x        = permuted(got.x, perm, bs);
          check_same(moved, ref, 1e-9);
        }
        REQUIRE(VecDestroy(&bperm) == 0);
        REQUIRE(MatDestroy(&Aperm) == 0);
      }
      // the split solves (symmetric preconditioning: forward then backward) compose to the whole one
      {
        KSP k = make_ksp(PETSC_COMM_SELF, KSPCG, PCICC, 1e-10);
        PC  pc;
        Vec t, split, whole;
        REQUIRE(KSPGetPC(k, &pc) == 0);
        REQUIRE(PCFactorSetMatOrderingType(pc, MATORDERINGRCM) == 0);
        REQUIRE(KSPSetOperators(k, A, A) == 0);
        REQUIRE(KSPSetUp(k) == 0);
        for (Vec *v : {&t, &split, &whole}) REQUIRE(VecDuplicate(b, v) == 0);
        REQUIRE(PCApplySymmetricLeft(pc, b, t) == 0);
        REQUIRE(PCApplySymmetricRight(pc, t, split) == 0);
        REQUIRE(PCApply(pc, b, whole) == 0);
        PetscReal norm, diff;
        REQUIRE(VecNorm(whole, NORM_INFINITY, &norm) == 0);
        REQUIRE(VecAXPY(split, -1.0, whole) == 0);
        REQUIRE(VecNorm(split, NORM_INFINITY, &diff) == 0);
        CHECK(diff <= 1e-12 * norm);
        for (Vec *v : {&t, &split, &whole}) REQUIRE(VecDestroy(v) == 0);
        REQUIRE(KSPDestroy(&k) == 0);
      }
      // a refill in an ordering: the renumbered shadow refilled, the numeric factorisation redone
      {
        KSP k = make_ksp(PETSC_COMM_SELF, KSPPREONLY, PCCHOLESKY, 1e-10);
        PC  pc;
        REQUIRE(KSPGetPC(k, &pc) == 0);
        REQUIRE(PCFactorSetMatOrderingType(pc, MATORDERINGRCM) == 0);
        CHECK(solve_with(k, A, b).relres < 1e-13);
        REQUIRE(MatScale(A, 2.0) == 0);
        CHECK(solve_with(k, A, b).relres < 1e-13);
        REQUIRE(KSPDestroy(&k) == 0);
      }
      // Cholesky defaults to nested dissection: less fill than natural order on this 3-D mesh; ICC
      // with fill levels high enough is exact in any ordering
      double nz_default = 0, nz_natural = 0, nz_icc = 0;
      CAPTURE(bs, sym);
      CHECK(factor_solve(A, PCCHOLESKY, nullptr, b, &nz_default).relres < 1e-13);
      CHECK(factor_solve(A, PCCHOLESKY, MATORDERINGNATURAL, b, &nz_natural).relres < 1e-13);
      CHECK(nz_default < 0.9 * nz_natural);
      CHECK(factor_solve(A, PCICC, MATORDERINGRCM, b, &nz_icc, 200).relres < 1e-12);
      REQUIRE(VecDestroy(&b) == 0);
      REQUIRE(MatDestroy(&A) == 0);
    }
}

TEST_CASE("single-precision binbcsr factors its rounded values", "[mat_factor]")
{
  const Pattern p = fem_pattern(4, 4, 3, 3);
  Mat           A = build_bin(p, false, MAT_BINBCSR_PRECISION_SINGLE);
  Vec           b = make_vec(p.m, 3);
  // the factor of the float values is exact for the matrix that is multiplied: LU solves it to rounding
  CHECK(solve(A, KSPPREONLY, PCLU, b).relres < 1e-12);
  const Solution icc = solve(A, KSPCG, PCICC, b);
  CHECK(icc.reason > 0);
  CHECK(icc.relres < 1e-10);
  REQUIRE(VecDestroy(&b) == 0);
  REQUIRE(MatDestroy(&A) == 0);
}

TEST_CASE("refactorisation picks up new values", "[mat_factor]")
{
  for (bool sym : {false, true}) {
    CAPTURE(sym);
    const Pattern p    = fem_pattern(4, 3, 3, 3);
    Mat           A    = build_bin(p, sym);
    Mat           Sref = build_sbaij(p);
    Vec           b    = make_vec(p.m, 5);
    KSP           lu   = make_ksp(PETSC_COMM_SELF, KSPPREONLY, PCLU, 1e-10);
    KSP           icc  = make_ksp(PETSC_COMM_SELF, KSPCG, PCICC, 1e-10);
    KSP           iref = make_ksp(PETSC_COMM_SELF, KSPCG, PCICC, 1e-10);

    CHECK(solve_with(lu, A, b).relres < 1e-13);
    check_same(solve_with(icc, A, b), solve_with(iref, Sref, b), 1e-10);
    // new values on the same pattern: a stale factor would leave an O(1) residual after LU
    for (Mat M : {A, Sref}) {
      REQUIRE(MatScale(M, 3.0) == 0);
      REQUIRE(MatShift(M, 7.0) == 0);
    }
    // and an off-diagonal value changed through MatSetValues (both triangles: binbcsr full storage
    // reads (0, 3), symmetric storage and sbaij store only it)
    for (Mat M : {A, Sref}) {
      REQUIRE(MatSetValue(M, 0, 3, -5.0, INSERT_VALUES) == 0);
      PetscBool s;
      REQUIRE(PetscObjectTypeCompare((PetscObject)M, MATSEQSBAIJ, &s) == 0);
      if (!sym && !s) REQUIRE(MatSetValue(M, 3, 0, -5.0, INSERT_VALUES) == 0);
      REQUIRE(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY) == 0);
      REQUIRE(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY) == 0);
    }
    CHECK(solve_with(lu, A, b).relres < 1e-13);
    check_same(solve_with(icc, A, b), solve_with(iref, Sref, b), 1e-10);

    for (KSP *k : {&lu, &icc, &iref}) REQUIRE(KSPDestroy(k) == 0);
    REQUIRE(VecDestroy(&b) == 0);
    REQUIRE(MatDestroy(&A) == 0);
    REQUIRE(MatDestroy(&Sref) == 0);
  }
}

TEST_CASE("unsupported factorisations are errors, not crashes", "[mat_factor][errors]")
{
  const Pattern p = fem_pattern(3, 3, 2, 3);
  Mat           A = build_bin(p, false), F = nullptr;
  CHECK(MatGetFactor(A, MATSOLVERPETSC, MAT_FACTOR_QR, &F) != 0);
  CHECK(MatGetFactor(A, MATSOLVERPETSC, MAT_FACTOR_ILUDT, &F) != 0);
  CHECK(F == nullptr);
  // an unassembled matrix: the factor may be asked for (PCSetFromOptions does), but not computed
  Mat U;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &U) == 0);
  REQUIRE(MatSetSizes(U, 9, 9, 9, 9) == 0);
  REQUIRE(MatSetType(U, MATSEQBINBCSR) == 0);
  REQUIRE(MatSetUp(U) == 0);
  REQUIRE(MatGetFactor(U, MATSOLVERPETSC, MAT_FACTOR_ICC, &F) == 0);
  MatFactorInfo info;
  REQUIRE(MatFactorInfoInitialize(&info) == 0);
  CHECK(MatICCFactorSymbolic(F, U, nullptr, &info) != 0);
  REQUIRE(MatDestroy(&F) == 0);
  REQUIRE(MatDestroy(&U) == 0);
  REQUIRE(MatDestroy(&A) == 0);
}

TEST_CASE(
  "the factor asked for before the first assembly (PCSetFromOptions) factors the matrix assembled later",
  "[mat_factor]")
{
  for (PCType pc : {PCICC, PCILU, PCLU, PCCHOLESKY})
    for (bool sym : {false, true}) {
      CAPTURE(pc, sym);
      const Pattern p = fem_pattern(4, 3, 3, 3);
      Mat           A, Aref = build(p, MATSEQBAIJ);
      REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
      REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
      REQUIRE(MatSetBlockSize(A, p.bs) == 0);
      REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
      if (sym) REQUIRE(MatBinBCSRSetSymmetricStorage(A, PETSC_TRUE) == 0);
      REQUIRE(MatSetUp(A) == 0);
      const bool direct = !strcmp(pc, PCLU) || !strcmp(pc, PCCHOLESKY);
      KSP        k      = make_ksp(PETSC_COMM_SELF, direct ? KSPPREONLY : KSPCG, pc, 1e-10);
      REQUIRE(KSPSetOperators(k, A, A) == 0);
      REQUIRE(KSPSetFromOptions(k) == 0); // PCFactor asks for the factor here, before any value
      Mat F = nullptr;
      PC  kpc;
      REQUIRE(KSPGetPC(k, &kpc) == 0);
      REQUIRE(PCFactorGetMatrix(kpc, &F) == 0);
      CHECK(F != nullptr);
      for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
      REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
      REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
      Vec            b   = make_vec(p.m, 3);
      const Solution got = solve_with(k, A, b);
      const Solution ref = solve(Aref, direct ? KSPPREONLY : KSPCG, !strcmp(pc, PCCHOLESKY) ? PCLU : pc, b);
      CHECK(got.relres < (direct ? 1e-13 : 1e-9));
      if (strcmp(pc, PCCHOLESKY)) check_same(got, ref, 1e-9); // baij's own ICC/ILU/LU
      REQUIRE(KSPDestroy(&k) == 0);
      REQUIRE(VecDestroy(&b) == 0);
      REQUIRE(MatDestroy(&A) == 0);
      REQUIRE(MatDestroy(&Aref) == 0);
    }
}

namespace {
// The pattern's matrix on PETSC_COMM_WORLD, rows split by PETSc (whole blocks), each rank setting its own.
Mat build_world(const Pattern &p, MatType type)
{
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_WORLD, &A) == 0);
  REQUIRE(MatSetSizes(A, PETSC_DECIDE, PETSC_DECIDE, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, p.bs) == 0);
  REQUIRE(MatSetType(A, type) == 0);
  REQUIRE(MatXAIJSetPreallocation(A, p.bs, nullptr, nullptr, nullptr, nullptr) == 0);
  REQUIRE(MatSetUp(A) == 0);
  REQUIRE(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE) == 0);
  PetscInt r0, r1;
  REQUIRE(MatGetOwnershipRange(A, &r0, &r1) == 0);
  for (const Entry &e : p.entries)
    if (e.i >= r0 && e.i < r1) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  return A;
}
} // namespace

TEST_CASE("block Jacobi with ICC/ILU blocks on binbcsr equals baij", "[mat_factor][mpi]")
{
  const Pattern p    = fem_pattern(6, 5, 4, 3);
  Mat           A    = build_world(p, MATBINBCSR);
  Mat           Aref = build_world(p, MATBAIJ);
  Vec           b;
  REQUIRE(MatCreateVecs(A, nullptr, &b) == 0);
  REQUIRE(VecSetRandom(b, nullptr) == 0);
  for (const char *sub : {PCICC, PCILU}) {
    CAPTURE(sub);
    REQUIRE(PetscOptionsSetValue(nullptr, "-sub_pc_type", sub) == 0);
    KSP k    = make_ksp(PETSC_COMM_WORLD, KSPCG, PCBJACOBI, 1e-10),
        kref = make_ksp(PETSC_COMM_WORLD, KSPCG, PCBJACOBI, 1e-10);
    REQUIRE(KSPSetFromOptions(k) == 0);
    REQUIRE(KSPSetFromOptions(kref) == 0);
    check_same(solve_with(k, A, b), solve_with(kref, Aref, b), 1e-10);
    // refactorisation of the blocks after the values change
    for (Mat M : {A, Aref}) {
      REQUIRE(MatScale(M, 2.0) == 0);
      REQUIRE(MatShift(M, 3.0) == 0);
    }
    check_same(solve_with(k, A, b), solve_with(kref, Aref, b), 1e-10);
    REQUIRE(KSPDestroy(&k) == 0);
    REQUIRE(KSPDestroy(&kref) == 0);
    REQUIRE(PetscOptionsClearValue(nullptr, "-sub_pc_type") == 0);
  }
  PetscMPIInt size;
  REQUIRE(MPI_Comm_size(PETSC_COMM_WORLD, &size) == 0);
  if (size > 1) { // the parallel type has no factorisation of its own: a clear error, as for mpibaij
    Mat F = nullptr;
    CHECK(MatGetFactor(A, MATSOLVERPETSC, MAT_FACTOR_ICC, &F) != 0);
  }
  REQUIRE(VecDestroy(&b) == 0);
  REQUIRE(MatDestroy(&A) == 0);
  REQUIRE(MatDestroy(&Aref) == 0);
}

// A matrix without rows (a rank holding none: PCBJACOBI's block there) factors and solves as nothing.
// PETSc 3.18's own BAIJ and SBAIJ factorisations crash on it (numeric ICC reads past its arrays), so
// binbcsr's shadow must not be asked.
TEST_CASE("ICC, Cholesky, ILU and LU of an empty binbcsr matrix do nothing, without error", "[mat_factor]")
{
  for (PetscInt bs : {1, 3})
    for (bool sym : {false, true})
      for (const char *pc : {PCICC, PCCHOLESKY, PCILU, PCLU}) {
        CAPTURE(bs, sym, pc);
        Mat A;
        REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
        REQUIRE(MatSetSizes(A, 0, 0, 0, 0) == 0);
        REQUIRE(MatSetBlockSize(A, bs) == 0);
        REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
        if (sym) REQUIRE(MatBinBCSRSetSymmetricStorage(A, PETSC_TRUE) == 0);
        REQUIRE(MatSetUp(A) == 0);
        REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
        REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
        Vec x, b;
        REQUIRE(MatCreateVecs(A, &x, &b) == 0);
        KSP ksp;
        PC  p;
        REQUIRE(KSPCreate(PETSC_COMM_SELF, &ksp) == 0);
        REQUIRE(KSPSetOperators(ksp, A, A) == 0);
        REQUIRE(KSPSetType(ksp, KSPPREONLY) == 0);
        REQUIRE(KSPGetPC(ksp, &p) == 0);
        REQUIRE(PCSetType(p, pc) == 0);
        CHECK(KSPSolve(ksp, b, x) == 0);
        CHECK(KSPSolve(ksp, b, x) == 0); // and again, after the values are "refilled"
        KSPDestroy(&ksp);
        VecDestroy(&x);
        VecDestroy(&b);
        MatDestroy(&A);
      }
}
