#include "sim/grid_mg.h"
#include "sim/smoother_copy.h"

#include <petscbinbcsr.h>

#include <algorithm>

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
// (a level's smoother is one collective object: the ranks must agree), and -info says why.
PetscErrorCode UseSlabs(GridMG *mg, PetscInt level, int n, std::vector<SlabGS::Entry> entries,
                        bool column_major, PetscBool whole)
{
  PetscFunctionBegin;
  const std::string why     = SlabGSBuild(n, std::move(entries), column_major, &mg->slabs[level]);
  int               here_ok = why.empty(), all_ok;
  PetscCallMPI(MPI_Allreduce(&here_ok, &all_ok, 1, MPI_INT, MPI_LAND, PetscObjectComm((PetscObject)mg->pc)));
  if (!all_ok) {
    mg->slab_used[level] = GridMG::kSor;
    mg->slabs[level]     = SlabGS();
    PetscCall(PetscInfo(mg->pc, "grid multigrid level %d keeps SOR: %s\n", (int)level,
                        here_ok ? "another rank's rows cannot be swept in slabs" : why.c_str()));
    PetscFunctionReturn(0);
  }
  KSP sides[2];
  PetscCall(LevelSmoothers(mg->pc, level, sides));
  for (KSP smoother : sides) {
    PC spc;
    PetscCall(KSPGetPC(smoother, &spc));
    PetscCall(SlabGSSetPC(spc, &mg->slabs[level], whole));
  }
  mg->slab_used[level] = GridMG::kSlab;
  PetscFunctionReturn(0);
}

// The blocks of A's rows on this rank among themselves (A AIJ with 3 unknowns per node: MPIAIJ's diagonal
// part, or SeqAIJ): where each block entry sits in the part's value array (a->gather, row-major) and the
// slab entries; returns why the rows cannot be swept in slabs, or an empty string.
// A coarse level with distributed block products: an AIJ matrix in the level's numbering whose COO list is
// every rank's share Ac (SeqBAIJ, the level's physics numbering, all its nodes) entry by entry in Ac's
// value order (column-major blocks), so that MatSetValuesCOO with Ac's values sums the shares.
PetscErrorCode PartialProductTarget(MPI_Comm comm, Mat Ac, const GridMG::DistributedLevel &c, Mat *target)
{
  PetscMPIInt           rank;
  std::vector<PetscInt> rows, cols, ci, cj;
  Mat                   A;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(BlockGalerkinBlocksOf(Ac, &rows, &cols));
  for (size_t k = 0; k < rows.size(); ++k)
    for (int e = 0; e < 9; ++e) {
      ci.push_back(3 * (PetscInt)c.num[rows[k]] + e % 3);
      cj.push_back(3 * (PetscInt)c.num[cols[k]] + e / 3);
    }
  const PetscInt local = 3 * (c.offsets[rank + 1] - c.offsets[rank]), global = 3 * c.side * c.side;
  PetscCall(MatCreate(comm, &A));
  PetscCall(MatSetSizes(A, local, local, global, global));
  PetscCall(MatSetBlockSize(A, 3));
  PetscCall(MatSetType(A, MATAIJ));
  PetscCall(MatSetPreallocationCOO(A, (PetscCount)ci.size(), ci.data(), cj.data()));
  *target = A;
  PetscFunctionReturn(0);
}

// The 3x3 blocks of this rank's rows of an AIJ level (MPIAIJ: diagonal and off-diagonal part) in the
// level's physics numbering (rows, cols), and where each of their entries sits: d->gather (9 per block,
// row-major) indexes the diagonal part's values, or the off-diagonal part's past d->diagonal_count.
PetscErrorCode AijRowBlocks(Mat A, const GridMG::DistributedLevel &level, GridMG::DistributedLevel *d,
                            std::vector<PetscInt> *rows, std::vector<PetscInt> *cols)
{
  Mat             Ad = A, Ao = nullptr;
  const PetscInt *garray = nullptr, *ia, *ja;
  PetscInt        rstart, cstart, nr;
  PetscBool       mpi, done;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpi));
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, &garray));
  PetscCall(MatGetOwnershipRange(A, &rstart, nullptr));
  PetscCall(MatGetOwnershipRangeColumn(A, &cstart, nullptr));
  std::vector<int> phys(level.num.size()); // solver -> physics numbering of the level's nodes
  for (size_t k = 0; k < level.num.size(); ++k) phys[level.num[k]] = (int)k;
  std::vector<std::pair<long, long>> keys; // (global block row * N + global block column, entry)
  const long                         N  = (long)level.num.size();
  PetscInt                           nd = 0;
  for (int part = 0; part < (mpi ? 2 : 1); ++part) {
    Mat M = part ? Ao : Ad;
    PetscCall(MatGetRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
    PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP,
               "grid multigrid: no row structure of a level's operator");
    for (PetscInt i = 0; i < nr; ++i)
      for (PetscInt k = ia[i]; k < ia[i + 1]; ++k) {
        const PetscInt col = part ? garray[ja[k]] : cstart + ja[k];
        keys.push_back({(long)((rstart + i) / 3) * N + col / 3, (long)(part ? nd + k : k)});
      }
    if (!part) nd = ia[nr];
    PetscCall(MatRestoreRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
  }
  d->diagonal_count = nd;
  std::sort(keys.begin(), keys.end());
  d->gather.clear();
  rows->clear();
  cols->clear();
  for (size_t q = 0; q < keys.size(); ++q) {
    const long R = keys[q].first / N, C = keys[q].first % N;
    if (q == 0 || keys[q].first != keys[q - 1].first) {
      rows->push_back(phys[R]);
      cols->push_back(phys[C]);
      d->gather.insert(d->gather.end(), 9, -1);
    }
    // the entry's scalar row and column within the block, from its place in the part it came from
    const long k = keys[q].second;
    PetscCall(MatGetRowIJ(k < nd ? Ad : Ao, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
    const PetscInt kk = k < nd ? k : k - nd, i = std::upper_bound(ia, ia + nr + 1, kk) - ia - 1;
    const PetscInt col = k < nd ? cstart + ja[kk] : garray[ja[kk]];
    d->gather[d->gather.size() - 9 + 3 * ((rstart + i) % 3) + col % 3] = (PetscInt)k;
    PetscCall(MatRestoreRowIJ(k < nd ? Ad : Ao, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
  }
  d->blocks.assign(d->gather.size(), 0.0);
  PetscFunctionReturn(0);
}

PetscErrorCode AijBlocks(Mat A, GridMG::AijSlab *a, int *nb, std::vector<SlabGS::Entry> *entries,
                         std::string *why)
{
  PetscBool       mpi, seq, done;
  Mat             Ad = A;
  PetscInt        nr;
  const PetscInt *ia, *ja;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpi));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQAIJ, &seq));
  if (!mpi && !seq) {
    *why = "the level's operator is not AIJ";
    PetscFunctionReturn(0);
  }
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, nullptr, nullptr));
  PetscCall(MatGetRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
  PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP,
             "grid multigrid: no row structure of the level's operator");
  if (nr % 3) {
    *why = "the level's rows are not in nodes of 3";
  } else {
    *nb = (int)(nr / 3);
    std::vector<std::pair<long, long>> keys; // (block row * nb + block column, entry index)
    for (PetscInt i = 0; i < nr; ++i)
      for (PetscInt k = ia[i]; k < ia[i + 1]; ++k) keys.push_back({(long)(i / 3) * *nb + ja[k] / 3, (long)k});
    std::sort(keys.begin(), keys.end());
    a->gather.clear();
    entries->clear();
    for (size_t q = 0; q < keys.size(); ++q) {
      if (q == 0 || keys[q].first != keys[q - 1].first) {
        entries->push_back(
          {(int)(keys[q].first / *nb), (int)(keys[q].first % *nb), (long)entries->size(), false});
        a->gather.insert(a->gather.end(), 9, -1);
      }
      const long     k = keys[q].second;
      const PetscInt i = std::upper_bound(ia, ia + nr + 1, (PetscInt)k) - ia - 1; // k's row
      a->gather[a->gather.size() - 9 + 3 * (i % 3) + ja[k] % 3] = (PetscInt)k;
    }
    a->blocks.assign(a->gather.size(), 0.0);
  }
  PetscCall(MatRestoreRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
  PetscFunctionReturn(0);
}

// The PCSHELL set-up of a coarse level's smoother with PCMG's products: at the first, the ranks decide
// together on slabs or SOR; then the slabs take the operator's new values (once per new set: the pre- and
// post-smoother share them).
PetscErrorCode AijSlabSetUp(PC pc)
{
  GridMG::AijSlab *a;
  Mat              A;
  SlabGS::Held     now;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &a));
  GridMG *mg = a->mg;
  PetscCall(PCGetOperators(pc, nullptr, &A));
  if (mg->slab_used[a->level] == GridMG::kUndecided) {
    std::string                why;
    std::vector<SlabGS::Entry> entries;
    int                        nb = 0;
    PetscCall(AijBlocks(A, a, &nb, &entries, &why));
    if (why.empty()) why = SlabGSBuild(nb, std::move(entries), false, &mg->slabs[a->level]);
    int here_ok = why.empty(), all_ok;
    PetscCallMPI(MPI_Allreduce(&here_ok, &all_ok, 1, MPI_INT, MPI_LAND, PetscObjectComm((PetscObject)pc)));
    mg->slab_used[a->level] = all_ok ? GridMG::kSlab : GridMG::kSor;
    if (!all_ok) {
      mg->slabs[a->level] = SlabGS();
      PetscCall(PetscInfo(mg->pc, "grid multigrid level %d keeps SOR: %s\n", (int)a->level,
                          here_ok ? "another rank's rows cannot be swept in slabs" : why.c_str()));
    }
  }
  if (mg->slab_used[a->level] == GridMG::kSor) {
    if (!a->sor) {
      PetscCall(PCCreate(PetscObjectComm((PetscObject)pc), &a->sor));
      PetscCall(PCSetType(a->sor, PCSOR));
      PetscCall(PCSORSetSymmetric(a->sor, SOR_LOCAL_SYMMETRIC_SWEEP));
    }
    PetscCall(PCSetOperators(a->sor, A, A));
    PetscCall(PCSetUp(a->sor));
    PetscFunctionReturn(0);
  }
  PetscCall(SlabGSHeldOf((PetscObject)A, &now));
  if (now.id == a->held.id && now.state == a->held.state) PetscFunctionReturn(0);
  Mat                Ad = A;
  PetscBool          mpi;
  const PetscScalar *v;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpi));
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, nullptr, nullptr));
  PetscCall(MatSeqAIJGetArrayRead(Ad, &v));
  for (size_t q = 0; q < a->gather.size(); ++q) a->blocks[q] = a->gather[q] < 0 ? 0.0 : v[a->gather[q]];
  PetscCall(MatSeqAIJRestoreArrayRead(Ad, &v));
  PetscCall(SlabGSRefill(&mg->slabs[a->level], a->blocks.data()));
  a->held = now;
  PetscFunctionReturn(0);
}

PetscErrorCode AijSlabApply(PC pc, Vec b, Vec x)
{
  GridMG::AijSlab *a;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &a));
  if (a->mg->slab_used[a->level] == GridMG::kSlab) PetscCall(SlabGSApplySweep(&a->mg->slabs[a->level], b, x));
  else PetscCall(PCApply(a->sor, b, x));
  PetscFunctionReturn(0);
}

PetscErrorCode AijSlabView(PC pc, PetscViewer viewer)
{
  GridMG::AijSlab *a;
  PetscBool        ascii;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &a));
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (!ascii) PetscFunctionReturn(0);
  switch (a->mg->slab_used[a->level]) {
  case GridMG::kSlab:
    PetscCall(PetscViewerASCIIPrintf(viewer,
                                     "slab Gauss-Seidel on this rank's rows of the level's AIJ operator "
                                     "(symmetric sweep from zero, 8 rows side by side)\n"));
    break;
  case GridMG::kSor:
    PetscCall(PetscViewerASCIIPrintf(viewer,
                                     "SOR, local symmetric sweeps (the level's rows cannot all be swept "
                                     "in slabs)\n"));
    break;
  default:
    PetscCall(
      PetscViewerASCIIPrintf(viewer, "slab Gauss-Seidel or SOR, decided at the level's first set-up\n"));
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
    PetscCall(Interpolation(comm, levels[l], levels[l + 1], w, galerkin == 0 && !mg->distributed, &P));
    PetscCall(PCMGSetInterpolation(pc, nlev - 1 - l, P));
    if (mg->distributed) {
      // the first product from this rank's COO blocks, the others from its rows of the AIJ level above
      // (at the first refill, when that level has its structure: GridMGRefill)
      mg->aij_interp.push_back(P);
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
        PetscCall(PartialProductTarget(comm, mg->galerkin[0].Ac, mg->dist_levels[0], &mg->aij_levels[0]));
      }
      continue;
    }
    PetscCall(MatDestroy(&P)); // PCMG holds a reference
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
    // to the rank. With PCMG's products (more ranks) only the fine level sweeps slabs, each rank its own
    // rows with their couplings to other ranks left out (block Jacobi between the ranks, as SOR's local
    // sweeps do), and its residual stays PCMG's on the whole operator.
    if (mg->smoother_slab && nlev > 1) {
      PetscMPIInt rank;
      PetscCallMPI(MPI_Comm_rank(comm, &rank));
      const int                  begin = row_offsets[rank], local = row_offsets[rank + 1] - begin;
      std::vector<SlabGS::Entry> entries;
      for (size_t k = 0; k < coo_row.size(); ++k) {
        const int r = new_of_old[coo_row[k]] - begin, c = new_of_old[coo_col[k]] - begin;
        PetscCheck(r >= 0 && r < local, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                   "grid multigrid: COO block %zu is in row %d, not one of this rank's", k, r + begin);
        if (c < 0 || c >= local) continue;
        entries.push_back({r, c, (long)k, false});
        if (coo_mirrored && r != c) entries.push_back({c, r, (long)k, true});
      }
      PetscCall(
        UseSlabs(mg, nlev - 1, local, std::move(entries), false, size == 1 ? PETSC_TRUE : PETSC_FALSE));
    }
    // The coarse levels with PCMG's products: their operators come at PCMG's set-up, so do their slabs
    // (AijSlabSetUp). Their SOR on MPIAIJ took more time than the fine level's slabs (cloth.opts, 2 ranks,
    // the 81 x 81 level: 22 against 16 ms per step, docs/cloth.md).
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
          PetscCall(PCSetType(spc, PCSHELL));
          PetscCall(PCShellSetContext(spc, &mg->aij_slabs[l]));
          PetscCall(PCShellSetSetUp(spc, AijSlabSetUp));
          PetscCall(PCShellSetApply(spc, AijSlabApply));
          PetscCall(PCShellSetView(spc, AijSlabView));
          PetscCall(PCShellSetName(spc, "grid multigrid coarse-level smoother"));
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
    PetscCall(SmootherCopyRefill(A, &mg->smoother_mats[level]));
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
  if (mg->distributed && mg->aij_levels.empty()) PetscFunctionReturn(0); // a lone level is solved directly
  if (mg->distributed) {
    // this rank's share of the first product, summed into the AIJ level by COO (the other ranks' shares
    // of its rows come from them); the coarser levels by MatPtAP
    PetscScalar *a;
    PetscCall(BlockGalerkinRefill(&mg->galerkin[0], coo_values));
    PetscCall(MatSeqBAIJGetArray(mg->galerkin[0].Ac, &a));
    PetscCall(MatSetValuesCOO(mg->aij_levels[0], a, INSERT_VALUES));
    PetscCall(MatSeqBAIJRestoreArray(mg->galerkin[0].Ac, &a));
    for (size_t l = 1; l < mg->aij_levels.size(); ++l) {
      GridMG::DistributedLevel &d = mg->dist_levels[l - 1]; // the source level's gather (its rows)
      if (!mg->aij_levels[l]) {                             // first refill: the level's pattern
        std::vector<PetscInt> rows, cols;
        MPI_Comm              comm;
        PetscCall(PetscObjectGetComm((PetscObject)mg->pc, &comm));
        PetscCall(AijRowBlocks(mg->aij_levels[l - 1], d, &d, &rows, &cols));
        const GridMG::DistributedLevel &c = mg->dist_levels[l];
        PetscCall(
          BlockGalerkinCreate(rows, cols, true, false, false, c.weights, c.side * c.side, &mg->galerkin[l]));
        PetscCall(PartialProductTarget(comm, mg->galerkin[l].Ac, c, &mg->aij_levels[l]));
      }
      Mat                Ad = mg->aij_levels[l - 1], Ao = nullptr;
      const PetscScalar *va, *vo                        = nullptr;
      PetscBool          mpi;
      PetscCall(PetscObjectTypeCompare((PetscObject)Ad, MATMPIAIJ, &mpi));
      if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(mg->aij_levels[l - 1], &Ad, &Ao, nullptr));
      PetscCall(MatSeqAIJGetArrayRead(Ad, &va));
      if (Ao) PetscCall(MatSeqAIJGetArrayRead(Ao, &vo));
      for (size_t q = 0; q < d.gather.size(); ++q) {
        const PetscInt g = d.gather[q];
        d.blocks[q]      = g < 0 ? 0.0 : (g < d.diagonal_count ? va[g] : vo[g - d.diagonal_count]);
      }
      PetscCall(MatSeqAIJRestoreArrayRead(Ad, &va));
      if (Ao) PetscCall(MatSeqAIJRestoreArrayRead(Ao, &vo));
      PetscCall(BlockGalerkinRefill(&mg->galerkin[l], d.blocks.data()));
      PetscCall(MatSeqBAIJGetArray(mg->galerkin[l].Ac, &a));
      PetscCall(MatSetValuesCOO(mg->aij_levels[l], a, INSERT_VALUES));
      PetscCall(MatSeqBAIJRestoreArray(mg->galerkin[l].Ac, &a));
    }
    for (size_t l = 0; l < mg->aij_levels.size(); ++l) {
      const PetscInt level = (PetscInt)(mg->aij_levels.size() - 1 - l);
      PetscCall(PCMGSetOperators(mg->pc, level, mg->aij_levels[l], mg->aij_levels[l]));
      if (level > 0) { // PCMG sets the pre-smoother's; the post-smoother is another KSP
        KSP sides[2];
        PetscCall(LevelSmoothers(mg->pc, level, sides));
        PetscCall(KSPSetOperators(sides[1], mg->aij_levels[l], mg->aij_levels[l]));
      }
    }
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
  for (Mat &m : mg->aij_levels) PetscCall(MatDestroy(&m));
  for (Mat &m : mg->aij_interp) PetscCall(MatDestroy(&m));
  mg->aij_levels.clear();
  mg->aij_interp.clear();
  mg->dist_levels.clear();
  mg->aij_slabs.clear();
  mg->smoother_mats.clear();
  mg->galerkin.clear();
  PetscFunctionReturn(0);
}
