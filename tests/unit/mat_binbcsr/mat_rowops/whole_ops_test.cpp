// Operations a PETSc user expects of aij, on -mat_type binbcsr (seq on one rank, mpi on more) against
// aij holding the same entries: MatInvertVariableBlockDiagonal and PCVPBJACOBI, MatSetRandom,
// MatFindNonzeroRows, MatGetColumnVector, MatRealPart/MatImaginaryPart/MatConjugate, MatGetRowIJ.
#include "rowops_support.hpp"

#include <petscksp.h>

#include <algorithm>
#include <set>

using namespace rowops;

namespace {

// This rank's variable blocks: sizes 1, 2, 4, 3, 5, ... (cutting across the bs x bs blocks), the last
// one cut to what is left of the local rows.
std::vector<PetscInt> variable_blocks(Mat A)
{
  static const PetscInt cycle[] = {1, 2, 4, 3, 5};
  PetscInt              n, k = 0;
  REQUIRE(MatGetLocalSize(A, &n, nullptr) == 0);
  std::vector<PetscInt> sizes;
  for (PetscInt done = 0; done < n; k++) {
    const PetscInt s = std::min(cycle[k % 5], n - done);
    sizes.push_back(s);
    done += s;
  }
  return sizes;
}

std::vector<PetscScalar> invert_blocks(Mat A, const std::vector<PetscInt> &sizes)
{
  size_t total = 0;
  for (PetscInt s : sizes) total += (size_t)s * s;
  std::vector<PetscScalar> d(total);
  PETSC_OK(MatInvertVariableBlockDiagonal(A, (PetscInt)sizes.size(), sizes.data(), d.data()));
  return d;
}

// a_ii += sign(a_ii) sum_j |a_ij| in both: strictly diagonally dominant rows, whatever the row and
// column scales (10^-4 .. 10^4), so that GMRES + PCVPBJACOBI converges in a few dozen iterations and the
// iteration counts do not hang on roundings (the test matrix itself needs about n iterations)
void make_dominant(const Pair &p)
{
  Vec          d;
  PetscInt     rstart, rend;
  PetscScalar *a;
  REQUIRE(MatCreateVecs(p.aij, nullptr, &d) == 0);
  REQUIRE(MatGetDiagonal(p.aij, d) == 0);
  REQUIRE(MatGetOwnershipRange(p.aij, &rstart, &rend) == 0);
  REQUIRE(VecGetArray(d, &a) == 0);
  for (PetscInt i = rstart; i < rend; i++) {
    PetscInt           n;
    const PetscScalar *v;
    double             sum = 0;
    REQUIRE(MatGetRow(p.aij, i, &n, nullptr, &v) == 0);
    for (PetscInt k = 0; k < n; k++) sum += std::fabs(v[k]);
    REQUIRE(MatRestoreRow(p.aij, i, &n, nullptr, &v) == 0);
    a[i - rstart] = a[i - rstart] < 0 ? -sum : sum;
  }
  REQUIRE(VecRestoreArray(d, &a) == 0);
  REQUIRE(MatDiagonalSet(p.bin, d, ADD_VALUES) == 0);
  REQUIRE(MatDiagonalSet(p.aij, d, ADD_VALUES) == 0);
  REQUIRE(VecDestroy(&d) == 0);
}

// x = A^-1 b by GMRES + PCVPBJACOBI from a zero guess; returns the iterations
PetscInt vpbjacobi_solve(Mat A, Vec b, Vec x, KSPConvergedReason *reason)
{
  KSP      ksp;
  PC       pc;
  PetscInt its;
  REQUIRE(KSPCreate(PETSC_COMM_WORLD, &ksp) == 0);
  REQUIRE(KSPSetOperators(ksp, A, A) == 0);
  REQUIRE(KSPSetType(ksp, KSPGMRES) == 0);
  REQUIRE(KSPGMRESSetRestart(ksp, 100) == 0);
  REQUIRE(KSPGetPC(ksp, &pc) == 0);
  REQUIRE(PCSetType(pc, PCVPBJACOBI) == 0);
  REQUIRE(KSPSetTolerances(ksp, 1e-10, 0.0, PETSC_DEFAULT, 100) == 0);
  REQUIRE(KSPSolve(ksp, b, x) == 0);
  REQUIRE(KSPGetIterationNumber(ksp, &its) == 0);
  REQUIRE(KSPGetConvergedReason(ksp, reason) == 0);
  REQUIRE(KSPDestroy(&ksp) == 0);
  return its;
}

// the local rows' column lists
std::vector<std::vector<PetscInt>> pattern(Mat A)
{
  PetscInt rstart, rend;
  REQUIRE(MatGetOwnershipRange(A, &rstart, &rend) == 0);
  std::vector<std::vector<PetscInt>> p;
  for (PetscInt i = rstart; i < rend; i++) {
    PetscInt        n;
    const PetscInt *cols;
    REQUIRE(MatGetRow(A, i, &n, &cols, nullptr) == 0);
    p.emplace_back(cols, cols + n);
    REQUIRE(MatRestoreRow(A, i, &n, &cols, nullptr) == 0);
  }
  return p;
}

std::vector<PetscInt> is_indices(IS is)
{
  if (!is) return {-1}; // NULL: every row kept
  PetscInt        n;
  const PetscInt *idx;
  REQUIRE(ISGetLocalSize(is, &n) == 0);
  REQUIRE(ISGetIndices(is, &idx) == 0);
  std::vector<PetscInt> v(idx, idx + n);
  REQUIRE(ISRestoreIndices(is, &idx) == 0);
  return v;
}

bool vec_equal(Vec a, Vec b)
{
  PetscBool eq;
  REQUIRE(VecEqual(a, b, &eq) == 0);
  return eq == PETSC_TRUE;
}

} // namespace

TEST_CASE("MatInvertVariableBlockDiagonal and PCVPBJACOBI match aij", "[wholeops]")
{
  for (Config c : configs()) {
    c.holes = false; // no empty rows: every block is invertible
    SECTION(c.name())
    {
      Pair                        p(c);
      const std::vector<PetscInt> sizes = variable_blocks(p.aij);
      // the inverses, block by block: both invert the same (float-rounded for single) entries in double,
      // so they differ by the roundings of two elimination orders, bounded through the block's
      // condition number: |D_bin - D_aij| <= 8 n cond_inf(B) eps_double |B^-1|_max
      const std::vector<PetscScalar> db = invert_blocks(p.bin, sizes), da = invert_blocks(p.aij, sizes);
      PetscInt                       rstart, off                          = 0;
      PETSC_OK(MatGetOwnershipRange(p.aij, &rstart, nullptr));
      for (size_t k = 0, row = rstart; k < sizes.size(); row += sizes[k], off += sizes[k] * sizes[k], k++) {
        const PetscInt n     = sizes[k];
        double         bnorm = 0, inorm = 0, imax = 0, err = 0;
        for (PetscInt i = 0; i < n; i++) {
          double bs = 0, is = 0;
          for (PetscInt j = 0; j < n; j++) {
            if (block_present(c, ((PetscInt)row + i) / c.bs, ((PetscInt)row + j) / c.bs))
              bs += std::fabs(entry(c, (PetscInt)row + i, (PetscInt)row + j));
            is += std::fabs(da[off + j * n + i]);
            imax = std::max(imax, std::fabs(da[off + j * n + i]));
            err  = std::max(err, std::fabs(db[off + j * n + i] - da[off + j * n + i]));
          }
          bnorm = std::max(bnorm, bs);
          inorm = std::max(inorm, is);
        }
        INFO("block " << k << " of size " << n << " at row " << row);
        CHECK(err <= 8 * n * bnorm * inorm * DBL_EPSILON * imax);
      }
      MatFactorError fe;
      PETSC_OK(MatFactorGetError(p.bin, &fe));
      CHECK(fe == MAT_FACTOR_NOERROR);

      // PCVPBJACOBI: the same iterations and solution
      make_dominant(p);
      Vec b, xb, xa;
      PETSC_OK(make_vec(p.aij, true, 7, &b));
      PETSC_OK(VecDuplicate(b, &xb));
      PETSC_OK(VecDuplicate(b, &xa));
      PETSC_OK(MatSetVariableBlockSizes(p.bin, (PetscInt)sizes.size(), const_cast<PetscInt *>(sizes.data())));
      PETSC_OK(MatSetVariableBlockSizes(p.aij, (PetscInt)sizes.size(), const_cast<PetscInt *>(sizes.data())));
      KSPConvergedReason rb, ra;
      const PetscInt     itb = vpbjacobi_solve(p.bin, b, xb, &rb), ita = vpbjacobi_solve(p.aij, b, xa, &ra);
      CHECK(ra > 0);
      CHECK(rb > 0);
      CHECK(itb == ita);
      // both reach the relative (preconditioned) residual 1e-10 on a well-conditioned system
      PetscReal dx, nx;
      PETSC_OK(VecAXPY(xb, -1.0, xa));
      PETSC_OK(VecNorm(xb, NORM_2, &dx));
      PETSC_OK(VecNorm(xa, NORM_2, &nx));
      CHECK(dx <= 1e-7 * nx);
      PETSC_OK(VecDestroy(&b));
      PETSC_OK(VecDestroy(&xb));
      PETSC_OK(VecDestroy(&xa));
    }
  }
}

TEST_CASE("MatInvertVariableBlockDiagonal refuses bad block sizes and reports zero pivots", "[wholeops]")
{
  Config c; // bs 3 with empty rows (holes): blocks holding an empty row are singular; every rank has one
  Pair   p(c);
  std::vector<PetscInt>    sizes = variable_blocks(p.bin);
  std::vector<PetscScalar> d(25 * sizes.size());
  PetscInt                 n;
  PETSC_OK(MatGetLocalSize(p.bin, &n, nullptr));
  // sizes that do not add up to the local rows, a negative size
  PETSC_FAILS_WITH(MatInvertVariableBlockDiagonal(p.bin, (PetscInt)sizes.size() - 1, sizes.data(), d.data()),
                   PETSC_ERR_ARG_SIZ);
  const PetscInt neg[] = {-1, n + 1};
  PETSC_FAILS_WITH(MatInvertVariableBlockDiagonal(p.bin, 2, neg, d.data()), PETSC_ERR_ARG_OUTOFRANGE);
  // zero pivot: recorded (PCVPBJACOBI then fails with a reason), or an error under MatSetErrorIfFailure
  MatFactorError fe;
  PETSC_OK(MatInvertVariableBlockDiagonal(p.bin, (PetscInt)sizes.size(), sizes.data(), d.data()));
  PETSC_OK(MatFactorGetError(p.bin, &fe));
  CHECK(fe == MAT_FACTOR_NUMERIC_ZEROPIVOT);
  Vec b, x;
  PETSC_OK(make_vec(p.bin, true, 7, &b));
  PETSC_OK(VecDuplicate(b, &x));
  PETSC_OK(MatSetVariableBlockSizes(p.bin, (PetscInt)sizes.size(), sizes.data()));
  KSPConvergedReason reason;
  vpbjacobi_solve(p.bin, b, x, &reason);
  CHECK(reason == KSP_DIVERGED_PC_FAILED);
  PETSC_OK(MatSetErrorIfFailure(p.bin, PETSC_TRUE));
  PETSC_FAILS_WITH(MatInvertVariableBlockDiagonal(p.bin, (PetscInt)sizes.size(), sizes.data(), d.data()),
                   PETSC_ERR_MAT_LU_ZRPVT);
  PETSC_OK(VecDestroy(&b));
  PETSC_OK(VecDestroy(&x));
}

TEST_CASE(
  "MatSetRandom fills the stored pattern; whole storage draws aij's values, symmetric storage stays symmetric",
  "[wholeops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair        p(c);
      const auto  pat = pattern(p.bin);
      PetscRandom rb, ra;
      PETSC_OK(PetscRandomCreate(PETSC_COMM_WORLD, &rb));
      PETSC_OK(PetscRandomCreate(PETSC_COMM_WORLD, &ra));
      PETSC_OK(PetscRandomSetInterval(rb, -2.0, 3.0));
      PETSC_OK(PetscRandomSetInterval(ra, -2.0, 3.0));
      PETSC_OK(MatSetRandom(p.bin, rb));
      CHECK(pattern(p.bin) == pat);
      Vec mx, mn;
      PETSC_OK(MatCreateVecs(p.bin, nullptr, &mx));
      PETSC_OK(VecDuplicate(mx, &mn));
      PETSC_OK(MatGetRowMax(p.bin, mx, nullptr));
      PETSC_OK(MatGetRowMin(p.bin, mn, nullptr));
      PetscReal hi, lo;
      PETSC_OK(VecMax(mx, nullptr, &hi));
      PETSC_OK(VecMin(mn, nullptr, &lo));
      CHECK(hi < 3.0);
      CHECK(lo >= -2.0);
      CHECK(hi - lo > 4.0); // spread over the interval
      if (!c.sym) {
        PETSC_OK(MatSetRandom(p.aij, ra));
        CHECK(row_error(p.bin, p.aij) <= (c.prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON / 2 : 0.0));
      } else {
        Mat       full;
        PetscBool symmetric;
        PETSC_OK(MatConvert(p.bin, MATAIJ, MAT_INITIAL_MATRIX, &full));
        PETSC_OK(MatIsSymmetric(full, 0.0, &symmetric));
        CHECK(symmetric);
        // the same PetscRandom state on double storage gives the same matrix (rounded for single)
        Config cd = c;
        cd.prec   = MAT_BINBCSR_PRECISION_DOUBLE;
        cd.bw     = c.bw ? 0 : 5;
        Mat         dbl;
        PetscRandom r2;
        PETSC_OK(make(cd, MATBINBCSR, &dbl));
        PETSC_OK(PetscRandomCreate(PETSC_COMM_WORLD, &r2));
        PETSC_OK(PetscRandomSetInterval(r2, -2.0, 3.0));
        PETSC_OK(MatSetRandom(dbl, r2));
        CHECK(row_error(p.bin, dbl) <= (c.prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON / 2 : 0.0));
        PETSC_OK(PetscRandomDestroy(&r2));
        PETSC_OK(MatDestroy(&dbl));
        PETSC_OK(MatDestroy(&full));
      }
      PETSC_OK(VecDestroy(&mx));
      PETSC_OK(VecDestroy(&mn));
      PETSC_OK(PetscRandomDestroy(&rb));
      PETSC_OK(PetscRandomDestroy(&ra));
    }
  }
  SECTION("no pattern yet: refused")
  {
    Mat A;
    PETSC_OK(MatCreate(PETSC_COMM_WORLD, &A));
    PETSC_OK(MatSetSizes(A, PETSC_DECIDE, PETSC_DECIDE, 12, 12));
    PETSC_OK(MatSetType(A, MATBINBCSR));
    PETSC_OK(MatSetUp(A));
    PetscRandom r; // given, not left to MatSetRandom: PETSc's own one leaks when the type refuses
    PETSC_OK(PetscRandomCreate(PETSC_COMM_WORLD, &r));
    PETSC_FAILS_WITH(MatSetRandom(A, r), PETSC_ERR_ARG_WRONGSTATE);
    PETSC_OK(PetscRandomDestroy(&r));
    PETSC_OK(MatDestroy(&A));
  }
}

TEST_CASE("MatFindNonzeroRows, MatGetColumnVector, MatRealPart/ImaginaryPart/Conjugate match aij",
          "[wholeops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair p(c);
      // rows: with holes some are empty; without, none (NULL). Then rows and columns zeroed (stored zeros
      // in binbcsr) are zero rows too.
      for (int round = 0; round < 2; round++) {
        IS kb, ka;
        PETSC_OK(MatFindNonzeroRows(p.bin, &kb));
        PETSC_OK(MatFindNonzeroRows(p.aij, &ka));
        CHECK(is_indices(kb) == is_indices(ka));
        if (round == 0) CHECK((kb == nullptr) == !c.holes);
        else CHECK(kb != nullptr);
        PETSC_OK(ISDestroy(&kb));
        PETSC_OK(ISDestroy(&ka));
        const PetscInt zr[] = {2, 3, c.mbs() * c.bs - 1};
        PETSC_OK(MatZeroRowsColumns(p.bin, 3, zr, 0.0, nullptr, nullptr));
        PETSC_OK(MatZeroRowsColumns(p.aij, 3, zr, 0.0, nullptr, nullptr));
      }
      // columns: the first, an empty one (holes), a middle one, the last
      Vec vb, va;
      PETSC_OK(MatCreateVecs(p.aij, nullptr, &va));
      PETSC_OK(VecDuplicate(va, &vb));
      for (PetscInt col : {(PetscInt)0, 5 * c.bs, c.mbs() * c.bs / 2, c.mbs() * c.bs - 2}) {
        PETSC_OK(MatGetColumnVector(p.bin, vb, col));
        PETSC_OK(MatGetColumnVector(p.aij, va, col));
        INFO("column " << col);
        CHECK(vec_equal(vb, va));
      }
      PETSC_FAILS_WITH(MatGetColumnVector(p.bin, vb, c.mbs() * c.bs), PETSC_ERR_ARG_OUTOFRANGE);
      PETSC_OK(VecDestroy(&vb));
      PETSC_OK(VecDestroy(&va));
      // real scalars: the real part and the conjugate are the matrix, the imaginary part is zero (pattern kept)
      const auto pat = pattern(p.bin);
      PETSC_OK(MatRealPart(p.bin));
      PETSC_OK(MatRealPart(p.aij));
      PETSC_OK(MatConjugate(p.bin));
      PETSC_OK(MatConjugate(p.aij));
      CHECK(row_error(p.bin, p.aij) == 0.0);
      PETSC_OK(MatImaginaryPart(p.bin));
      PETSC_OK(MatImaginaryPart(p.aij));
      CHECK(row_error(p.bin, p.aij) == 0.0);
      PetscReal nrm;
      PETSC_OK(MatNorm(p.bin, NORM_FROBENIUS, &nrm));
      CHECK(nrm == 0.0);
      CHECK(pattern(p.bin) == pat);
      // a NaN alone in a zero row: nonzero for aij (the row maximum skips NaN)
      PetscInt rstart, rend;
      PETSC_OK(MatGetOwnershipRange(p.aij, &rstart, &rend));
      for (Mat M : {p.bin, p.aij}) {
        if (rstart <= 2 && 2 < rend) PETSC_OK(MatSetValue(M, 2, 2, NAN, INSERT_VALUES));
        PETSC_OK(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY));
        PETSC_OK(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY));
      }
      IS kb, ka;
      PETSC_OK(MatFindNonzeroRows(p.bin, &kb));
      PETSC_OK(MatFindNonzeroRows(p.aij, &ka));
      CHECK(is_indices(kb) == is_indices(ka));
      CHECK(is_indices(kb) == (rstart <= 2 && 2 < rend ? std::vector<PetscInt>{2} : std::vector<PetscInt>{}));
      PETSC_OK(ISDestroy(&kb));
      PETSC_OK(ISDestroy(&ka));
    }
  }
}

TEST_CASE("MatGetRowIJ gives aij's structure of the local rows (global columns)", "[wholeops]")
{
  for (const Config &c : configs()) {
    SECTION(c.name())
    {
      Pair p(c);
      for (PetscInt shift : {0, 1}) {
        PetscInt        nb, na;
        const PetscInt *ib, *jb, *ia, *ja;
        PetscBool       db, da;
        PETSC_OK(MatGetRowIJ(p.bin, shift, PETSC_FALSE, PETSC_FALSE, &nb, &ib, &jb, &db));
        PETSC_OK(MatGetRowIJ(p.aij, shift, PETSC_FALSE, PETSC_FALSE, &na, &ia, &ja, &da));
        CHECK(db == da);
        CHECK(bool(db));
        REQUIRE(nb == na);
        CHECK(std::vector<PetscInt>(ib, ib + nb + 1) == std::vector<PetscInt>(ia, ia + na + 1));
        CHECK(std::vector<PetscInt>(jb, jb + ib[nb] - shift) ==
              std::vector<PetscInt>(ja, ja + ia[na] - shift));
        PETSC_OK(MatRestoreRowIJ(p.bin, shift, PETSC_FALSE, PETSC_FALSE, &nb, &ib, &jb, &db));
        PETSC_OK(MatRestoreRowIJ(p.aij, shift, PETSC_FALSE, PETSC_FALSE, &na, &ia, &ja, &da));
      }
    }
  }
}
