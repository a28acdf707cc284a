// Submatrices of binbcsr (seq on one rank, mpi on more) and the PCs built on them (PCASM, PCGASM,
// PCREDUNDANT, PCFIELDSPLIT) against the same operations on aij. Every TEST_CASE is collective on
// PETSC_COMM_WORLD: this program runs as unit_mat_sub on one rank and under mpiexec -n 2 and -n 3
// (tests/mat_sub.cmake); checks are reduced over the ranks first (all_ranks).
//
// Storage variants: full double, symmetric storage (upper triangle of the diagonal part), single
// precision. The single-precision reference is the aij copy of the single matrix (its values are the
// rounded ones), so that both sides solve the same system and can be compared tightly.
#include <catch2/catch.hpp>

#include "support/fem_problem.hpp"
#include <petsc/private/matimpl.h> // nonzerostate

#include <cmath>
#include <string>
#include <vector>

using namespace mpitest;

#define PCHK(expr) REQUIRE((expr) == 0)

namespace {

struct Storage {
  const char *name;
  bool        sym, single;
};
const Storage storages[] = {
  {"full", false, false}, {"symmetric storage", true, false}, {"single", false, true}};

double weight0(int) { return 1.0; }
double weight1(int e) { return 1.0 + 3.0 * (e % 4); } // a refill that changes the preconditioner a lot

// A binbcsr (or aij) matrix filled through COO with element weights weight0.
PetscErrorCode coo_matrix(const FemProblem &fem, MatType type, const Storage &st, Mat *A)
{
  std::vector<PetscInt> ci, cj;
  PetscFunctionBeginUser;
  const PetscInt m = local_rows(fem, PETSC_COMM_WORLD, false);
  PetscCall(MatCreate(PETSC_COMM_WORLD, A));
  PetscCall(MatSetSizes(*A, m, m, fem.rows(), fem.rows()));
  PetscCall(MatSetBlockSize(*A, 3));
  PetscCall(MatSetType(*A, type));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
  if (st.sym) PetscCall(MatBinBCSRSetSymmetricStorage(*A, PETSC_TRUE));
  if (st.single) PetscCall(MatBinBCSRSetPrecision(*A, MAT_BINBCSR_PRECISION_SINGLE));
  rank_coo_entries(fem, ci, cj);
  PetscCall(MatSetPreallocationCOO(*A, static_cast<PetscCount>(ci.size()), ci.data(), cj.data()));
  PetscCall(MatSetValuesCOO(*A, rank_element_values(fem, weight0).data(), INSERT_VALUES));
  PetscFunctionReturn(0);
}

// The binbcsr matrix and its aij reference (assembled alike, or for single precision or when asked the
// aij copy of the binbcsr values).
PetscErrorCode matrix_pair(const FemProblem &fem, const Storage &st, Mat *A, Mat *R, bool copy_values = false)
{
  PetscFunctionBeginUser;
  PetscCall(coo_matrix(fem, MATBINBCSR, st, A));
  if (st.single || copy_values) PetscCall(MatConvert(*A, MATAIJ, MAT_INITIAL_MATRIX, R));
  else PetscCall(coo_matrix(fem, MATAIJ, st, R));
  PetscFunctionReturn(0);
}

// Both matrices refilled in place with weight1.
PetscErrorCode refill_pair(const FemProblem &fem, const Storage &st, Mat A, Mat R, bool copy_values = false)
{
  PetscFunctionBeginUser;
  const auto cv = rank_element_values(fem, weight1);
  PetscCall(MatSetValuesCOO(A, cv.data(), INSERT_VALUES));
  if (st.single || copy_values) PetscCall(MatConvert(A, MATAIJ, MAT_REUSE_MATRIX, &R));
  else PetscCall(MatSetValuesCOO(R, cv.data(), INSERT_VALUES));
  PetscFunctionReturn(0);
}

// Tolerance for comparing a binbcsr submatrix with aij's: exact for double (same values moved), the
// float rounding of the entries for single.
double sub_tol(const Storage &st) { return st.single ? 2 * 1.2e-7 : 1e-15; }

// Index sets of this rank: its own block rows (bs 3), and a strided set of the next rank's rows (a
// rectangular, non-symmetric extraction).
PetscErrorCode own_and_next(Mat A, IS *own, IS *next)
{
  PetscMPIInt     rank, size;
  const PetscInt *ranges;
  PetscFunctionBeginUser;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  PetscCall(MatGetOwnershipRanges(A, &ranges));
  const PetscInt lo = ranges[rank], hi = ranges[rank + 1], q = (rank + 1) % size;
  PetscCall(ISCreateStride(PETSC_COMM_SELF, hi - lo, lo, 1, own));
  PetscCall(ISSetBlockSize(*own, 3));
  PetscCall(ISCreateStride(PETSC_COMM_SELF, (ranges[q + 1] - ranges[q]) / 2, ranges[q], 2, next));
  PetscFunctionReturn(0);
}

// Sets options under a prefix for the duration of one set-up.
struct ScopedOptions {
  std::vector<std::string> names;
  explicit ScopedOptions(std::vector<std::pair<std::string, std::string>> opts)
  {
    for (auto &[k, v] : opts) {
      PetscOptionsSetValue(nullptr, k.c_str(), v.c_str());
      names.push_back(k);
    }
  }
  ~ScopedOptions()
  {
    for (auto &k : names) PetscOptionsClearValue(nullptr, k.c_str());
  }
};

} // namespace

TEST_CASE(
  "binbcsr submatrices (MatIncreaseOverlap, MatCreateSubMatrices, MatCreateSubMatrix) equal aij's, also after a refill",
  "[mat_sub]")
{
  const FemProblem fem(5, 4, 4, true); // shuffled numbering: ghost-heavy rows
  for (const Storage &st : storages) {
    SECTION(st.name)
    {
      Mat A, R;
      PCHK(matrix_pair(fem, st, &A, &R));
      IS isa[2], isr[2];
      PCHK(own_and_next(A, &isa[0], &isa[1]));
      PCHK(own_and_next(R, &isr[0], &isr[1]));
      PCHK(MatIncreaseOverlap(A, 1, isa, 1));
      PCHK(MatIncreaseOverlap(R, 1, isr, 1));
      PetscBool same;
      PCHK(ISEqual(isa[0], isr[0], &same));
      REQUIRE(all_ranks(same));
      PetscInt nov;
      PCHK(ISGetLocalSize(isa[0], &nov));
      PetscInt rstart, rend;
      PCHK(MatGetOwnershipRange(A, &rstart, &rend));
      PetscMPIInt size;
      MPI_Comm_size(PETSC_COMM_WORLD, &size);
      REQUIRE(all_ranks(size == 1 || rend == rstart || nov > rend - rstart)); // the overlap added rows

      Mat *sa, *sr;
      IS   cols_a[2] = {isa[0], isa[0]}, cols_r[2] = {isr[0], isr[0]}; // own x own, next x own
      PCHK(MatCreateSubMatrices(A, 2, isa, cols_a, MAT_INITIAL_MATRIX, &sa));
      PCHK(MatCreateSubMatrices(R, 2, isr, cols_r, MAT_INITIAL_MATRIX, &sr));
      PetscBool isseq;
      PCHK(PetscObjectTypeCompare((PetscObject)sa[0], MATSEQBINBCSR, &isseq));
      REQUIRE(all_ranks(isseq));
      PetscInt bs;
      PCHK(MatGetBlockSize(sa[0], &bs));
      CHECK(bs == 3);
      PetscBool sym;
      PCHK(MatBinBCSRGetSymmetricStorage(sa[0], &sym));
      CHECK((sym == PETSC_TRUE) == st.sym); // symmetric extraction keeps the parent's storage
      PCHK(MatBinBCSRGetSymmetricStorage(sa[1], &sym));
      CHECK(!sym); // rows of the next rank x own rows: not symmetric
      MatBinBCSRPrecision prec;
      PCHK(MatBinBCSRGetPrecision(sa[0], &prec));
      CHECK((prec == MAT_BINBCSR_PRECISION_SINGLE) == st.single);
      for (int i = 0; i < 2; ++i) CHECK(all_ranks(mat_rel_diff(sa[i], sr[i]) <= sub_tol(st)));

      // parallel submatrix: fields 0 and 2 of this rank's rows (PCFIELDSPLIT's kind)
      std::vector<PetscInt> f02;
      for (PetscInt r = rstart; r < rend; ++r)
        if (r % 3 != 1) f02.push_back(r);
      IS fis;
      PCHK(ISCreateGeneral(PETSC_COMM_WORLD, static_cast<PetscInt>(f02.size()), f02.data(), PETSC_COPY_VALUES,
                           &fis));
      Mat pa, pr;
      PCHK(MatCreateSubMatrix(A, fis, fis, MAT_INITIAL_MATRIX, &pa));
      PCHK(MatCreateSubMatrix(R, fis, fis, MAT_INITIAL_MATRIX, &pr));
      PetscBool isbin;
      PCHK(PetscObjectTypeCompareAny((PetscObject)pa, &isbin, MATSEQBINBCSR, MATMPIBINBCSR, ""));
      REQUIRE(all_ranks(isbin));
      CHECK(all_ranks(mat_rel_diff(pa, pr) <= sub_tol(st)));

      // refill: the same submatrix objects get the new values, their layout (nonzero state) stays
      PCHK(refill_pair(fem, st, A, R));
      Mat              keep[2] = {sa[0], sa[1]}, keep_p = pa;
      PetscObjectState nz0 = sa[0]->nonzerostate, nzp = pa->nonzerostate;
      PCHK(MatCreateSubMatrices(A, 2, isa, cols_a, MAT_REUSE_MATRIX, &sa));
      PCHK(MatCreateSubMatrices(R, 2, isr, cols_r, MAT_REUSE_MATRIX, &sr));
      PCHK(MatCreateSubMatrix(A, fis, fis, MAT_REUSE_MATRIX, &pa));
      PCHK(MatCreateSubMatrix(R, fis, fis, MAT_REUSE_MATRIX, &pr));
      CHECK(all_ranks(sa[0] == keep[0] && sa[1] == keep[1] && pa == keep_p));
      CHECK(all_ranks(sa[0]->nonzerostate == nz0 && pa->nonzerostate == nzp));
      for (int i = 0; i < 2; ++i) CHECK(all_ranks(mat_rel_diff(sa[i], sr[i]) <= sub_tol(st)));
      CHECK(all_ranks(mat_rel_diff(pa, pr) <= sub_tol(st)));

      PCHK(MatDestroySubMatrices(2, &sa));
      PCHK(MatDestroySubMatrices(2, &sr));
      PCHK(MatDestroy(&pa));
      PCHK(MatDestroy(&pr));
      PCHK(ISDestroy(&fis));
      for (int i = 0; i < 2; ++i) {
        PCHK(ISDestroy(&isa[i]));
        PCHK(ISDestroy(&isr[i]));
      }
      PCHK(MatDestroy(&A));
      PCHK(MatDestroy(&R));
    }
  }
}

TEST_CASE("binbcsr submatrices: bad input gives PETSc errors", "[mat_sub]")
{
  const FemProblem fem(4, 3, 3, false);
  Mat              A;
  PCHK(coo_matrix(fem, MATBINBCSR, storages[0], &A));
  IS own, next;
  PCHK(own_and_next(A, &own, &next));
  Mat *sa;
  PCHK(MatCreateSubMatrices(A, 1, &own, &own, MAT_INITIAL_MATRIX, &sa));
  // reuse with index sets that select another size than the submatrix has
  CHECK(all_ranks(MatCreateSubMatrices(A, 1, &next, &next, MAT_REUSE_MATRIX, &sa) != 0));
  PCHK(MatDestroySubMatrices(1, &sa));
  // an unassembled matrix
  Mat U;
  PCHK(MatCreate(PETSC_COMM_WORLD, &U));
  PCHK(MatSetSizes(U, A->rmap->n, A->rmap->n, PETSC_DETERMINE, PETSC_DETERMINE));
  PCHK(MatSetType(U, MATBINBCSR));
  PCHK(MatSetUp(U));
  CHECK(all_ranks(MatCreateSubMatrices(U, 1, &own, &own, MAT_INITIAL_MATRIX, &sa) != 0));
  PCHK(MatDestroy(&U));
  PCHK(ISDestroy(&own));
  PCHK(ISDestroy(&next));
  PCHK(MatDestroy(&A));
}

namespace {

struct PCCase {
  const char                                      *name;
  std::vector<std::pair<std::string, std::string>> opts; // without the KSP prefix
  bool copy_values = false; // compare with the aij copy of the binbcsr matrix: round-off-sensitive PCs
};

// One application of the PC (KSPPREONLY): x = M^{-1} b. Stale values in the PC would change x.
PetscErrorCode pc_apply(KSP ksp, Vec b, Vec x)
{
  PetscFunctionBeginUser;
  PetscCall(KSPSolve(ksp, b, x));
  PetscFunctionReturn(0);
}

PetscErrorCode make_ksp(Mat A, const char *prefix, const PCCase &c, KSPType type, KSP *ksp)
{
  PetscFunctionBeginUser;
  std::vector<std::pair<std::string, std::string>> opts;
  for (auto &[k, v] : c.opts) opts.emplace_back("-" + std::string(prefix) + k, v);
  ScopedOptions so(opts);
  PetscCall(KSPCreate(PETSC_COMM_WORLD, ksp));
  PetscCall(KSPSetOptionsPrefix(*ksp, prefix));
  PetscCall(KSPSetOperators(*ksp, A, A));
  PetscCall(KSPSetType(*ksp, type));
  PetscCall(KSPSetTolerances(*ksp, 1e-10, 1e-50, PETSC_DEFAULT, 500));
  PetscCall(KSPSetFromOptions(*ksp));
  PetscCall(KSPSetUp(*ksp));
  PetscFunctionReturn(0);
}

const std::vector<PCCase> pc_cases = {
  {"asm overlap 0, sub lu", {{"pc_type", "asm"}, {"pc_asm_overlap", "0"}, {"sub_pc_type", "lu"}}},
  {"asm overlap 1, sub lu", {{"pc_type", "asm"}, {"pc_asm_overlap", "1"}, {"sub_pc_type", "lu"}}},
  {"asm overlap 1, 2 blocks per rank, sub lu",
   {{"pc_type", "asm"}, {"pc_asm_overlap", "1"}, {"pc_asm_local_blocks", "2"}, {"sub_pc_type", "lu"}}},
  {"gasm, sub lu", {{"pc_type", "gasm"}, {"sub_pc_type", "lu"}}},
  {"redundant", {{"pc_type", "redundant"}}},
  {"redundant, one copy over all ranks", {{"pc_type", "redundant"}, {"pc_redundant_number", "1"}}},
  {"fieldsplit by component",
   {{"pc_type", "fieldsplit"}, {"pc_fieldsplit_block_size", "3"}, {"fieldsplit_pc_type", "jacobi"}}},
#if defined(PETSC_HAVE_HYPRE)
  // BoomerAMG's coarsening breaks ties of equal |a_ij| by round-off: the aij side gets the same bits
  {"hypre boomeramg", {{"pc_type", "hypre"}}, true},
#endif
  // the default package: PETSc's own on one rank, the first external one (MUMPS) on more
  {"lu", {{"pc_type", "lu"}}},
  {"cholesky", {{"pc_type", "cholesky"}}},
#if defined(PETSC_HAVE_MUMPS)
  {"lu mumps", {{"pc_type", "lu"}, {"pc_factor_mat_solver_type", "mumps"}}},
#endif
  // (not SuperLU_DIST: with Debian's PETSc 3.18 two of its factors alive in one process corrupt the heap,
  // aij alone as well; it is checked on its own in tests/mat_sub.cmake)
};

} // namespace

TEST_CASE(
  "PCASM, PCGASM, PCREDUNDANT, PCFIELDSPLIT, PCLU, PCCHOLESKY on binbcsr equal aij's, and see a refill",
  "[mat_sub][pc]")
{
  const FemProblem fem(5, 4, 4, true);
  for (const Storage &st : storages) {
    for (const PCCase &c : pc_cases) {
      DYNAMIC_SECTION(st.name << ": " << c.name)
      {
        Mat A, R;
        PCHK(matrix_pair(fem, st, &A, &R, c.copy_values));
        Vec b, xa, xr;
        PCHK(MatCreateVecs(A, &xa, &b));
        PCHK(VecDuplicate(xa, &xr));
        PetscRandom rnd;
        PCHK(PetscRandomCreate(PETSC_COMM_WORLD, &rnd));
        PCHK(PetscRandomSetSeed(rnd, 7));
        PCHK(PetscRandomSeed(rnd));
        PCHK(VecSetRandom(b, rnd));
        PCHK(PetscRandomDestroy(&rnd));

        KSP pa, pr, ga, gr; // one PC application; GMRES to 1e-10
        PCHK(make_ksp(A, "a_", c, KSPPREONLY, &pa));
        PCHK(make_ksp(R, "r_", c, KSPPREONLY, &pr));
        PCHK(make_ksp(A, "ga_", c, KSPGMRES, &ga));
        PCHK(make_ksp(R, "gr_", c, KSPGMRES, &gr));
        // an application of a PC built from exact LU blocks, etc.: equal to aij's to round-off
        const double tol = 1e-9;
        for (int pass = 0; pass < 2; ++pass) {
          INFO("pass " << pass << (pass ? " (after the refill)" : ""));
          PCHK(pc_apply(pa, b, xa));
          PCHK(pc_apply(pr, b, xr));
          INFO("PC application rel diff " << vec_rel_diff(xa, xr));
          CHECK(all_ranks(vec_rel_diff(xa, xr) < tol));
          PetscInt           ita, itr;
          KSPConvergedReason ra, rr;
          PCHK(VecSet(xa, 0));
          PCHK(VecSet(xr, 0));
          PCHK(KSPSolve(ga, b, xa));
          PCHK(KSPSolve(gr, b, xr));
          PCHK(KSPGetIterationNumber(ga, &ita));
          PCHK(KSPGetIterationNumber(gr, &itr));
          PCHK(KSPGetConvergedReason(ga, &ra));
          PCHK(KSPGetConvergedReason(gr, &rr));
          INFO("iterations binbcsr " << ita << ", aij " << itr);
          CHECK(ra > 0);
          CHECK(std::abs(ita - itr) <= 1);
          CHECK(all_ranks(vec_rel_diff(xa, xr) < 1e-7));
          if (pass == 0) {
            // stale values would now give another answer: the refill changes the PC a lot
            Vec before;
            PCHK(VecDuplicate(xa, &before));
            PCHK(pc_apply(pa, b, before));
            PCHK(refill_pair(fem, st, A, R, c.copy_values));
            PCHK(pc_apply(pa, b, xa));
            CHECK(all_ranks(vec_rel_diff(xa, before) > 1e-2));
            PCHK(VecDestroy(&before));
          }
        }
        KSP all[4] = {pa, pr, ga, gr};
        for (KSP &k : all) PCHK(KSPDestroy(&k));
        PCHK(VecDestroy(&b));
        PCHK(VecDestroy(&xa));
        PCHK(VecDestroy(&xr));
        PCHK(MatDestroy(&A));
        PCHK(MatDestroy(&R));
      }
    }
  }
}
