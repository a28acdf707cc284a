#include "sim/grid_mg_aij.h"
#include "petsc_compat.h" // PetscOptionsPushCreateViewerOff

#include <algorithm>
#include <unordered_map>

PetscErrorCode GridMGAijBlocks(Mat A, std::vector<PetscInt> *gather, PetscInt *diagonal_count,
                               std::vector<PetscInt> *rows, std::vector<PetscInt> *cols, std::string *why)
{
  Mat             Ad = A, Ao = nullptr;
  const PetscInt *garray = nullptr, *ia, *ja;
  PetscInt        rstart, cstart, nr, N;
  PetscBool       mpi, seq, done;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpi));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQAIJ, &seq));
  if (!mpi && !seq) {
    *why = "the level's operator is not AIJ";
    PetscFunctionReturn(0);
  }
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, &garray));
  PetscCall(MatGetOwnershipRange(A, &rstart, nullptr));
  PetscCall(MatGetOwnershipRangeColumn(A, &cstart, nullptr));
  PetscCall(MatGetSize(A, &N, nullptr));
  if (rstart % 3 || cstart % 3 || N % 3) {
    *why = "the level's rows are not in nodes of 3";
    PetscFunctionReturn(0);
  }
  // every stored entry: (global block row * nodes + global block column, (scalar row % 3) * 3 + column % 3,
  // its index), sorted so that a block's entries are together and the blocks in row order
  struct Key {
    long     block;
    int      entry;
    PetscInt at;
  };
  std::vector<Key> keys;
  const long       nodes = N / 3;
  *diagonal_count        = 0;
  for (int part = 0; part < (mpi ? 2 : 1); ++part) {
    Mat M = part ? Ao : Ad;
    PetscCall(MatGetRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
    PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP,
               "grid multigrid: no row structure of a level's operator");
    for (PetscInt i = 0; i < nr; ++i)
      for (PetscInt k = ia[i]; k < ia[i + 1]; ++k) {
        const PetscInt col = part ? garray[ja[k]] : cstart + ja[k], row = rstart + i;
        keys.push_back({(long)(row / 3) * nodes + col / 3, (int)(3 * (row % 3) + col % 3),
                        part ? *diagonal_count + k : k});
      }
    if (!part) *diagonal_count = ia[nr];
    PetscCall(MatRestoreRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &nr, &ia, &ja, &done));
  }
  std::sort(keys.begin(), keys.end(), [](const Key &a, const Key &b) { return a.block < b.block; });
  gather->clear();
  rows->clear();
  cols->clear();
  for (size_t q = 0; q < keys.size(); ++q) {
    if (q == 0 || keys[q].block != keys[q - 1].block) {
      rows->push_back((PetscInt)(keys[q].block / nodes));
      cols->push_back((PetscInt)(keys[q].block % nodes));
      gather->insert(gather->end(), 9, -1);
    }
    (*gather)[gather->size() - 9 + keys[q].entry] = keys[q].at;
  }
  PetscFunctionReturn(0);
}

PetscErrorCode GridMGAijGather(Mat A, const std::vector<PetscInt> &gather, PetscInt diagonal_count,
                               std::vector<PetscScalar> *blocks)
{
  Mat                Ad = A, Ao = nullptr;
  const PetscScalar *va, *vo    = nullptr;
  PetscBool          mpi;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpi));
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, nullptr));
  PetscCall(MatSeqAIJGetArrayRead(Ad, &va));
  if (Ao) PetscCall(MatSeqAIJGetArrayRead(Ao, &vo));
  blocks->resize(gather.size());
  for (size_t q = 0; q < gather.size(); ++q) {
    const PetscInt g = gather[q];
    (*blocks)[q]     = g < 0 ? 0.0 : (g < diagonal_count ? va[g] : vo[g - diagonal_count]);
  }
  PetscCall(MatSeqAIJRestoreArrayRead(Ad, &va));
  if (Ao) PetscCall(MatSeqAIJRestoreArrayRead(Ao, &vo));
  PetscFunctionReturn(0);
}

PetscErrorCode GridMGShareTarget(MPI_Comm comm, Mat Ac, const GridMG::DistributedLevel &c, Mat *target)
{
  PetscMPIInt           rank;
  std::vector<PetscInt> rows, cols, ci, cj;
  Mat                   A;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(BlockGalerkinBlocksOf(Ac, &rows, &cols));
  for (size_t k = 0; k < rows.size(); ++k)
    for (int e = 0; e < 9; ++e) { // BAIJ blocks are column-major
      ci.push_back(3 * (PetscInt)c.num[rows[k]] + e % 3);
      cj.push_back(3 * (PetscInt)c.num[cols[k]] + e / 3);
    }
  const PetscInt local = 3 * (c.offsets[rank + 1] - c.offsets[rank]), global = 3 * c.side * c.side;
  PetscCall(MatCreate(comm, &A));
  PetscCall(MatSetOptionsPrefix(A, "grid_mg_coarse_")); // -mat_view is for the system matrix
  PetscCall(MatSetSizes(A, local, local, global, global));
  PetscCall(MatSetBlockSize(A, 3));
  PetscCall(MatSetType(A, MATAIJ));
  // viewers off: MPIAIJ's COO preallocation assembles its parts on their own (-mat_view printed them)
  PetscCall(PetscOptionsPushCreateViewerOff(PETSC_TRUE));
  PetscCall(MatSetPreallocationCOO(A, (PetscCount)ci.size(), ci.data(), cj.data()));
  PetscCall(PetscOptionsPopCreateViewerOff());
  *target = A;
  PetscFunctionReturn(0);
}

PetscErrorCode GridMGDistributedRefill(GridMG *mg, const PetscScalar *coo_values)
{
  PetscScalar *a;
  MPI_Comm     comm;

  PetscFunctionBegin;
  PetscCall(PetscObjectGetComm((PetscObject)mg->pc, &comm));
  // this rank's share of the first product, summed into the AIJ level by COO (the other ranks' shares of
  // its rows come from them); each further level the same from this rank's rows of the level above
  PetscCall(BlockGalerkinRefill(&mg->galerkin[0], coo_values));
  PetscCall(MatSeqBAIJGetArray(mg->galerkin[0].Ac, &a));
  PetscCall(MatSetValuesCOO(mg->aij_levels[0], a, INSERT_VALUES));
  PetscCall(MatSeqBAIJRestoreArray(mg->galerkin[0].Ac, &a));
  for (size_t l = 1; l < mg->aij_levels.size(); ++l) {
    GridMG::DistributedLevel &d = mg->dist_levels[l - 1]; // the source level
    if (!mg->aij_levels[l]) { // first refill: the source level has its structure now
      std::vector<PetscInt> rows, cols;
      std::string           why;
      PetscCall(GridMGAijBlocks(mg->aij_levels[l - 1], &d.gather, &d.diagonal_count, &rows, &cols, &why));
      PetscCheck(why.empty(), comm, PETSC_ERR_PLIB, "grid multigrid: %s", why.c_str());
      std::vector<int> phys(d.num.size()); // the level's solver -> physics numbering (the weights')
      for (size_t k = 0; k < d.num.size(); ++k) phys[d.num[k]] = (int)k;
      for (PetscInt &r : rows) r = phys[r];
      for (PetscInt &c : cols) c = phys[c];
      const GridMG::DistributedLevel &c = mg->dist_levels[l];
      PetscCall(
        BlockGalerkinCreate(rows, cols, true, false, false, c.weights, c.side * c.side, &mg->galerkin[l]));
      PetscCall(GridMGShareTarget(comm, mg->galerkin[l].Ac, c, &mg->aij_levels[l]));
    }
    PetscCall(GridMGAijGather(mg->aij_levels[l - 1], d.gather, d.diagonal_count, &d.blocks));
    PetscCall(SlabGSHeldOf((PetscObject)mg->aij_levels[l - 1], &d.held));
    PetscCall(BlockGalerkinRefill(&mg->galerkin[l], d.blocks.data()));
    PetscCall(MatSeqBAIJGetArray(mg->galerkin[l].Ac, &a));
    PetscCall(MatSetValuesCOO(mg->aij_levels[l], a, INSERT_VALUES));
    PetscCall(MatSeqBAIJRestoreArray(mg->galerkin[l].Ac, &a));
  }
  // The fine level's residual in its slabs' layout where they hold every coupling of the rank's rows
  const PetscInt fine = (PetscInt)mg->aij_levels.size();
  if (mg->smoother_slab && mg->slab_used[fine] == GridMG::kSlab && mg->slabs[fine].distributed) {
    Mat A;
    PetscCall(PCGetOperators(mg->pc, &A, nullptr));
    PetscCall(SlabGSAttach(A, &mg->slabs[fine]));
    PetscCall(PCMGSetResidual(mg->pc, fine, SlabGSResidualMat, A));
  }
  for (size_t l = 0; l < mg->aij_levels.size(); ++l) {
    const PetscInt level = (PetscInt)(mg->aij_levels.size() - 1 - l);
    PetscCall(PCMGSetOperators(mg->pc, level, mg->aij_levels[l], mg->aij_levels[l]));
    if (level > 0) { // PCMG sets the pre-smoother's; the post-smoother is another KSP
      KSP up;
      PetscCall(PCMGGetSmootherUp(mg->pc, level, &up));
      PetscCall(KSPSetOperators(up, mg->aij_levels[l], mg->aij_levels[l]));
    }
  }
  PetscFunctionReturn(0);
}

PetscErrorCode GridMGAgreeOnSlabs(GridMG *mg, PetscInt level, const std::string &why, GridMG::SlabUse *use)
{
  int here_ok = why.empty(), all_ok;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Allreduce(&here_ok, &all_ok, 1, MPI_INT, MPI_LAND, PetscObjectComm((PetscObject)mg->pc)));
  mg->slab_used[level] = all_ok ? GridMG::kSlab : GridMG::kSor;
  if (!all_ok) {
    mg->slabs[level] = SlabGS();
    PetscCall(PetscInfo(mg->pc, "grid multigrid level %d keeps SOR: %s\n", (int)level,
                        here_ok ? "another rank's rows cannot be swept in slabs" : why.c_str()));
  }
  *use = mg->slab_used[level];
  PetscFunctionReturn(0);
}

namespace {

// The slabs of this rank's rows of A: the blocks among them, and (distributed) the halo toward the other
// ranks' rows. Returns why they cannot be swept in slabs, or an empty string.
PetscErrorCode BuildAijSlabs(Mat A, GridMG::AijSlab *a, SlabGS *gs, std::string *why)
{
  std::vector<PetscInt> rows, cols;
  PetscInt              rstart, rend;
  PetscMPIInt           size;

  PetscFunctionBegin;
  PetscCall(GridMGAijBlocks(A, &a->gather, &a->diagonal_count, &rows, &cols, why));
  if (!why->empty()) PetscFunctionReturn(0);
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)A), &size));
  PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
  const PetscInt                    r0 = rstart / 3, n = (rend - rstart) / 3;
  std::vector<SlabGS::Entry>        entries;
  std::vector<SlabGS::HaloEntry>    halo;
  std::vector<PetscInt>             ghosts;
  std::unordered_map<PetscInt, int> ghost_of;
  for (size_t k = 0; k < rows.size(); ++k) {
    const PetscInt r = rows[k] - r0, c = cols[k] - r0;
    if (c >= 0 && c < n) {
      entries.push_back({(int)r, (int)c, (long)k, false});
      continue;
    }
    const auto g = ghost_of.emplace(cols[k], (int)ghosts.size());
    if (g.second) ghosts.push_back(cols[k]);
    halo.push_back({(int)r, g.first->second, (long)k, false});
  }
  *why = SlabGSBuild((int)n, std::move(entries), false, gs);
  if (why->empty() && size > 1) SlabGSSetHalo(gs, std::move(halo), std::move(ghosts));
  PetscFunctionReturn(0);
}

// The PCSHELL set-up: at the first, the ranks decide together on slabs or SOR; then the slabs take the
// operator's new values (once per new set: the pre- and post-smoother share them).
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
    std::string     why;
    GridMG::SlabUse use;
    PetscCall(BuildAijSlabs(A, a, &mg->slabs[a->level], &why));
    PetscCall(GridMGAgreeOnSlabs(mg, a->level, why, &use));
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
  // the same blocks in the same order (GridMGAijBlocks of the same operator) where the distributed
  // products just gathered them as the next product's source; else gathered here
  const PetscScalar *blocks = nullptr;
  const size_t       l      = mg->aij_levels.size() - 1 - (size_t)a->level; // A is aij_levels[l]?
  if (mg->distributed && a->level < (PetscInt)mg->aij_levels.size() && l < mg->dist_levels.size() &&
      mg->aij_levels[l] == A && mg->dist_levels[l].held.id == now.id &&
      mg->dist_levels[l].held.state == now.state)
    blocks = mg->dist_levels[l].blocks.data();
  else {
    PetscCall(GridMGAijGather(A, a->gather, a->diagonal_count, &a->blocks));
    blocks = a->blocks.data();
  }
  PetscCall(SlabGSRefill(&mg->slabs[a->level], blocks));
  // the level's residual in the slabs' layout too (with the halo on more ranks): MPIAIJ's took more time
  // than the level's smoothing (cloth.opts, 2 ranks, the 81 x 81 level: 5.4 against 2.9 ms per step);
  // once per operator, which keeps its identity from refill to refill
  if (now.id != a->held.id) {
    PetscCall(SlabGSAttach(A, &mg->slabs[a->level]));
    PetscCall(PCMGSetResidual(mg->pc, a->level, SlabGSResidualMat, A));
  }
  a->held = now;
  PetscFunctionReturn(0);
}

// Richardson's one application: the sweeps from the smoother's guess (the halo takes the other ranks'
// part), or SOR's
PetscErrorCode AijSlabApplyRichardson(PC pc, Vec b, Vec x, Vec w, PetscReal rtol, PetscReal abstol,
                                      PetscReal dtol, PetscInt its, PetscBool zero_guess, PetscInt *outits,
                                      PCRichardsonConvergedReason *reason)
{
  GridMG::AijSlab *a;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &a));
  if (a->mg->slab_used[a->level] != GridMG::kSlab)
    PetscCall(PCApplyRichardson(a->sor, b, x, w, rtol, abstol, dtol, its, zero_guess, outits, reason));
  else {
    PetscCall(SlabGSApplySweeps(&a->mg->slabs[a->level], b, x, its, zero_guess));
    *outits = its;
    *reason = PCRICHARDSON_CONVERGED_ITS;
  }
  PetscFunctionReturn(0);
}

// As a preconditioner (outside a Richardson smoother): one sweep from zero
PetscErrorCode AijSlabApply(PC pc, Vec b, Vec x)
{
  GridMG::AijSlab *a;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &a));
  if (a->mg->slab_used[a->level] == GridMG::kSlab)
    PetscCall(SlabGSApplySweeps(&a->mg->slabs[a->level], b, x, 1, PETSC_TRUE));
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
                                     "(symmetric sweep, 8 rows side by side)\n"));
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

PetscErrorCode GridMGAijSmoother(PC spc, GridMG::AijSlab *a)
{
  PetscFunctionBegin;
  PetscCall(PCSetType(spc, PCSHELL));
  PetscCall(PCShellSetContext(spc, a));
  PetscCall(PCShellSetSetUp(spc, AijSlabSetUp));
  PetscCall(PCShellSetApply(spc, AijSlabApply));
  PetscCall(PCShellSetApplyRichardson(spc, AijSlabApplyRichardson));
  PetscCall(PCShellSetView(spc, AijSlabView));
  PetscCall(PCShellSetName(spc, "grid multigrid coarse-level smoother"));
  PetscFunctionReturn(0);
}
