// mat_ops_bench: times the value operations (MatAXPY with the same pattern, MatScale, MatShift,
// MatNorm, MatZeroRowsColumns with x and b) and the row/column ones (MatDiagonalScale D A D,
// MatGetRowMaxAbs with columns, MatGetColumnNorms 2), MatInvertVariableBlockDiagonal (PCVPBJACOBI's set-up,
// one block of 3 rows per node) and MatFindNonzeroRows on the 27-point 3x3-block stencil matrix, for seqaij,
// seqbaij and binbcsr in double and single storage, in one run. Prints the minimum over -repeats
// runs of each operation in milliseconds (the machine is shared: the minimum is the least disturbed).
//
//   mat_ops_bench [-stencil_n 24] [-repeats 10]
#include "sim/stencil.h"
#include "sim/summary.h"

#include <petscbinbcsr.h>

#include "sim/bench_util.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <vector>

namespace {

struct Flavour {
  const char         *label;
  MatType             type;
  MatBinBCSRPrecision precision;
  bool                sym = false; // -mat_binbcsr_symmetric_storage
};

PetscErrorCode Time(PetscInt repeats, const std::function<PetscErrorCode()> &op, double *ms)
{
  PetscFunctionBeginUser;
  *ms = std::numeric_limits<double>::infinity();
  for (PetscInt r = 0; r < repeats; r++) {
    const double t0 = WallTime();
    PetscCall(op());
    *ms = std::min(*ms, 1e3 * (WallTime() - t0));
  }
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  StencilGrid grid;
  PetscInt    repeats = 10;

  PetscCall(PetscInitialize(&argc, &argv, nullptr,
                            "Times MATSEQBINBCSR's value operations against seqaij and seqbaij.\n"));
  PetscCall(PetscBinBCSRRegisterAll());
  grid.nx = grid.ny = grid.nz = 24;
  PetscCall(StencilGridFromOptions(nullptr, &grid));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &repeats, nullptr));
  /* -repeats 0 printed the unset minimum (inf) for every operation */
  PetscCheck(repeats >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-repeats must be >= 1, not %" PetscInt_FMT, repeats);
  /* the types timed are the sequential ones, on PETSC_COMM_SELF: under mpiexec every rank ran its own copy
     and the tables came out interleaved */
  PetscMPIInt size;
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCheck(
    size == 1, PETSC_COMM_WORLD, PETSC_ERR_SUP,
    "mat_ops_bench times the sequential matrix types on one process: run it without mpiexec, not on %d ranks",
    size);

  const Flavour flavours[] = {
    {"seqaij", MATSEQAIJ, MAT_BINBCSR_PRECISION_DOUBLE},
    {"seqbaij", MATSEQBAIJ, MAT_BINBCSR_PRECISION_DOUBLE},
    {"binbcsr", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_DOUBLE},
    {"binbcsr-single", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_SINGLE},
    {"binbcsr-sym", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_DOUBLE, true},
    {"binbcsr-sym-single", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_SINGLE, true},
  };
  const char *ops[] = {"axpy_same",         "scale",      "shift",       "norm_frobenius", "norm_1",
                       "zero_rows_columns", "diag_scale", "row_max_abs", "col_norms_2",    "vpb_inverse",
                       "nonzero_rows"};
  PetscCall(PetscPrintf(PETSC_COMM_SELF,
                        "27-point 3x3-block stencil, %" PetscInt_FMT "^3 nodes, %" PetscInt_FMT
                        " rows; minimum of %" PetscInt_FMT " runs, ms\n",
                        grid.nx, 3 * grid.nodes(), repeats));
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-16s", "type"));
  for (const char *op : ops) PetscCall(PetscPrintf(PETSC_COMM_SELF, " %18s", op));
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "\n"));

  for (const Flavour &f : flavours) {
    Mat                 A, X;
    Vec                 x, b;
    std::vector<double> ms;
    PetscReal           nrm;
    double              t;

    PetscCall(CreateStencilMatrix(PETSC_COMM_SELF, grid, f.type, nullptr, &A));
    if (f.sym) PetscCall(ReplaceWithBinBCSRSymmetric(&A));
    PetscCall(MatBinBCSRSetPrecision(A, f.precision));
    PetscCall(MatDuplicate(A, MAT_COPY_VALUES, &X));
    PetscCall(MatCreateVecs(A, &x, &b));
    PetscCall(VecSet(x, 1.0));
    PetscCall(VecSet(b, 1.0));
    /* boundary conditions: the unknowns of the z = 0 face */
    std::vector<PetscInt> rows;
    for (PetscInt node = 0; node < grid.nx * grid.ny; node++)
      for (PetscInt c = 0; c < 3; c++) rows.push_back(3 * node + c);

    PetscCall(Time(
      repeats, [&] { return MatAXPY(A, 1e-3, X, SAME_NONZERO_PATTERN); }, &t));
    ms.push_back(t);
    PetscCall(Time(
      repeats, [&] { return MatScale(A, 1.0001); }, &t));
    ms.push_back(t);
    PetscCall(Time(
      repeats, [&] { return MatShift(A, 1e-3); }, &t));
    ms.push_back(t);
    PetscCall(Time(
      repeats, [&] { return MatNorm(A, NORM_FROBENIUS, &nrm); }, &t));
    ms.push_back(t);
    PetscCall(Time(
      repeats, [&] { return MatNorm(A, NORM_1, &nrm); }, &t));
    ms.push_back(t);
    PetscCall(Time(
      repeats, [&] { return MatZeroRowsColumns(A, (PetscInt)rows.size(), rows.data(), 1.0, x, b); }, &t));
    ms.push_back(t);

    {
      Vec                    d, rmax;
      std::vector<PetscInt>  at(3 * grid.nodes());
      std::vector<PetscReal> norms(3 * grid.nodes());
      PetscCall(VecDuplicate(x, &d));
      PetscCall(VecDuplicate(x, &rmax));
      PetscCall(VecSet(d, 1.0001));
      PetscCall(Time(
        repeats, [&] { return MatDiagonalScale(A, d, d); }, &t));
      ms.push_back(t);
      PetscCall(Time(
        repeats, [&] { return MatGetRowMaxAbs(A, rmax, at.data()); }, &t));
      ms.push_back(t);
      PetscCall(Time(
        repeats, [&] { return MatGetColumnNorms(A, NORM_2, norms.data()); }, &t));
      ms.push_back(t);
      PetscCall(VecDestroy(&d));
      PetscCall(VecDestroy(&rmax));
    }
    {
      PetscBool                has;
      std::vector<PetscInt>    sizes(grid.nodes(), 3);
      std::vector<PetscScalar> inv(9 * grid.nodes());
      IS                       kept;
      t = -1; /* not provided by the type */
      PetscCall(MatHasOperation(A, MATOP_INVERT_VBLOCK_DIAGONAL, &has));
      if (has)
        PetscCall(Time(
          repeats,
          [&] { return MatInvertVariableBlockDiagonal(A, (PetscInt)sizes.size(), sizes.data(), inv.data()); },
          &t));
      ms.push_back(t);
      PetscCall(Time(
        repeats,
        [&] {
          PetscCall(MatFindNonzeroRows(A, &kept));
          return ISDestroy(&kept);
        },
        &t));
      ms.push_back(t);
    }

    PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-16s", f.label));
    for (double v : ms) PetscCall(PetscPrintf(PETSC_COMM_SELF, " %18.3f", v));
    PetscCall(PetscPrintf(PETSC_COMM_SELF, "\n"));
    PetscCall(VecDestroy(&x));
    PetscCall(VecDestroy(&b));
    PetscCall(MatDestroy(&X));
    PetscCall(MatDestroy(&A));
  }
  PetscCall(PetscFinalize());
  return 0;
}
