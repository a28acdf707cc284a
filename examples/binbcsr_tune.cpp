// binbcsr_tune: MatMult of MATSEQBINBCSR for several bin widths and both precisions against seqbaij
// and seqaij on the 27-point 3x3-block stencil, timed round-robin in one run (so load from other
// processes hits all variants alike); reports the minimum over the rounds. This is the measurement
// behind the default bin width (docs/mat_binbcsr.md).
//
//   binbcsr_tune [-stencil_n 48] [-bin_widths 1,2,4,8,16,32] [-repeats 15] [-batch 10] [-bs 3]
//
// -bs 1 measures BIN-CSR on the same stencil seen as a scalar matrix.
#include <petscbinbcsr.h>
#include "common/stencil.h"
#include <string>
#include <vector>

namespace
{
struct Variant {
  std::string name;
  Mat         A   = nullptr;
  double      best = 1e300;
};

PetscErrorCode MakeBinBCSR(Mat src, PetscInt bs, PetscInt bw, MatBinBCSRPrecision prec, Mat *A)
{
  PetscInt m, n;

  PetscFunctionBeginUser;
  PetscCall(MatGetLocalSize(src, &m, &n));
  PetscCall(MatCreate(PETSC_COMM_SELF, A));
  PetscCall(MatSetSizes(*A, m, n, m, n));
  PetscCall(MatSetBlockSize(*A, bs));
  PetscCall(MatSetType(*A, MATSEQBINBCSR));
  PetscCall(MatBinBCSRSetBinWidth(*A, bw));
  PetscCall(MatBinBCSRSetPrecision(*A, prec));
  PetscCall(MatSetUp(*A));
  for (PetscInt r = 0; r < m; r++) {
    PetscInt           nc;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(src, r, &nc, &cols, &vals));
    PetscCall(MatSetValues(*A, 1, &r, nc, cols, vals, INSERT_VALUES));
    PetscCall(MatRestoreRow(src, r, &nc, &cols, &vals));
  }
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}
} // namespace

int main(int argc, char **argv)
{
  StencilGrid          grid;
  PetscInt             widths[16] = {1, 2, 4, 8, 16, 32}, nw = 6, repeats = 15, batch = 10, bs = 3;
  std::vector<Variant> vars;
  Mat                  aij, baij;
  Vec                  x, y;

  PetscCall(PetscInitialize(&argc, &argv, nullptr, nullptr));
  PetscCall(PetscBinBCSRRegisterAll());
  grid.nx = grid.ny = grid.nz = 48;
  PetscCall(StencilGridFromOptions(nullptr, &grid));
  {
    PetscInt  nset = 16;
    PetscBool flg;
    PetscCall(PetscOptionsGetIntArray(nullptr, nullptr, "-bin_widths", widths, &nset, &flg));
    if (flg) nw = nset;
  }
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &repeats, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-batch", &batch, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-bs", &bs, nullptr));

  PetscCall(CreateStencilMatrix(PETSC_COMM_SELF, grid, MATSEQAIJ, nullptr, &aij));
  PetscCall(CreateStencilMatrix(PETSC_COMM_SELF, grid, MATSEQBAIJ, nullptr, &baij));
  if (bs == 1) PetscCall(MatSetBlockSize(aij, 1));
  vars.push_back({"seqaij", aij});
  vars.push_back({"seqbaij", baij});
  for (PetscInt w = 0; w < nw; w++)
    for (int p = 0; p < 2; p++) {
      Variant v;
      v.name = std::string(p ? "single" : "double") + " bw " + std::to_string(widths[w]);
      PetscCall(MakeBinBCSR(aij, bs, widths[w], p ? MAT_BINBCSR_PRECISION_SINGLE : MAT_BINBCSR_PRECISION_DOUBLE, &v.A));
      vars.push_back(v);
    }
  PetscCall(MatCreateVecs(aij, &x, &y));
  PetscCall(VecSet(x, 1.0));
  for (PetscInt r = 0; r < repeats; r++)
    for (Variant &v : vars) {
      PetscCall(MatMult(v.A, x, y)); /* warm */
      const double t0 = MPI_Wtime();
      for (PetscInt b = 0; b < batch; b++) PetscCall(MatMult(v.A, x, y));
      v.best = PetscMin(v.best, (MPI_Wtime() - t0) / batch);
    }
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "stencil %" PetscInt_FMT "^3, bs %" PetscInt_FMT ", %" PetscInt_FMT " rounds of %" PetscInt_FMT " MatMults, minimum per MatMult\n", grid.nx, bs, repeats, batch));
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-16s %10s %8s %8s\n", "variant", "ms", "x baij", "x aij"));
  for (Variant &v : vars) PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-16s %10.4f %8.2f %8.2f\n", v.name.c_str(), 1e3 * v.best, vars[1].best / v.best, vars[0].best / v.best));
  for (Variant &v : vars) PetscCall(MatDestroy(&v.A));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&y));
  PetscCall(PetscFinalize());
  return 0;
}
