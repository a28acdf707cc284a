// A NaN or Inf in x reaches exactly the entries of y that aij gives nonfinite: padding slots (zero
// values) must not multiply an x entry their row does not use. A diagonal matrix with a few couplings
// (one across ranks), two empty block rows, x[0] = NaN or +Inf; every product, body set, block size,
// bin width (the generic one too), precision and storage. Collective: runs on 1, 2 and 3 ranks
// (tests/mpi.cmake), so the off-diagonal part of MATMPIBINBCSR is covered where there are several.
#include <catch2/catch.hpp>

#include <petscbinbcsr.h>

#include <cmath>
#include <limits>
#include <vector>

#define PCHK(expr) REQUIRE((expr) == 0)

namespace {

// Empty block rows pad with column 0, where x holds the NaN or Inf. Row 9 shares its bin with phantom
// lanes; row 3 sits in the first bin, whose second slot group (columns N-3, 6, 1, 1 in its real lanes)
// runs over no consecutive columns, so the AVX-512 bodies read it lane by lane and must leave row 3's
// lane out.
constexpr PetscInt rows_per_rank = 10, empty_rows[] = {3, 9};

// The global block pattern: diagonal blocks except the empty rows, couplings (0, N-3), (1, 6), (1, 7)
// and their transposes (N = block rows).
Mat build(MatType type, PetscInt bs, PetscInt bw, MatBinBCSRPrecision prec, PetscBool sym,
          MatBinBCSRKernel kernel)
{
  PetscMPIInt size, rank;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  const PetscInt N = rows_per_rank * size;
  Mat            A;
  PCHK(MatCreate(PETSC_COMM_WORLD, &A));
  PCHK(MatSetSizes(A, rows_per_rank * bs, rows_per_rank * bs, PETSC_DETERMINE, PETSC_DETERMINE));
  PCHK(MatSetBlockSize(A, bs));
  PCHK(MatSetType(A, type));
  PCHK(MatBinBCSRSetBinWidth(A, bw));
  PCHK(MatBinBCSRSetPrecision(A, prec));
  PCHK(MatBinBCSRSetSymmetricStorage(A, sym));
  PCHK(MatSetUp(A));
  PCHK(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  std::vector<PetscScalar> d(bs * bs), o(bs * bs, 0.5);
  for (PetscInt i = 0; i < bs; i++)
    for (PetscInt j = 0; j < bs; j++) d[i * bs + j] = i == j ? 4.0 : 1.0;
  const PetscInt couplings[][2] = {{0, N - 3}, {1, 6}, {1, 7}};
  if (rank == 0) {
    for (PetscInt r = 0; r < N; r++)
      if (r != empty_rows[0] && r != empty_rows[1])
        PCHK(MatSetValuesBlocked(A, 1, &r, 1, &r, d.data(), INSERT_VALUES));
    for (const auto &c : couplings) {
      PCHK(MatSetValuesBlocked(A, 1, &c[0], 1, &c[1], o.data(), INSERT_VALUES));
      PCHK(MatSetValuesBlocked(A, 1, &c[1], 1, &c[0], o.data(), INSERT_VALUES));
    }
  }
  PCHK(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PCHK(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PCHK(MatBinBCSRSetKernel(A, kernel));
  return A;
}

int cls(PetscScalar v) { return std::isnan(v) ? 0 : std::isinf(v) ? (v > 0 ? 1 : 2) : 3; }

// Entries whose class (NaN, +Inf, -Inf, finite) differs, or finite ones that differ beyond the
// rounding of single storage, summed over the ranks; and the nonfinite entries of ref.
void compare(Vec got, Vec ref, PetscInt *bad, PetscInt *nonfinite)
{
  const PetscScalar *g, *r;
  PetscInt           n, cnt[2] = {0, 0}, sum[2];
  PCHK(VecGetLocalSize(got, &n));
  PCHK(VecGetArrayRead(got, &g));
  PCHK(VecGetArrayRead(ref, &r));
  for (PetscInt i = 0; i < n; i++) {
    cnt[1] += cls(r[i]) != 3;
    if (cls(g[i]) != cls(r[i]) || (cls(r[i]) == 3 && std::fabs(g[i] - r[i]) > 1e-5 * (1.0 + std::fabs(r[i]))))
      cnt[0]++;
  }
  PCHK(VecRestoreArrayRead(got, &g));
  PCHK(VecRestoreArrayRead(ref, &r));
  REQUIRE(MPI_Allreduce(cnt, sum, 2, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD) == MPI_SUCCESS);
  *bad       = sum[0];
  *nonfinite = sum[1];
}

} // namespace

TEST_CASE("products propagate NaN and Inf of x exactly as aij", "[mpi][nonfinite]")
{
  const PetscInt            bs   = GENERATE(1, 3, 2);
  const PetscInt            bw   = GENERATE(4, 8, 16, 5);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  const PetscBool           sym  = GENERATE(PETSC_FALSE, PETSC_TRUE);
  const double              bad_x =
    GENERATE(std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity());
  for (MatBinBCSRKernel kernel :
       {MAT_BINBCSR_KERNEL_PORTABLE, MAT_BINBCSR_KERNEL_AVX2, MAT_BINBCSR_KERNEL_AVX512}) {
    PetscBool avail;
    PCHK(MatBinBCSRKernelAvailable(kernel, &avail));
    if (!avail) continue;
    CAPTURE(bs, bw, prec, sym, bad_x, kernel);
    Mat A = build(MATBINBCSR, bs, bw, prec, sym, kernel),
        R = build(MATAIJ, bs, bw, prec, PETSC_FALSE, kernel);
    Vec         x, y, yr, z;
    PetscMPIInt rank;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    PCHK(MatCreateVecs(A, &x, &y));
    PCHK(VecDuplicate(y, &yr));
    PCHK(VecDuplicate(y, &z));
    PCHK(VecSet(x, 1.0));
    PCHK(VecSet(z, 2.0));
    if (rank == 0) PCHK(VecSetValue(x, 0, bad_x, INSERT_VALUES));
    PCHK(VecAssemblyBegin(x));
    PCHK(VecAssemblyEnd(x));
    PetscInt bad, nonfinite;

    PCHK(MatMult(A, x, y));
    PCHK(MatMult(R, x, yr));
    compare(y, yr, &bad, &nonfinite);
    CHECK(bad == 0);
    CHECK(nonfinite == 2 * bs); /* row 0 and row N - 3: the entries of x[0]'s block column */

    PCHK(MatMultAdd(A, x, z, y));
    PCHK(MatMultAdd(R, x, z, yr));
    compare(y, yr, &bad, &nonfinite);
    CHECK(bad == 0);

    PCHK(VecCopy(z, y));
    PCHK(MatMultAdd(A, x, y, y));
    compare(y, yr, &bad, &nonfinite);
    CHECK(bad == 0);

    PCHK(MatMultTranspose(A, x, y));
    PCHK(MatMultTranspose(R, x, yr));
    compare(y, yr, &bad, &nonfinite);
    CHECK(bad == 0);

    PetscScalar dot;
    PCHK(MatMultDotLocal(A, x, y, &dot));
    PCHK(MatMult(R, x, yr));
    compare(y, yr, &bad, &nonfinite);
    CHECK(bad == 0);

    VecDestroy(&x);
    VecDestroy(&y);
    VecDestroy(&yr);
    VecDestroy(&z);
    MatDestroy(&A);
    MatDestroy(&R);
  }
}
