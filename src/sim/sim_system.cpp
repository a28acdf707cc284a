#include "sim/sim_system.h"
#include "sim/gamg_coarse_space.h"

#include "sim/pc_failure.h"
#include "petsc_compat.h" // PetscOptionsPushCreateViewerOff

#include <petscbinbcsr.h>

#include <algorithm>
#include <string>
#include <vector>

namespace {

// PETSc without CUDA/HIP/Kokkos reports a GPU type as merely "unknown"; say why instead.
PetscErrorCode CheckMatTypeAvailable(MPI_Comm comm)
{
  char      type[256] = "";
  PetscBool set       = PETSC_FALSE;

  PetscFunctionBegin;
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-mat_type", type, sizeof type, &set));
  if (!set) PetscFunctionReturn(0);
  const std::string t      = type;
  const bool        cuda   = t.find("cusparse") != std::string::npos || t.find("cuda") != std::string::npos;
  const bool        hip    = t.find("hipsparse") != std::string::npos || t.find("hip") == 0;
  const bool        kokkos = t.find("kokkos") != std::string::npos;
#if !defined(PETSC_HAVE_CUDA)
  PetscCheck(!cuda, comm, PETSC_ERR_SUP,
             "-mat_type %s needs a PETSc configured with CUDA, and this PETSc has no CUDA support; "
             "use -mat_type aij, baij, sell or binbcsr",
             type);
#endif
#if !defined(PETSC_HAVE_HIP)
  PetscCheck(!hip, comm, PETSC_ERR_SUP,
             "-mat_type %s needs a PETSc configured with HIP, and this PETSc has no HIP support; "
             "use -mat_type aij, baij, sell or binbcsr",
             type);
#endif
#if !defined(PETSC_HAVE_KOKKOS_KERNELS)
  PetscCheck(!kokkos, comm, PETSC_ERR_SUP,
             "-mat_type %s needs a PETSc configured with Kokkos, and this PETSc has none; "
             "use -mat_type aij, baij, sell or binbcsr",
             type);
#endif
  (void)cuda;
  (void)hip;
  (void)kokkos;
  PetscFunctionReturn(0);
}

// Exact per-row lengths of the block pattern (all ranks' contributions), computed through an aij
// matrix of the block graph (native COO, handles off-rank entries), then handed to the preallocation
// routines of every family (each is a no-op for the other families).
// Also returns the number of distinct blocks over all ranks (nnz / 9). A may be null (count only).
PetscErrorCode PreallocateFromBlockPattern(MPI_Comm comm, PetscInt n_local, PetscInt n_global,
                                           const std::vector<PetscInt> &rows,
                                           const std::vector<PetscInt> &cols, Mat A, PetscInt *n_blocks)
{
  Mat      graph;
  PetscInt bstart, bend;

  PetscFunctionBegin;
  PetscCall(MatCreate(comm, &graph));
  PetscCall(MatSetSizes(graph, n_local, n_local, n_global, n_global));
  PetscCall(MatSetType(graph, MATAIJ));
  // Viewers off while the graph is filled, so that a user's -mat_view shows the system matrix only:
  // the graph's own assembly, and on more ranks those of MPIAIJ's parts, which its COO preallocation
  // assembles on their own (a prefix on the graph would not reach them).
  PetscCall(PetscOptionsPushCreateViewerOff(PETSC_TRUE));
  {
    std::vector<PetscInt> ci(rows), cj(cols);
    PetscCall(MatSetPreallocationCOO(graph, (PetscCount)ci.size(), ci.data(), cj.data()));
  }
  std::vector<PetscScalar> ones(rows.size(), 1.0);
  PetscCall(MatSetValuesCOO(graph, ones.data(), INSERT_VALUES));
  PetscCall(PetscOptionsPopCreateViewerOff());
  PetscCall(MatGetOwnershipRange(graph, &bstart, &bend));
  {
    MatInfo info;
    PetscCall(MatGetInfo(graph, MAT_GLOBAL_SUM, &info));
    *n_blocks = (PetscInt)info.nz_used;
  }
  if (!A) {
    PetscCall(MatDestroy(&graph));
    PetscFunctionReturn(0);
  }
  // sbaij stores the upper triangle only: it gets its own (upper) counts.
  std::vector<PetscInt> d_blocks(n_local), o_blocks(n_local), du_blocks(n_local), ou_blocks(n_local);
  std::vector<PetscInt> d_rows(3 * n_local), o_rows(3 * n_local);
  PetscInt              d_max = 0, o_max = 0;
  for (PetscInt i = bstart; i < bend; ++i) {
    PetscInt        ncols;
    const PetscInt *c;
    PetscInt        d = 0, o = 0, du = 0, ou = 0;
    PetscCall(MatGetRow(graph, i, &ncols, &c, nullptr));
    for (PetscInt k = 0; k < ncols; ++k) {
      const bool local = c[k] >= bstart && c[k] < bend;
      local ? ++d : ++o;
      if (c[k] >= i) local ? ++du : ++ou;
    }
    PetscCall(MatRestoreRow(graph, i, &ncols, &c, nullptr));
    d_blocks[i - bstart]  = d;
    o_blocks[i - bstart]  = o;
    du_blocks[i - bstart] = du;
    ou_blocks[i - bstart] = ou;
    for (int r = 0; r < 3; ++r) {
      d_rows[3 * (i - bstart) + r] = 3 * d;
      o_rows[3 * (i - bstart) + r] = 3 * o;
    }
    d_max = std::max(d_max, 3 * d);
    o_max = std::max(o_max, 3 * o);
  }
  PetscCall(MatDestroy(&graph));
  PetscCall(
    MatXAIJSetPreallocation(A, 3, d_blocks.data(), o_blocks.data(), du_blocks.data(), ou_blocks.data()));
  {
    // The drivers hand over both triangles of their symmetric systems; sbaij keeps the upper one.
    PetscBool is_sbaij;
    PetscCall(PetscObjectTypeCompareAny((PetscObject)A, &is_sbaij, MATSEQSBAIJ, MATMPISBAIJ, ""));
    if (is_sbaij) PetscCall(MatSetOption(A, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));
  }
  PetscCall(MatSeqSELLSetPreallocation(A, d_max, d_rows.data()));
  PetscCall(MatMPISELLSetPreallocation(A, d_max, d_rows.data(), o_max, o_rows.data()));
  PetscCall(MatSetUp(A));
  PetscFunctionReturn(0);
}

PetscErrorCode MatStoredTriangle(Mat A, PetscBool *upper_only, PetscBool *offrank_full, PetscBool *mirrored)
{
  PetscBool is_sbaij, sym = PETSC_FALSE, mirror = PETSC_FALSE;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)A, &is_sbaij, MATSEQSBAIJ, MATMPISBAIJ, MATSBAIJ, ""));
  PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym)); // PETSC_FALSE for other types
  PetscCall(MatBinBCSRGetCOOMirror(A, &mirror));     // PETSC_FALSE for other types
  *upper_only   = (is_sbaij || sym) ? PETSC_TRUE : PETSC_FALSE;
  *offrank_full = (!is_sbaij && sym) ? PETSC_TRUE : PETSC_FALSE;
  *mirrored     = mirror;
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode BlockSystemStoredTriangle(MPI_Comm comm, PetscBool *upper_only, PetscBool *offrank_full,
                                         PetscInt *bin_width, PetscBool *lower_mirrored)
{
  Mat       probe;
  PetscBool mirrored;

  PetscFunctionBegin;
  PetscCall(CheckMatTypeAvailable(comm));
  // A one-block-row-per-rank matrix of the type the options select, thrown away after the question.
  PetscCall(MatCreate(comm, &probe));
  PetscCall(MatSetSizes(probe, 3, 3, PETSC_DETERMINE, PETSC_DETERMINE));
  PetscCall(MatSetBlockSize(probe, 3));
  // no MatSetType(MATAIJ) first: MatSetFromOptions takes aij by default, and an aij made first printed
  // its own "Matrix (Mat) options" under -help, after which PETSc printed that block no more, so the
  // -mat_type and -mat_binbcsr_* lines never showed
  PetscCall(MatSetFromOptions(probe));
  PetscCall(MatStoredTriangle(probe, upper_only, offrank_full, &mirrored));
  if (lower_mirrored) *lower_mirrored = mirrored;
  if (bin_width) PetscCall(MatBinBCSRGetBinWidth(probe, bin_width)); // 0 for other types
  PetscCall(MatDestroy(&probe));
  PetscFunctionReturn(0);
}

/* A scene's fixed iteration count (-ksp_mcg_fixed_iterations N, N > 0) carried over to another
   -ksp_type: N iterations with no norm and no convergence test, as KSPMCG's fixed mode. So a scene
   file and a comparison file giving only -mat_type and -ksp_type (options/compare_aij_cg.opts) run
   the same iterations as the scene where it fixes them, and the scene's tolerance where it has one
   (a comparison file that skipped the test itself ran a converged scene's -ksp_max_it 5000
   untested iterations into a blow-up). */
static PetscErrorCode CarryFixedIterations(KSP ksp)
{
  PetscBool   mcg, set;
  PetscInt    n      = 0;
  const char *prefix = nullptr;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPMCG, &mcg));
  if (mcg) PetscFunctionReturn(0);
  PetscCall(KSPGetOptionsPrefix(ksp, &prefix));
  PetscCall(PetscOptionsGetInt(nullptr, prefix, "-ksp_mcg_fixed_iterations", &n, &set));
  if (!set || n <= 0) PetscFunctionReturn(0);
  PetscCall(KSPSetTolerances(ksp, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, n));
  PetscCall(KSPSetNormType(ksp, KSP_NORM_NONE));
  PetscCall(KSPSetConvergenceTest(ksp, KSPConvergedSkip, nullptr, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemCreate(MPI_Comm comm, PetscInt n_block_rows_global, PetscInt n_block_rows_local,
                                 const std::vector<PetscInt> &coo_block_row,
                                 const std::vector<PetscInt> &coo_block_col, BlockSystem *sys)
{
  PetscFunctionBegin;
  PetscCheck(sys, comm, PETSC_ERR_ARG_NULL, "BlockSystem pointer is null");
  PetscCheck(n_block_rows_global > 0, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "need at least one block row, got %" PetscInt_FMT, n_block_rows_global);
  PetscCheck(coo_block_row.size() == coo_block_col.size(), PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "COO block lists differ in length: %zu rows, %zu columns", coo_block_row.size(),
             coo_block_col.size());
  PetscCheck(coo_block_row.size() * 9 < (size_t)PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "%zu COO blocks expand to more scalar entries than 32-bit PetscInt can index",
             coo_block_row.size());
  for (size_t k = 0; k < coo_block_row.size(); ++k) {
    PetscCheck(coo_block_row[k] >= 0 && coo_block_row[k] < n_block_rows_global && coo_block_col[k] >= 0 &&
                 coo_block_col[k] < n_block_rows_global,
               PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "COO block %zu is (%" PetscInt_FMT ", %" PetscInt_FMT "), outside [0, %" PetscInt_FMT ")", k,
               coo_block_row[k], coo_block_col[k], n_block_rows_global);
  }
  PetscCall(CheckMatTypeAvailable(comm));

  *sys                     = BlockSystem{};
  sys->n_block_rows_global = n_block_rows_global;
  sys->coo_block_row       = coo_block_row;
  sys->coo_block_col       = coo_block_col;
  sys->n_coo_blocks        = (PetscInt)coo_block_row.size();

  PetscInt n_local = n_block_rows_local;
  PetscCall(PetscSplitOwnership(comm, &n_local, &n_block_rows_global));
  sys->n_block_rows_local = n_local;

  PetscCall(MatCreate(comm, &sys->A));
  PetscCall(MatSetSizes(sys->A, 3 * n_local, 3 * n_local, 3 * n_block_rows_global, 3 * n_block_rows_global));
  PetscCall(MatSetBlockSize(sys->A, 3));
  PetscCall(MatSetFromOptions(sys->A)); // aij unless -mat_type says otherwise
  {
    PetscBool offrank_full, mirrored;
    PetscCall(MatStoredTriangle(sys->A, &sys->upper_only, &offrank_full, &mirrored));
    if (mirrored) sys->upper_only = PETSC_TRUE; // the caller lists the upper triangle, the Mat mirrors it
    for (size_t k = 0; mirrored && k < coo_block_row.size(); ++k)
      PetscCheck(
        coo_block_row[k] <= coo_block_col[k], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
        "COO block %zu is (%" PetscInt_FMT ", %" PetscInt_FMT
        "), below the diagonal, but -mat_binbcsr_coo_mirror "
        "fills the lower triangle from the upper one: list the upper triangle only (see BlockSystemStoredTriangle)",
        k, coo_block_row[k], coo_block_col[k]);
  }

  // The block graph for the structural count (and the row lengths): an upper-triangle list stands
  // for its mirror image too, so nnz counts the whole symmetric matrix whatever the caller listed.
  std::vector<PetscInt> graph_row(coo_block_row), graph_col(coo_block_col);
  if (sys->upper_only)
    for (size_t k = 0; k < coo_block_row.size(); ++k)
      if (coo_block_row[k] < coo_block_col[k]) {
        graph_row.push_back(coo_block_col[k]);
        graph_col.push_back(coo_block_row[k]);
      }
  {
    PetscErrorCode (*f)(Mat, PetscCount, const PetscInt[], const PetscInt[]) = nullptr;
    PetscCall(PetscObjectQueryFunction((PetscObject)sys->A, "MatSetPreallocationCOO_C", &f));
    sys->native_coo = f ? PETSC_TRUE : PETSC_FALSE;
  }
  if (sys->native_coo) {
    // 9 scalar entries per block, row-major, so block values need no reordering.
    const size_t          nb = coo_block_row.size();
    std::vector<PetscInt> ci(9 * nb), cj(9 * nb);
    for (size_t k = 0; k < nb; ++k)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          ci[9 * k + 3 * r + c] = 3 * coo_block_row[k] + r;
          cj[9 * k + 3 * r + c] = 3 * coo_block_col[k] + c;
        }
    PetscCall(MatSetPreallocationCOO(sys->A, (PetscCount)ci.size(), ci.data(), cj.data()));
    {
      PetscBool           binbcsr;
      MatBinBCSRPrecision precision;
      PetscCall(PetscObjectTypeCompareAny((PetscObject)sys->A, &binbcsr, MATSEQBINBCSR, MATMPIBINBCSR, ""));
      PetscCall(MatBinBCSRGetPrecision(sys->A, &precision));
      sys->single_values = binbcsr && precision == MAT_BINBCSR_PRECISION_SINGLE ? PETSC_TRUE : PETSC_FALSE;
    }
    PetscCall(PreallocateFromBlockPattern(comm, n_local, n_block_rows_global, graph_row, graph_col, nullptr,
                                          &sys->n_blocks));
  } else {
    // PETSc 3.18's generic COO preallocation cannot preallocate sell; preallocate every other type
    // from the exact row lengths instead.
    PetscCall(PreallocateFromBlockPattern(comm, n_local, n_block_rows_global, graph_row, graph_col, sys->A,
                                          &sys->n_blocks));
    PetscCall(MatSetOption(sys->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  }
  PetscCall(MatSetOption(sys->A, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatGetOwnershipRange(sys->A, &sys->row_begin, &sys->row_end));

  PetscCall(MatCreateVecs(sys->A, &sys->x, &sys->b));
  PetscCall(KSPCreate(comm, &sys->ksp));
  PetscCall(KSPSetOperators(sys->ksp, sys->A, sys->A));
  PetscCall(KSPSetType(sys->ksp, KSPCG));
  {
    PC pc;
    PetscCall(KSPGetPC(sys->ksp, &pc));
    PetscCall(PCSetType(pc, PCJACOBI)); // what the seed uses; works for every Mat type
  }
  PetscCall(KSPSetFromOptions(sys->ksp));
  PetscCall(CarryFixedIterations(sys->ksp));
  { // KSPSetFromOptions stores -ksp_rtol and friends without KSPSetTolerances' checks; NaN ran CG to its
    // iteration limit and called the result converged
    PetscReal rtol, abstol, divtol;
    PetscInt  max_it;
    PetscCall(KSPGetTolerances(sys->ksp, &rtol, &abstol, &divtol, &max_it));
    PetscCheck(rtol >= 0 && rtol < 1 && abstol >= 0 && !PetscIsNanReal(divtol), comm,
               PETSC_ERR_ARG_OUTOFRANGE,
               "the solver's tolerances: -ksp_rtol %g (in [0, 1)), -ksp_atol %g (>= 0), -ksp_divtol %g",
               (double)rtol, (double)abstol, (double)divtol);
  }
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-initial_guess_scaled", &sys->guess_scaled, nullptr));
  if (sys->guess_scaled) PetscCall(VecDuplicate(sys->b, &sys->r));
  PetscCall(
    PetscOptionsGetReal(nullptr, nullptr, "-reuse_preconditioner_growth", &sys->reuse_growth, nullptr));
  PetscCheck(sys->reuse_growth == 0 || sys->reuse_growth >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-reuse_preconditioner_growth %g: 0 (never set up again) or >= 1", (double)sys->reuse_growth);
  PetscCall(GAMGSmootherCopiesFromOptions(comm, &sys->gamg_copies));
  PetscCall(
    PetscOptionsGetBool(nullptr, nullptr, "-gamg_refit_coarse_space", &sys->refit_coarse_space, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemSetRigidBodyModes(BlockSystem *sys, const PetscScalar *coords_local)
{
  Vec          coords;
  MatNullSpace modes;
  PetscScalar *c;

  PetscFunctionBegin;
  PetscCall(MatCreateVecs(sys->A, &coords, nullptr));
  PetscCall(VecSetBlockSize(coords, 3));
  PetscCall(VecGetArrayWrite(coords, &c));
  for (PetscInt i = 0; i < sys->row_end - sys->row_begin; i++) c[i] = coords_local[i];
  PetscCall(VecRestoreArrayWrite(coords, &c));
  PetscCall(MatNullSpaceCreateRigidBody(coords, &modes));
  PetscCall(MatSetNearNullSpace(sys->A, modes));
  PetscCall(MatNullSpaceDestroy(&modes));
  PetscCall(VecDestroy(&coords));
  sys->mode_coords.assign(coords_local, coords_local + (sys->row_end - sys->row_begin));
  { // PCGAMG reads a near null space at its first set-up only; coordinates, at each set-up that builds
    // its coarse space
    PC        pc;
    PetscBool gamg, set;
    PetscCall(KSPGetPC(sys->ksp, &pc));
    PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCGAMG, &gamg));
    PetscCall(PCGetOperatorsSet(pc, nullptr, &set));
    if (gamg && set) {
      std::vector<PetscReal> xyz(coords_local, coords_local + (sys->row_end - sys->row_begin));
      PetscCall(PCSetCoordinates(pc, 3, (sys->row_end - sys->row_begin) / 3, xyz.data()));
    }
  }
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemSetValues(BlockSystem *sys, const PetscScalar *block_values)
{
  PetscFunctionBegin;
  PetscCheck(sys && sys->A, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "BlockSystem not created");
  sys->last_values        = block_values;
  sys->last_values_single = nullptr;
  sys->values_set         = PETSC_TRUE;
  if (sys->native_coo) {
    PetscCall(MatSetValuesCOO(sys->A, block_values, INSERT_VALUES));
  } else {
    PetscCall(MatZeroEntries(sys->A));
    for (PetscInt k = 0; k < sys->n_coo_blocks; ++k) {
      const PetscInt r = sys->coo_block_row[k], c = sys->coo_block_col[k];
      PetscCall(MatSetValuesBlocked(sys->A, 1, &r, 1, &c, block_values + 9 * k, ADD_VALUES));
    }
    PetscCall(MatAssemblyBegin(sys->A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(sys->A, MAT_FINAL_ASSEMBLY));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemSetValuesSingle(BlockSystem *sys, const float *block_values)
{
  PetscFunctionBegin;
  PetscCheck(sys && sys->A, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "BlockSystem not created");
  PetscCheck(sys->single_values, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "BlockSystemSetValuesSingle: this system's matrix takes BlockSystemSetValues");
  sys->last_values        = nullptr;
  sys->last_values_single = block_values;
  sys->values_set         = PETSC_TRUE;
  PetscCall(MatBinBCSRSetValuesCOOSingle(sys->A, block_values, INSERT_VALUES));
  PetscFunctionReturn(0);
}

/* x = a x with a = (b . A x) / (A x . A x), the factor that minimises ||b - a A x||: then ||b - a A x||
   <= ||b||, so a guess can no longer start a solve further from b than zero does. The tolerances are
   relative to ||b||: on the cloth the last step's dv left ||b - A dv|| at 1-3.6 ||b|| in most steps
   on the sphere (60 steps, docs/cloth.md), and every such guess cost CG iterations. One product and
   one reduction (the two dots together). */
static PetscErrorCode ScaleGuess(BlockSystem *sys, SolveStats *stats)
{
  PetscScalar dots[2];
  Vec         v[2];

  PetscFunctionBegin;
  PetscCall(MatMult(sys->A, sys->x, sys->r));
  v[0] = sys->b;
  v[1] = sys->r;
  PetscCall(VecMDot(sys->r, 2, v, dots)); // (A x . b, A x . A x)
  const PetscReal a = PetscRealPart(dots[1]) > 0 ? PetscRealPart(dots[0]) / PetscRealPart(dots[1]) : 0;
  PetscCheck(!PetscIsInfOrNanReal(a), PetscObjectComm((PetscObject)sys->A), PETSC_ERR_FP,
             "-initial_guess_scaled: the guess or its product is not finite");
  PetscCall(VecScale(sys->x, a));
  if (stats) stats->guess_scale = a;
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemSolve(BlockSystem *sys, const PetscScalar *rhs_local, PetscScalar *sol_local,
                                SolveStats *stats)
{
  PetscScalar *a;
  PetscBool    nonzero_guess;
  const size_t n = (size_t)(sys->row_end - sys->row_begin);

  PetscFunctionBegin;
  // std::copy_n, not memcpy: a rank without rows has null arrays (PETSc allocates nothing for an
  // empty Vec, std::vector nothing for an empty one), and memcpy of null is undefined even for 0 bytes
  PetscCall(VecGetArrayWrite(sys->b, &a));
  std::copy_n(rhs_local, n, a);
  PetscCall(VecRestoreArrayWrite(sys->b, &a));
  PetscCall(KSPGetInitialGuessNonzero(sys->ksp, &nonzero_guess));
  if (nonzero_guess) {
    PetscCall(VecGetArrayWrite(sys->x, &a));
    std::copy_n(sol_local, n, a);
    PetscCall(VecRestoreArrayWrite(sys->x, &a));
  }
  const double t0 = MPI_Wtime();
  if (stats) stats->guess_scale = 1;
  if (nonzero_guess && sys->guess_scaled) PetscCall(ScaleGuess(sys, stats));
  PetscBool reuse, rebuild = PETSC_FALSE;
  PetscCall(KSPGetReusePreconditioner(sys->ksp, &reuse));
  if (reuse && sys->rebuild_next) { // the preconditioner set up again on this matrix, before the solve
    PC        pc;
    PetscBool gamg;
    PetscCall(KSPGetPC(sys->ksp, &pc));
    PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCGAMG, &gamg));
    // GAMG: a new coarse space, not only new Galerkin products of the old interpolation: refitted on
    // its aggregates where it can be (then GAMG reuses the refitted interpolation), else built anew
    if (gamg) {
      PetscBool refit = PETSC_FALSE;
      if (sys->refit_coarse_space && !sys->mode_coords.empty()) {
        std::vector<Mat> interp;
        PetscCall(GAMGSmootherCopiesOwnInterpolations(pc, &sys->gamg_copies, &interp));
        PetscCall(GAMGRefitCoarseSpace(PetscObjectComm((PetscObject)pc), interp, sys->mode_coords.data(),
                                       (PetscInt)sys->mode_coords.size() / 3, &refit));
      }
      PetscCall(PCGAMGSetReuseInterpolation(pc, refit));
      sys->pc_refits += refit;
    }
    PetscCall(KSPSetReusePreconditioner(sys->ksp, PETSC_FALSE));
    PetscCall(GAMGSmootherCopiesUpdate(sys->ksp, &sys->gamg_copies)); // (hands GAMG its own levels back)
    PetscCall(PCSetUp(pc));
    // reused again before KSPSolve, which would otherwise reset the initial guess's history
    PetscCall(KSPSetReusePreconditioner(sys->ksp, PETSC_TRUE));
    rebuild = PETSC_TRUE;
    sys->pc_rebuilds++;
  }
  PetscCall(GAMGSmootherCopiesUpdate(sys->ksp, &sys->gamg_copies));
  PetscCall(KSPSolve(sys->ksp, sys->b, sys->x));
  const double t1 = MPI_Wtime();
  PetscInt     its;
  PetscCall(KSPGetIterationNumber(sys->ksp, &its));
  if (reuse) {
    if (rebuild || sys->fewest_its < 0 || its < sys->fewest_its) sys->fewest_its = its;
    // the same on every rank: the iteration count is the KSP's, collective
    sys->rebuild_next = sys->reuse_growth > 0 && its > sys->reuse_growth * PetscMax(sys->fewest_its, 1)
                          ? PETSC_TRUE
                          : PETSC_FALSE;
  }
  const PetscScalar *xa;
  PetscCall(VecGetArrayRead(sys->x, &xa));
  std::copy_n(xa, n, sol_local);
  PetscCall(VecRestoreArrayRead(sys->x, &xa));
  if (stats) {
    stats->iterations = its;
    PetscCall(KSPGetResidualNorm(sys->ksp, &stats->residual_norm));
    PetscCall(KSPGetConvergedReason(sys->ksp, &stats->reason));
    stats->pc_failure.clear();
    if (stats->reason == KSP_DIVERGED_PC_FAILED) PetscCall(DescribePCFailure(sys->ksp, &stats->pc_failure));
    if (stats->reason == KSP_DIVERGED_BREAKDOWN) { /* KSPMCG's precision floor: say so, and what helps */
      PetscReal floor;
      PetscBool stopped;
      PetscCall(KSPMCGGetPrecisionFloor(sys->ksp, &floor, &stopped));
      if (stopped) {
        char detail[200];
        PetscCall(PetscSNPrintf(detail, sizeof detail,
                                "stopped at the precision floor u ||A|| ||x|| = %.3g of the rounded operator "
                                "before the tolerance: loosen -ksp_rtol or store double values",
                                (double)floor));
        stats->pc_failure = detail;
      }
    }
    stats->ms = 1e3 * (t1 - t0);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemDumpMatrix(BlockSystem *sys, const char *path)
{
  MPI_Comm    comm;
  PetscViewer viewer;
  Mat         aij;

  PetscFunctionBegin;
  PetscCall(PetscObjectGetComm((PetscObject)sys->A, &comm));
  // Checked on every rank alike: a rank with no blocks of its own has no value array (the check was on
  // that array, and such a rank stopped alone, without a message from the others).
  PetscCheck(sys->values_set, comm, PETSC_ERR_ARG_WRONGSTATE, "BlockSystemDumpMatrix: no values set yet");
  // Rebuilt as aij from the same COO list, so the dump works for every type (binbcsr has no MatView
  // to binary of its own) and loads anywhere.
  PetscCall(MatCreate(comm, &aij));
  PetscCall(MatSetOptionsPrefix(aij, "sim_dump_")); // -mat_view is for the system matrix
  PetscCall(MatSetSizes(aij, sys->row_end - sys->row_begin, sys->row_end - sys->row_begin,
                        3 * sys->n_block_rows_global, 3 * sys->n_block_rows_global));
  PetscCall(MatSetBlockSize(aij, 3));
  PetscCall(MatSetType(aij, MATAIJ));
  {
    // A matrix that ignores the lower triangle is dumped from the upper blocks and their mirror
    // images (lower blocks the caller still listed, e.g. across ranks, are left out: the mirror
    // of their upper twin replaces them).
    std::vector<PetscInt>    ci, cj;
    std::vector<PetscScalar> v;
    for (size_t k = 0; k < sys->coo_block_row.size(); ++k) {
      const PetscInt br = sys->coo_block_row[k], bc = sys->coo_block_col[k];
      if (sys->upper_only && br > bc) continue;
      for (int mirror = 0; mirror < ((sys->upper_only && br < bc) ? 2 : 1); ++mirror)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) {
            ci.push_back(3 * (mirror ? bc : br) + r);
            cj.push_back(3 * (mirror ? br : bc) + c);
            v.push_back(sys->last_values_single
                          ? sys->last_values_single[9 * k + (mirror ? 3 * c + r : 3 * r + c)]
                          : sys->last_values[9 * k + (mirror ? 3 * c + r : 3 * r + c)]);
          }
    }
    PetscCall(MatSetPreallocationCOO(aij, (PetscCount)ci.size(), ci.data(), cj.data()));
    PetscCall(MatSetValuesCOO(aij, v.data(), INSERT_VALUES));
  }
  PetscCall(PetscViewerBinaryOpen(comm, path, FILE_MODE_WRITE, &viewer));
  PetscCall(MatView(aij, viewer));
  PetscCall(PetscViewerDestroy(&viewer));
  PetscCall(MatDestroy(&aij));
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemGetInfo(BlockSystem *sys, PetscInt *nnz, const char **mat_type,
                                  const char **ksp_type)
{
  PetscFunctionBegin;
  if (nnz) *nnz = 9 * sys->n_blocks;
  if (mat_type) PetscCall(MatGetType(sys->A, (MatType *)mat_type));
  if (ksp_type) PetscCall(KSPGetType(sys->ksp, (KSPType *)ksp_type));
  PetscFunctionReturn(0);
}

PetscErrorCode BlockSystemDestroy(BlockSystem *sys)
{
  PetscFunctionBegin;
  if (!sys) PetscFunctionReturn(0);
  PetscCall(GAMGSmootherCopiesDestroy(&sys->gamg_copies));
  PetscCall(KSPDestroy(&sys->ksp));
  PetscCall(VecDestroy(&sys->x));
  PetscCall(VecDestroy(&sys->b));
  PetscCall(VecDestroy(&sys->r));
  PetscCall(MatDestroy(&sys->A));
  *sys = BlockSystem{};
  PetscFunctionReturn(0);
}
