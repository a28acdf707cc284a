#include "sim/stencil.h"
#include <petscbinbcsr.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace {

// Varies the coupling strength from node to node so that rows are not all alike (values in [1, 1.5]).
PetscReal NodeCoefficient(PetscInt i, PetscInt j, PetscInt k)
{
  return 1.0 + 0.05 * (PetscReal)((7 * i + 13 * j + 29 * k) % 11);
}

} // namespace

void StencilBlockRow(const StencilGrid &g, PetscInt node, PetscInt *ncols, PetscInt cols[27],
                     PetscScalar vals[27 * 9])
{
  const PetscInt  i = node % g.nx, j = (node / g.nx) % g.ny, k = node / (g.nx * g.ny);
  const PetscReal cp        = NodeCoefficient(i, j, k);
  PetscReal       offsum[3] = {0, 0, 0}; // absolute off-diagonal sum of each of the block row's 3 rows
  PetscInt        n = 0, diag_slot = -1;
  PetscScalar     blocks[27][3][3];

  // Neighbours in increasing column order: dz outermost, dx innermost.
  for (PetscInt dz = -1; dz <= 1; ++dz)
    for (PetscInt dy = -1; dy <= 1; ++dy)
      for (PetscInt dx = -1; dx <= 1; ++dx) {
        const PetscInt ii = i + dx, jj = j + dy, kk = k + dz;
        if (ii < 0 || ii >= g.nx || jj < 0 || jj >= g.ny || kk < 0 || kk >= g.nz) continue;
        cols[n] = ii + g.nx * (jj + g.ny * kk);
        if (dx == 0 && dy == 0 && dz == 0) {
          diag_slot = n++;
          continue;
        }
        const PetscReal d2 = (PetscReal)(dx * dx + dy * dy + dz * dz);
        const PetscReal w  = 0.5 * (cp + NodeCoefficient(ii, jj, kk)) / d2;
        // |d| / |d| componentwise: every off-diagonal entry is <= 0, so with the diagonal below the
        // matrix is a shifted M-matrix whose smallest eigenvalue falls like n^-2 (as a stiffness
        // matrix's), not a trivially well-conditioned one.
        const PetscReal u[3] = {std::abs(dx) / std::sqrt(d2), std::abs(dy) / std::sqrt(d2),
                                std::abs(dz) / std::sqrt(d2)};
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) {
            blocks[n][a][b] = -w * ((a == b ? 1.0 : 0.0) + 0.5 * u[a] * u[b]);
            offsum[a] += std::fabs(blocks[n][a][b]);
          }
        ++n;
      }
  // Diagonal = the row's absolute off-diagonal sum + shift c_p: just strictly dominant, so the
  // smallest eigenvalue shrinks with the grid (like a stiffness matrix) down to about shift.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) blocks[diag_slot][a][b] = (a == b) ? offsum[a] + g.shift * cp : 0.0;
  *ncols = n;
  for (PetscInt c = 0; c < n; ++c)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) vals[a * 3 * n + 3 * c + b] = blocks[c][a][b];
}

PetscErrorCode CreateStencilMatrix(MPI_Comm comm, const StencilGrid &grid, MatType type, const char *prefix,
                                   Mat *A)
{
  PetscInt    rstart, rend, cols[27], ncols;
  PetscScalar vals[27 * 9];
  PetscBool   is_sbaij = PETSC_FALSE;
  MatType     actual;

  PetscFunctionBegin;
  PetscCheck(grid.nx > 0 && grid.ny > 0 && grid.nz > 0, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "Stencil grid must have at least one node per direction, got %" PetscInt_FMT " x %" PetscInt_FMT
             " x %" PetscInt_FMT,
             grid.nx, grid.ny, grid.nz);
  /* before grid.nodes() is formed: a 2000^3 grid overflowed it and the vectors' sizes */
  PetscCheck(243.0 * grid.nx * grid.ny * grid.nz <= (double)PETSC_MAX_INT, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "Stencil grid %" PetscInt_FMT " x %" PetscInt_FMT " x %" PetscInt_FMT
             ": its %.3g entries exceed PETSc's index range",
             grid.nx, grid.ny, grid.nz, 243.0 * grid.nx * grid.ny * grid.nz);
  PetscCheck(grid.shift > 0 && std::isfinite((double)grid.shift), comm, PETSC_ERR_ARG_OUTOFRANGE,
             "Stencil shift must be positive and finite for an SPD matrix, got %g", (double)grid.shift);
  const PetscInt bs = 3, nodes = grid.nodes();

  // PETSc's default row layout (whole blocks per rank), computed up front to count the preallocation.
  PetscLayout map;
  PetscInt    nlocal;
  PetscCall(PetscLayoutCreate(comm, &map));
  PetscCall(PetscLayoutSetBlockSize(map, bs));
  PetscCall(PetscLayoutSetSize(map, bs * nodes));
  PetscCall(PetscLayoutSetUp(map));
  PetscCall(PetscLayoutGetRange(map, &rstart, &rend));
  PetscCall(PetscLayoutGetLocalSize(map, &nlocal));
  PetscCall(PetscLayoutDestroy(&map));
  rstart /= bs;
  rend /= bs;

  PetscCall(MatCreate(comm, A));
  if (prefix) PetscCall(MatSetOptionsPrefix(*A, prefix));
  PetscCall(MatSetSizes(*A, nlocal, nlocal, bs * nodes, bs * nodes));
  PetscCall(MatSetBlockSize(*A, bs));
  if (type) {
    PetscCall(MatSetType(*A, type));
    PetscCall(MatBinBCSRSetFromOptions(
      *A)); /* -mat_binbcsr_bin_width, ... (not -mat_type: the caller chose the type) */
  } else PetscCall(MatSetFromOptions(*A));

  // Exact preallocation, in blocks (d/o: diagonal/off-diagonal part; u: upper triangle for SBAIJ).
  const PetscInt        m = rend - rstart;
  std::vector<PetscInt> dnnz(m), onnz(m), dnnzu(m), onnzu(m), sd(bs * m), so(bs * m);
  for (PetscInt r = rstart; r < rend; ++r) {
    StencilBlockRow(grid, r, &ncols, cols, vals);
    PetscInt d = 0, o = 0, du = 0, ou = 0;
    for (PetscInt c = 0; c < ncols; ++c) {
      const bool local = cols[c] >= rstart && cols[c] < rend;
      (local ? d : o)++;
      if (cols[c] >= r) (local ? du : ou)++;
    }
    dnnz[r - rstart]  = d;
    onnz[r - rstart]  = o;
    dnnzu[r - rstart] = du;
    onnzu[r - rstart] = ou;
    for (PetscInt a = 0; a < bs; ++a) {
      sd[bs * (r - rstart) + a] = bs * d;
      so[bs * (r - rstart) + a] = bs * o;
    }
  }
  PetscCall(MatXAIJSetPreallocation(*A, bs, dnnz.data(), onnz.data(), dnnzu.data(), onnzu.data()));
  // MatXAIJSetPreallocation does not reach SELL; these are no-ops on other types.
  PetscCall(MatSeqSELLSetPreallocation(*A, 0, sd.data()));
  PetscCall(MatMPISELLSetPreallocation(*A, 0, sd.data(), 0, so.data()));
  PetscCall(MatSetUp(*A));

  PetscCall(MatGetType(*A, &actual));
  is_sbaij = (PetscBool)(std::strstr(actual, "sbaij") != nullptr);
  if (is_sbaij) PetscCall(MatSetOption(*A, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));

  for (PetscInt r = rstart; r < rend; ++r) {
    StencilBlockRow(grid, r, &ncols, cols, vals);
    PetscCall(MatSetValuesBlocked(*A, 1, &r, ncols, cols, vals, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
  // PETSc 3.18's MPIBAIJ refuses MAT_SPD as an unknown option; the flag is only a hint, so a type
  // that refuses it still gets a usable matrix.
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
  const PetscErrorCode spd_err = MatSetOption(*A, MAT_SPD, PETSC_TRUE);
  PetscCall(PetscPopErrorHandler());
  PetscCheck(!spd_err || spd_err == PETSC_ERR_SUP, comm, spd_err, "MatSetOption(MAT_SPD) failed");
  PetscFunctionReturn(0);
}

PetscErrorCode StencilGridFromOptions(const char *prefix, StencilGrid *grid)
{
  PetscInt  n;
  PetscBool set;

  PetscFunctionBegin;
  PetscCall(PetscOptionsGetInt(nullptr, prefix, "-stencil_n", &n, &set));
  if (set) grid->nx = grid->ny = grid->nz = n;
  PetscCall(PetscOptionsGetInt(nullptr, prefix, "-stencil_nx", &grid->nx, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, prefix, "-stencil_ny", &grid->ny, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, prefix, "-stencil_nz", &grid->nz, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, prefix, "-stencil_shift", &grid->shift, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode StencilSizesFromOptions(MPI_Comm comm, const char *program,
                                       const std::vector<PetscInt> &defaults, PetscInt max_sizes,
                                       std::vector<PetscInt> *sizes)
{
  std::vector<PetscInt> buf(max_sizes + 1); // one more than it takes: PETSc drops extras silently
  PetscInt              n = max_sizes + 1, one;
  PetscBool             listed, single, other = PETSC_FALSE, o;

  PetscFunctionBegin;
  PetscCall(PetscOptionsGetIntArray(nullptr, nullptr, "-stencil_sizes", buf.data(), &n, &listed));
  PetscCheck(n <= max_sizes, comm, PETSC_ERR_ARG_SIZ,
             "%s: -stencil_sizes takes at most %" PetscInt_FMT " sizes", program, max_sizes);
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-stencil_n", &one, &single));
  PetscCheck(!(listed && single), comm, PETSC_ERR_ARG_WRONG,
             "%s: give the stencils by -stencil_sizes or -stencil_n, not both", program);
  for (const char *name : {"-stencil_nx", "-stencil_ny", "-stencil_nz", "-stencil_shift"}) {
    PetscCall(PetscOptionsHasName(nullptr, nullptr, name, &o));
    other = (PetscBool)(other || o);
  }
  PetscCheck(!other, comm, PETSC_ERR_ARG_WRONG,
             "%s: its stencils are cubes given by -stencil_sizes N,M,... or -stencil_n N; -stencil_nx, "
             "-stencil_ny, -stencil_nz and -stencil_shift are not read here",
             program);
  if (listed) sizes->assign(buf.begin(), buf.begin() + n);
  else if (single) sizes->assign(1, one);
  else *sizes = defaults;
  for (PetscInt s : *sizes)
    PetscCheck(s >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE,
               "%s: %" PetscInt_FMT " is no grid size (0: no stencil)", program, s);
  PetscFunctionReturn(0);
}
