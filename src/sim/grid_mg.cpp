#include "sim/grid_mg.h"
#include "sim/grid_mg_aij.h"
#include "sim/smoother_copy.h"

#include <petscbinbcsr.h>

#include <algorithm>
#include <unordered_map>

namespace {

// One level's nodes: side x side, row-major; num[node] is its global index in the level's numbering,
// offsets[r] .. offsets[r + 1] the indices rank r owns.
struct GridLevel {
  PetscInt         side = 0;
  std::vector<int> num, offsets;
};

int OwnerOf(const std::vector<int> &offsets, int index)
{
  return (int)(std::upper_bound(offsets.begin(), offsets.end(), index) - offsets.begin()) - 1;
}

// The coarse grid keeps every other node per side, coarse node I at fine node 2 I: n / 2 + 1 per side.
// For an even n the last coarse line lies one spacing beyond the grid (fine node n - 1 is the mean of two
// coarse lines, as every odd one is), so the weights are always 1 or 1/2 and a fine node has at most 4.
GridLevel Coarsen(const GridLevel &f)
{
  GridLevel c;
  c.side                 = f.side / 2 + 1;
  const int        ranks = (int)f.offsets.size() - 1;
  std::vector<int> owner(c.side * c.side);
  for (PetscInt I = 0; I < c.side; ++I)
    for (PetscInt J = 0; J < c.side; ++J) {
      // The coarse node goes with its fine node (the nearest one beyond the grid), so P's rows and
      // columns mostly share ranks.
      const PetscInt fi = std::min(2 * I, f.side - 1), fj = std::min(2 * J, f.side - 1);
      owner[I * c.side + J] = OwnerOf(f.offsets, f.num[fi * f.side + fj]);
    }
  c.num.resize(owner.size());
  c.offsets.assign(ranks + 1, 0);
  int next = 0;
  for (int r = 0; r < ranks; ++r) {
    for (size_t k = 0; k < owner.size(); ++k)
      if (owner[k] == r) c.num[k] = next++;
    c.offsets[r + 1] = next;
  }
  return c;
}

// The coarse nodes (lo, lo + 1) around fine index i along one side and the weight of lo + 1: 0 or 1/2, and 1
// for the last node of an odd side (it is coarse node lo + 1).
void Bracket(PetscInt i, PetscInt cside, PetscInt *lo, double *a)
{
  *lo = std::min(i / 2, cside - 2);
  *a  = i - 2 * *lo == 0 ? 0.0 : (i - 2 * *lo == 1 ? 0.5 : 1.0);
}

// Bilinear interpolation from c to f, one row of weights per fine node (physics numbering of the level);
// fixed (may be empty) marks fine nodes whose rows stay zero, unless a coarse node would then interpolate
// to nothing (all its fine nodes fixed: its Galerkin row would be zero and the coarse operator singular).
std::vector<std::vector<BlockWeight>> Weights(const GridLevel &f, const GridLevel &c,
                                              const std::vector<char> &fixed)
{
  std::vector<std::vector<BlockWeight>> rows(f.side * f.side);
  std::vector<int>                      support(c.side * c.side, 0);
  for (PetscInt i = 0; i < f.side; ++i)
    for (PetscInt j = 0; j < f.side; ++j) {
      PetscInt I, J;
      double   a, b;
      Bracket(i, c.side, &I, &a);
      Bracket(j, c.side, &J, &b);
      const double wi[2] = {1 - a, a}, wj[2] = {1 - b, b};
      for (int di = 0; di < 2; ++di)
        for (int dj = 0; dj < 2; ++dj) {
          const double w = wi[di] * wj[dj];
          if (w == 0) continue; // a node on a coarse line interpolates from that line only
          const PetscInt cn = (I + di) * c.side + J + dj;
          rows[i * f.side + j].push_back({cn, w});
          if (fixed.empty() || !fixed[i * f.side + j]) support[cn]++;
        }
    }
  if (!fixed.empty())
    for (size_t node = 0; node < rows.size(); ++node)
      if (fixed[node]) {
        std::vector<BlockWeight> keep;
        for (const BlockWeight &w : rows[node])
          if (!support[w.coarse]) keep.push_back(w);
        rows[node] = keep;
      }
  return rows;
}

// The interpolation as PCMG applies it, rows and columns in the levels' (solver) numbering. maij: the
// scalar weights once, as MAIJ with 3 components (PCMG's transfers then read a third of the bytes); else
// AIJ with the weight repeated for each component (what MatPtAP takes, for PCMG's own products).
PetscErrorCode Interpolation(MPI_Comm comm, const GridLevel &f, const GridLevel &c,
                             const std::vector<std::vector<BlockWeight>> &rows, bool maij, Mat *P)
{
  PetscMPIInt    rank;
  Mat            W;
  const PetscInt dof = maij ? 1 : 3, nf = f.side * f.side; // the components W itself carries

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(MatCreate(comm, &W));
  PetscCall(MatSetOptionsPrefix(W, "grid_mg_interp_")); // -mat_view is for the system matrix
  PetscCall(MatSetSizes(W, dof * (f.offsets[rank + 1] - f.offsets[rank]),
                        dof * (c.offsets[rank + 1] - c.offsets[rank]), dof * nf, dof * c.side * c.side));
  PetscCall(MatSetBlockSizes(W, dof, dof));
  PetscCall(MatSetType(W, MATAIJ));
  PetscCall(MatSeqAIJSetPreallocation(W, 4, nullptr));
  PetscCall(MatMPIAIJSetPreallocation(W, 4, nullptr, 4, nullptr));
  for (PetscInt node = 0; node < nf; ++node) {
    if (OwnerOf(f.offsets, f.num[node]) != rank) continue;
    for (const BlockWeight &w : rows[node])
      for (PetscInt k = 0; k < dof; ++k) {
        const PetscInt    row = dof * f.num[node] + k, col = dof * c.num[w.coarse] + k;
        const PetscScalar v = w.w;
        PetscCall(MatSetValues(W, 1, &row, 1, &col, &v, INSERT_VALUES));
      }
  }
  PetscCall(MatAssemblyBegin(W, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(W, MAT_FINAL_ASSEMBLY));
  if (!maij) {
    *P = W;
    PetscFunctionReturn(0);
  }
  PetscCall(MatCreateMAIJ(W, 3, P));
  PetscCall(MatDestroy(&W));
  PetscFunctionReturn(0);
}

// The pre- and post-smoother of PCMG level `level` (distinct objects, see GridMGSetUp); the coarse
// solve, level 0, is one KSP, returned twice.
PetscErrorCode LevelSmoothers(PC pc, PetscInt level, KSP sides[2])
{
  PetscFunctionBegin;
  PetscCall(PCMGGetSmootherDown(pc, level, &sides[0]));
  sides[1] = sides[0];
  if (level > 0) PetscCall(PCMGGetSmootherUp(pc, level, &sides[1]));
  PetscFunctionReturn(0);
}

// Level `level`'s smoothers become slab Gauss-Seidel on the blocks `entries` (this rank's n block rows)
// when the level's couplings allow it (slab_gs.h) on every rank; otherwise they stay SOR on all of them
// (GridMGAgreeOnSlabs).
// halo (a rank's rows of a distributed level, with ghosts: the rows they couple to on other ranks): the
// level's couplings toward other ranks, so that the sweeps run from the smoother's guess (SlabGSSetHalo).
PetscErrorCode UseSlabs(GridMG *mg, PetscInt level, int n, std::vector<SlabGS::Entry> entries,
                        bool column_major, PetscBool whole, std::vector<SlabGS::HaloEntry> *halo = nullptr,
                        std::vector<PetscInt> *ghosts = nullptr)
{
  PetscFunctionBegin;
  const std::string why = SlabGSBuild(n, std::move(entries), column_major, &mg->slabs[level]);
  GridMG::SlabUse   use;
  if (why.empty() && halo) {
    SlabGSSetHalo(&mg->slabs[level], std::move(*halo), std::move(*ghosts));
    whole = PETSC_TRUE;
  }
  PetscCall(GridMGAgreeOnSlabs(mg, level, why, &use));
  if (use != GridMG::kSlab) PetscFunctionReturn(0);
  KSP sides[2];
  PetscCall(LevelSmoothers(mg->pc, level, sides));
  for (KSP smoother : sides) {
    PC spc;
    PetscCall(KSPGetPC(smoother, &spc));
    PetscCall(SlabGSSetPC(spc, &mg->slabs[level], whole));
  }
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode GridMGSetUp(KSP ksp, PetscInt n, const std::vector<char> &fixed,
                           const std::vector<int> &new_of_old, const std::vector<int> &row_offsets,
                           const std::vector<int> &coo_row, const std::vector<int> &coo_col,
                           PetscBool coo_mirrored, PetscBool offrank_full, GridMG *mg)
{
  MPI_Comm    comm;
  PC          pc;
  PetscBool   is_mg;
  PetscInt    coarse_nodes = 150, galerkin = 0;
  PetscMPIInt size;
  const char *galerkins[] = {"blocks", "pcmg"};

  PetscFunctionBegin;
  PetscCall(PetscObjectGetComm((PetscObject)ksp, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCMG, &is_mg));
  PetscCheck(is_mg, comm, PETSC_ERR_ARG_WRONG, "the grid multigrid needs -pc_type mg");
  PetscCheck(
    n >= 2 && (PetscInt)new_of_old.size() == n * n && (fixed.empty() || (PetscInt)fixed.size() == n * n),
    comm, PETSC_ERR_ARG_SIZ, "grid multigrid: %" PetscInt_FMT " x %" PetscInt_FMT " grid, %zu rows numbered",
    n, n, new_of_old.size());
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-grid_mg_coarse_nodes", &coarse_nodes, nullptr));
  PetscCheck(coarse_nodes >= 4, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-grid_mg_coarse_nodes must be at least 4 (a 2 x 2 grid), got %" PetscInt_FMT, coarse_nodes);
  PetscCall(PetscOptionsGetEList(nullptr, nullptr, "-grid_mg_galerkin", galerkins, 2, &galerkin, nullptr));
  mg->own_galerkin = galerkin == 0;
  mg->distributed  = mg->own_galerkin && size > 1;
  mg->pc           = pc;

  std::vector<GridLevel> levels(1);
  levels[0].side    = n;
  levels[0].num     = new_of_old;
  levels[0].offsets = row_offsets;
  while (levels.back().side * levels.back().side > coarse_nodes &&
         levels.back().side / 2 + 1 < levels.back().side)
    levels.push_back(Coarsen(levels.back()));
  mg->sides.clear();
  for (const GridLevel &l : levels) mg->sides.push_back(l.side);

  // PCMG counts levels from the coarsest (0); ours count from the finest.
  const PetscInt nlev = (PetscInt)levels.size();
  PetscCall(PCMGSetLevels(pc, nlev, nullptr));
  mg->galerkin.assign(nlev - 1, BlockGalerkin());
  for (PetscInt l = 0; l + 1 < nlev; ++l) {
    Mat        P;
    const auto w = Weights(levels[l], levels[l + 1], l == 0 ? fixed : std::vector<char>());
    PetscCall(Interpolation(comm, levels[l], levels[l + 1], w, galerkin == 0, &P));
    PetscCall(PCMGSetInterpolation(pc, nlev - 1 - l, P));
    PetscCall(MatDestroy(&P)); // PCMG holds a reference
    if (mg->distributed) {
      // the first product from this rank's COO blocks, the others from its rows of the AIJ level above
      // (at the first refill, when that level has its structure: GridMGRefill)
      GridMG::DistributedLevel d;
      d.num     = levels[l + 1].num;
      d.offsets = levels[l + 1].offsets;
      d.side    = levels[l + 1].side;
      d.weights = w;
      mg->dist_levels.push_back(d);
      if (l == 0) {
        // A block coupling two ranks stands for its transpose only where the other rank does not list
        // that itself (offrank_full: both list their own rows' blocks whole); then this rank's share is
        // not symmetric, so every coarse block is summed.
        PetscMPIInt       rank;
        std::vector<char> mirror(coo_row.size(), coo_mirrored ? 1 : 0);
        PetscCallMPI(MPI_Comm_rank(comm, &rank));
        if (coo_mirrored && offrank_full)
          for (size_t k = 0; k < coo_row.size(); ++k) {
            const int c = new_of_old[coo_col[k]];
            if (c < row_offsets[rank] || c >= row_offsets[rank + 1]) mirror[k] = 0;
          }
        PetscCall(BlockGalerkinCreate(std::vector<PetscInt>(coo_row.begin(), coo_row.end()),
                                      std::vector<PetscInt>(coo_col.begin(), coo_col.end()), true,
                                      coo_mirrored, coo_mirrored && !offrank_full, w,
                                      levels[1].side * levels[1].side, &mg->galerkin[0], &mirror));
        mg->aij_levels.assign(nlev - 1, nullptr);
        PetscCall(GridMGShareTarget(comm, mg->galerkin[0].Ac, mg->dist_levels[0], &mg->aij_levels[0]));
      }
      continue;
    }
    if (!mg->own_galerkin) continue;
    // The first product reads the driver's COO blocks (physics numbering, as the weights), the others
    // the level above's BAIJ values.
    std::vector<PetscInt> rows, cols;
    if (l == 0) rows.assign(coo_row.begin(), coo_row.end()), cols.assign(coo_col.begin(), coo_col.end());
    else PetscCall(BlockGalerkinBlocksOf(mg->galerkin[l - 1].Ac, &rows, &cols));
    // the fine operator is symmetric (the driver assembles a symmetric system), so is every product
    PetscCall(BlockGalerkinCreate(rows, cols, l == 0, l == 0 && coo_mirrored, true, w,
                                  levels[l + 1].side * levels[l + 1].side, &mg->galerkin[l]));
    PetscCall(PCMGSetOperators(pc, nlev - 2 - l, mg->galerkin[l].Ac, mg->galerkin[l].Ac));
  }
  PetscCall(PCMGSetGalerkin(pc, mg->own_galerkin ? PC_MG_GALERKIN_NONE : PC_MG_GALERKIN_BOTH));
  // Smoothers: one symmetric Gauss-Seidel sweep (processor-local on more ranks), so that the V-cycle is
  // symmetric positive definite for CG whatever the values (Chebyshev needs eigenvalue estimates, which
  // turned the cycle indefinite on the cloth when they were short). Their own prefixes keep GAMG's
  // -mg_levels_* options (a scene file may hold both) away from them. The pre- and post-smoother are
  // distinct objects with the same settings: PCMG then tells the pre-smoother that its initial guess is
  // zero (one KSP serving both must assume a nonzero one), and the first half of its sweep skips the
  // product with the upper triangle, a third of the pre-smoothing on binbcsr's upper-triangle storage.
  PetscCall(PCMGSetDistinctSmoothUp(pc));
  for (PetscInt l = 0; l < nlev; ++l) {
    if (l == 0) {
      KSP coarse;
      PC  cpc;
      PetscCall(PCMGGetSmoother(pc, l, &coarse));
      PetscCall(KSPGetPC(coarse, &cpc));
      PetscCall(KSPSetOptionsPrefix(coarse, "grid_mg_coarse_"));
      if (nlev == 1) { // PCMG makes a lone level a smoother; a grid this small is solved directly
        PetscCall(KSPSetType(coarse, KSPPREONLY));
        PetscCall(PCSetType(cpc, size > 1 ? PCREDUNDANT : PCLU));
      }
      continue; // PCMG's default: LU (redundant on more ranks)
    }
    char prefix[64]; // -grid_mg_levels_N_* for level N (PCMG's numbering), -grid_mg_levels_* for all
    PetscCall(PetscSNPrintf(prefix, sizeof prefix, "grid_mg_levels_%d_", (int)l));
    KSP sides[2];
    PetscCall(LevelSmoothers(pc, l, sides));
    for (KSP smoother : sides) {
      PC spc;
      PetscCall(KSPGetPC(smoother, &spc));
      PetscCall(KSPSetOptionsPrefix(smoother, prefix));
      PetscCall(KSPSetType(smoother, KSPRICHARDSON));
      PetscCall(KSPSetTolerances(smoother, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 1));
      PetscCall(PCSetType(spc, PCSOR));
      PetscCall(PCSORSetSymmetric(spc, SOR_LOCAL_SYMMETRIC_SWEEP));
    }
  }
  {
    const char *kinds[] = {"sor", "slab"};
    PetscInt    kind    = 1;
    PetscCall(PetscOptionsGetEList(nullptr, nullptr, "-grid_mg_smoother", kinds, 2, &kind, nullptr));
    mg->smoother_slab = kind == 1;
    mg->slabs.assign(nlev, SlabGS());
    mg->slab_used.assign(nlev, GridMG::kUndecided);
    // The fine level's blocks: the driver's COO list (this rank's rows), in the solver's numbering local
    // to the rank. On more ranks each rank sweeps its own rows (block Jacobi between the ranks, as SOR's
    // local sweeps do): where each rank lists its rows' blocks toward the others itself (not mirrored
    // from the other side) they form the halo, and the sweeps run from the guess with the other ranks'
    // part on the right-hand side; else the couplings are left out and the smoother sweeps from zero
    // on the residual Richardson forms with the whole operator (a product more per smoothing).
    if (mg->smoother_slab && nlev > 1) {
      PetscMPIInt rank;
      PetscCallMPI(MPI_Comm_rank(comm, &rank));
      const int                      begin = row_offsets[rank], local = row_offsets[rank + 1] - begin;
      const bool                     with_halo = size > 1 && (!coo_mirrored || offrank_full);
      std::vector<SlabGS::Entry>     entries;
      std::vector<SlabGS::HaloEntry> halo;
      std::vector<PetscInt>          ghosts;
      std::unordered_map<int, int>   ghost_of;
      for (size_t k = 0; k < coo_row.size(); ++k) {
        const int r = new_of_old[coo_row[k]] - begin, c = new_of_old[coo_col[k]] - begin;
        PetscCheck(r >= 0 && r < local, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                   "grid multigrid: COO block %zu is in row %d, not one of this rank's", k, r + begin);
        if (c < 0 || c >= local) {
          if (!with_halo) continue;
          const auto g = ghost_of.emplace(c + begin, (int)ghosts.size());
          if (g.second) ghosts.push_back(c + begin);
          halo.push_back({r, g.first->second, (long)k, false});
          continue;
        }
        entries.push_back({r, c, (long)k, false});
        if (coo_mirrored && r != c) entries.push_back({c, r, (long)k, true});
      }
      PetscCall(UseSlabs(mg, nlev - 1, local, std::move(entries), false, size == 1 ? PETSC_TRUE : PETSC_FALSE,
                         with_halo ? &halo : nullptr, with_halo ? &ghosts : nullptr));
    }
    // The AIJ coarse levels (more ranks, or PCMG's products): their operators come with the refills or at
    // PCMG's set-up, so do their slabs (grid_mg_aij.h). Their SOR on MPIAIJ took more time than the fine
    // level's slabs (cloth.opts, 2 ranks, the 81 x 81 level: 22 against 16 ms per step, docs/cloth.md).
    mg->aij_slabs.assign(nlev, GridMG::AijSlab());
    if (mg->smoother_slab && (!mg->own_galerkin || mg->distributed))
      for (PetscInt l = 1; l + 1 < nlev; ++l) {
        mg->aij_slabs[l].mg    = mg;
        mg->aij_slabs[l].level = l;
        KSP sides[2];
        PetscCall(LevelSmoothers(pc, l, sides));
        for (KSP smoother : sides) {
          PC spc;
          PetscCall(KSPGetPC(smoother, &spc));
          PetscCall(GridMGAijSmoother(spc, &mg->aij_slabs[l]));
        }
      }
  }
  {
    const char *precisions[] = {"double", "single"};
    PetscInt    precision    = 0;
    PetscCall(PetscOptionsGetEList(nullptr, nullptr, "-grid_mg_smoother_precision", precisions, 2, &precision,
                                   nullptr));
    // PCMG's own products (-grid_mg_galerkin pcmg, more ranks) would be taken from the copies: there the
    // smoothers stay on the operators (the driver's set-up line says which)
    mg->single_smoothers = precision == 1 && mg->own_galerkin && !mg->distributed;
    mg->smoother_mats.assign(nlev, nullptr);
  }
  PetscCall(KSPSetFromOptions(ksp)); // the new levels' smoothers and coarse solve take their options
  PetscFunctionReturn(0);
}

/* Hands level `level`'s smoothers their operators after a refill of A: A itself, or A with its
   single-precision copy as the matrix they sweep. Handing them again makes a smoother set up anew
   (Chebyshev's eigenvalue estimate: a KSP whose operators were set once keeps its first estimate)
   and the coarse solve refactor. */
static PetscErrorCode SetLevelOperators(GridMG *mg, PetscInt level, Mat A)
{
  Mat sweep = A;
  KSP sides[2];

  PetscFunctionBegin;
  PetscCall(LevelSmoothers(mg->pc, level, sides));
  if (mg->smoother_slab && level > 0 && mg->slab_used[level] == GridMG::kSlab) {
    // slab Gauss-Seidel holds the level's blocks itself (single precision off the diagonal) and takes the
    // level's residual in the same layout: no copy of the operator. PCMG hands its residual function the
    // level's operator (not the Mat given here), so the slabs go with that operator
    PetscCall(SlabGSAttach(A, &mg->slabs[level]));
    for (KSP smoother : sides) PetscCall(KSPSetOperators(smoother, A, A));
    PetscCall(PCMGSetResidual(mg->pc, level, SlabGSResidualMat, A));
    PetscFunctionReturn(0);
  }
  if (mg->single_smoothers && level > 0) {
    if (level == (PetscInt)mg->smoother_mats.size() - 1) { // the fine operator: the driver's Mat type
      PetscBool binbcsr;
      MatType   type;
      PetscCall(MatGetType(A, &type));
      PetscCall(PetscObjectTypeCompareAny((PetscObject)A, &binbcsr, MATSEQBINBCSR, MATMPIBINBCSR, ""));
      PetscCheck(
        binbcsr, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP,
        "-grid_mg_smoother_precision single needs a binbcsr fine operator (-mat_type binbcsr), not %s", type);
    }
    // the coarse levels in upper-triangle storage: the sweeps stream a quarter of the BAIJ bytes
    PetscCall(SmootherCopyRefill(A, PETSC_TRUE, &mg->smoother_mats[level]));
    sweep = mg->smoother_mats[level];
  }
  for (KSP smoother : sides) PetscCall(KSPSetOperators(smoother, A, sweep));
  // The level's residual on the copy as well: BAIJ's product ran at about a third of binbcsr single's
  // (cloth 160 x 160: the 81 x 81 level's residuals took more than the fine level's)
  if (sweep != A) PetscCall(PCMGSetResidual(mg->pc, level, PCMGResidualDefault, sweep));
  PetscFunctionReturn(0);
}

PetscErrorCode GridMGRefill(GridMG *mg, const PetscScalar *coo_values)
{
  PetscFunctionBegin;
  if (mg->single_smoothers && mg->smoother_mats.size() > 1) { // a lone level is solved directly
    Mat A;
    PetscCall(PCGetOperators(mg->pc, &A, nullptr));
    PetscCall(SetLevelOperators(mg, (PetscInt)mg->smoother_mats.size() - 1, A));
  }
  const PetscInt fine = (PetscInt)mg->galerkin.size();
  if (mg->smoother_slab && fine > 0 && mg->slab_used[fine] == GridMG::kSlab)
    PetscCall(SlabGSRefill(&mg->slabs[fine], coo_values));
  if (!mg->own_galerkin) PetscFunctionReturn(0); // PCMG recomputes its products at its set-up
  if (mg->distributed) {
    if (!mg->aij_levels.empty()) PetscCall(GridMGDistributedRefill(mg, coo_values)); // else one level: LU
    PetscFunctionReturn(0);
  }
  for (size_t l = 0; l < mg->galerkin.size(); ++l) {
    const PetscScalar *src = coo_values;
    PetscScalar       *a   = nullptr;
    if (l > 0) {
      PetscCall(MatSeqBAIJGetArray(mg->galerkin[l - 1].Ac, &a));
      src = a;
    }
    PetscCall(BlockGalerkinRefill(&mg->galerkin[l], src));
    if (l > 0) PetscCall(MatSeqBAIJRestoreArray(mg->galerkin[l - 1].Ac, &a));
    const PetscInt level = (PetscInt)(mg->galerkin.size() - 1 - l);
    if (mg->smoother_slab && level > 0) {
      Mat          Ac = mg->galerkin[l].Ac;
      PetscInt     nb;
      PetscScalar *ac;
      if (mg->slab_used[level] == GridMG::kUndecided) { // first refill: the level's pattern
        std::vector<PetscInt>      rows, cols;
        std::vector<SlabGS::Entry> entries;
        PetscCall(BlockGalerkinBlocksOf(Ac, &rows, &cols));
        for (size_t k = 0; k < rows.size(); ++k)
          entries.push_back({(int)rows[k], (int)cols[k], (long)k, false});
        PetscCall(MatGetLocalSize(Ac, &nb, nullptr));
        PetscCall(UseSlabs(mg, level, (int)(nb / 3), std::move(entries), true, PETSC_TRUE));
      }
      if (mg->slab_used[level] == GridMG::kSlab) {
        PetscCall(MatSeqBAIJGetArray(Ac, &ac));
        PetscCall(SlabGSRefill(&mg->slabs[level], ac));
        PetscCall(MatSeqBAIJRestoreArray(Ac, &ac));
      }
    }
    PetscCall(SetLevelOperators(mg, level, mg->galerkin[l].Ac));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode GridMGDestroy(GridMG *mg)
{
  PetscFunctionBegin;
  for (BlockGalerkin &g : mg->galerkin) PetscCall(BlockGalerkinDestroy(&g));
  for (Mat &m : mg->smoother_mats) PetscCall(MatDestroy(&m));
  for (GridMG::AijSlab &a : mg->aij_slabs) PetscCall(PCDestroy(&a.sor));
  mg->aij_slabs.clear();
  mg->slabs.clear(); // their halos' scatters: PETSc objects, gone before PetscFinalize
  for (Mat &m : mg->aij_levels) PetscCall(MatDestroy(&m));
  mg->aij_levels.clear();
  mg->dist_levels.clear();
  mg->smoother_mats.clear();
  mg->galerkin.clear();
  PetscFunctionReturn(0);
}
