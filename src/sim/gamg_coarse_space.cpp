#include "sim/gamg_coarse_space.h"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>

namespace {

PetscLogEvent REFIT_Event = 0;

// -log_view event: the prolongators refitted (the Galerkin products after it are GAMG's own events)
PetscErrorCode RefitRegisterEvent()
{
  static PetscClassId classid = 0;
  PetscFunctionBegin;
  if (classid) PetscFunctionReturn(0);
  PetscCall(PetscClassIdRegister("GAMGCoarseSpaceRefit", &classid));
  PetscCall(PetscLogEventRegister("GAMGRefit", classid, &REFIT_Event));
  PetscFunctionReturn(0);
}

// 3D elasticity: six modes (three translations, three rotations) per node, so six columns per aggregate
// in every prolongator and six rows per node below the finest level.
constexpr PetscInt kModes = 6;

// The Householder QR of the ld x kModes column-major matrix a (ld >= kModes): R into r (kModes x
// kModes, row-major, upper), the first kModes columns of Q over a. Eigen's HouseholderQR (the physics'
// dependency) makes the reflectors as LAPACK's geqrf does, which PCGAMG's formProl0 calls (none where a
// column is zero below the diagonal), so Q and R are formProl0's up to the signs of Q's columns and R's
// rows: the same span, the same coarse space.
void HouseholderQR(std::vector<PetscReal> &a, PetscInt ld, PetscReal r[kModes][kModes])
{
  using Block = Eigen::Matrix<PetscReal, Eigen::Dynamic, kModes>;
  Eigen::Map<Block>                 A(a.data(), ld, kModes);
  const Eigen::HouseholderQR<Block> qr(A);
  for (PetscInt i = 0; i < kModes; ++i)
    for (PetscInt k = 0; k < kModes; ++k) r[i][k] = k >= i ? qr.matrixQR()(i, k) : 0.0;
  A = qr.householderQ() * Block::Identity(ld, kModes);
}

// The finest level's modes at node coordinates c (x, y, z), as PCSetCoordinates gives PCGAMG: per node
// a 3 x 6 block, row-major, columns e_x, e_y, e_z, e_x x c, e_y x c, e_z x c.
std::vector<PetscReal> RigidBodyModes(const PetscReal *coords, PetscInt nodes)
{
  std::vector<PetscReal> modes((size_t)nodes * 3 * kModes, 0.0);
  for (PetscInt i = 0; i < nodes; ++i) {
    const PetscReal x = coords[3 * i], y = coords[3 * i + 1], z = coords[3 * i + 2];
    PetscReal      *b         = modes.data() + (size_t)i * 3 * kModes;
    const PetscReal rot[3][3] = {{0, z, -y}, {-z, 0, x}, {y, -x, 0}}; // row d: component d of the rotations
    for (int d = 0; d < 3; ++d) {
      b[kModes * d + d] = 1;
      for (int r = 0; r < 3; ++r) b[kModes * d + 3 + r] = rot[d][r];
    }
  }
  return modes;
}

// This rank's rows r0 + k of one prolongator and what the refit writes into them: row r0 + k gets
// vals[i] at cols[i], i in [offsets[k], offsets[k + 1]) (its pattern, ascending).
struct LocalRows {
  PetscInt                 r0 = 0;
  std::vector<PetscInt>    offsets, cols;
  std::vector<PetscScalar> vals;
};

// All ranks' entries of `mine` (this rank's share, in rank order): the level's arrays over all its nodes.
template <typename T>
PetscErrorCode AllGather(MPI_Comm comm, const std::vector<T> &mine, MPI_Datatype type, std::vector<T> *all)
{
  PetscMPIInt size, count = (PetscMPIInt)mine.size();

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<PetscMPIInt> counts(size), displs(size, 0);
  PetscCallMPI(MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (PetscMPIInt r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  all->resize((size_t)displs[size - 1] + counts[size - 1]);
  PetscCallMPI(
    MPI_Allgatherv(mine.data(), count, type, all->data(), counts.data(), displs.data(), type, comm));
  PetscFunctionReturn(0);
}

// One prolongator P (AIJ, bs rows per node of its fine level, kModes columns per aggregate), from the
// modes of every node of its fine level (per node a bs x kModes block, row-major, the same on every
// rank): this rank's rows refitted (*mine) and the modes of every node of its coarse level (per
// aggregate a kModes x kModes block). Every rank factors every aggregate, in the same order on the same
// data, so all hold the same coarse modes without sending them. *ok false (the same on every rank)
// where P is not plain aggregation or lacks an entry of the refit.
PetscErrorCode RefitLevel(Mat P, PetscInt bs, const std::vector<PetscReal> &modes, LocalRows *mine,
                          std::vector<PetscReal> *coarse_modes, bool *ok)
{
  MPI_Comm comm;
  PetscInt m, n, r0, r1;
  int      fits = 1, all_fit;

  PetscFunctionBegin;
  *ok = false;
  PetscCall(PetscObjectGetComm((PetscObject)P, &comm));
  PetscCall(MatGetSize(P, &m, &n));
  PetscCall(MatGetOwnershipRange(P, &r0, &r1));
  fits = m % bs == 0 && n % kModes == 0 && r0 % bs == 0 && r1 % bs == 0 && (size_t)m * kModes == modes.size();
  PetscCallMPI(MPI_Allreduce(&fits, &all_fit, 1, MPI_INT, MPI_LAND, comm));
  if (!all_fit) PetscFunctionReturn(0);
  const PetscInt nodes = m / bs, aggregates = n / kModes;
  // this rank's nodes' aggregates: the column block of their rows' entries, all in one block
  std::vector<PetscInt> local_aggregate((r1 - r0) / bs, -1), aggregate_of;
  mine->r0 = r0;
  mine->offsets.assign(1, 0);
  mine->cols.clear();
  for (PetscInt r = r0; r < r1; ++r) {
    PetscInt        ncols;
    const PetscInt *cols;
    PetscCall(MatGetRow(P, r, &ncols, &cols, nullptr));
    PetscInt &g = local_aggregate[(r - r0) / bs];
    for (PetscInt k = 0; k < ncols; ++k) {
      if (g < 0) g = cols[k] / kModes;
      fits = fits && cols[k] / kModes == g;
    }
    mine->cols.insert(mine->cols.end(), cols, cols + ncols);
    mine->offsets.push_back((PetscInt)mine->cols.size());
    PetscCall(MatRestoreRow(P, r, &ncols, &cols, nullptr));
  }
  mine->vals.assign(mine->cols.size(), 0.0);
  PetscCall(AllGather(comm, local_aggregate, MPIU_INT, &aggregate_of));
  // every node's aggregate known; the aggregates' members, ascending
  std::vector<PetscInt> first(aggregates + 1, 0), members(nodes);
  for (PetscInt i = 0; i < nodes; ++i)
    if (aggregate_of[i] >= 0) first[aggregate_of[i] + 1]++;
  for (PetscInt g = 0; g < aggregates; ++g) {
    fits = fits && first[g + 1] > 0; // every column block is an aggregate of some nodes
    first[g + 1] += first[g];
  }
  PetscCallMPI(MPI_Allreduce(&fits, &all_fit, 1, MPI_INT, MPI_LAND, comm));
  if (!all_fit) PetscFunctionReturn(0);
  {
    std::vector<PetscInt> fill(first.begin(), first.end() - 1);
    for (PetscInt i = 0; i < nodes; ++i)
      if (aggregate_of[i] >= 0) members[fill[aggregate_of[i]]++] = i;
  }
  coarse_modes->assign((size_t)aggregates * kModes * kModes, 0.0);
  std::vector<PetscReal> qr;
  for (PetscInt g = 0; g < aggregates; ++g) {
    // formProl0's factorisation: the members' mode blocks stacked (column-major, padded with zero rows
    // to at least kModes), geqrf; R -> the coarse node's modes, orgqr's Q -> the members' rows of P
    const PetscInt rows = (first[g + 1] - first[g]) * bs, ld = std::max(rows, kModes);
    qr.assign((size_t)ld * kModes, 0.0);
    for (PetscInt t = first[g]; t < first[g + 1]; ++t)
      for (PetscInt d = 0; d < bs; ++d)
        for (PetscInt j = 0; j < kModes; ++j)
          qr[(size_t)j * ld + (t - first[g]) * bs + d] = modes[((size_t)members[t] * bs + d) * kModes + j];
    PetscReal r[kModes][kModes];
    HouseholderQR(qr, ld, r);
    for (PetscInt i = 0; i < kModes; ++i)
      for (PetscInt j = 0; j < kModes; ++j) (*coarse_modes)[((size_t)g * kModes + i) * kModes + j] = r[i][j];
    for (PetscInt t = first[g]; t < first[g + 1]; ++t)
      for (PetscInt d = 0; d < bs; ++d) {
        const PetscInt row = members[t] * bs + d;
        if (row < r0 || row >= r1) continue; // another rank's row
        const PetscInt *begin = mine->cols.data() + mine->offsets[row - r0],
                       *end   = mine->cols.data() + mine->offsets[row - r0 + 1];
        for (PetscInt j = 0; j < kModes; ++j) {
          const PetscReal q   = qr[(size_t)j * ld + (t - first[g]) * bs + d];
          const PetscInt  col = g * kModes + j;
          const PetscInt *at  = std::lower_bound(begin, end, col);
          if (at != end && *at == col) mine->vals[at - mine->cols.data()] = q;
          else if (q != 0.0) fits = false; // an entry the pattern lacks
        }
      }
  }
  PetscCallMPI(MPI_Allreduce(&fits, &all_fit, 1, MPI_INT, MPI_LAND, comm));
  *ok = all_fit != 0;
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode GAMGRefitCoarseSpace(MPI_Comm comm, const std::vector<Mat> &interp, const PetscReal *coords,
                                    PetscInt nodes, PetscBool *refit)
{
  int usable = interp.size() >= 2, all_usable;

  PetscFunctionBegin;
  *refit = PETSC_FALSE;
  for (PetscInt k = 0; k < 3 * nodes && usable; ++k)
    usable = std::isfinite(coords[k]); // (a set-up from scratch says what breaks)
  for (size_t l = 1; l < interp.size() && usable; ++l) {
    PetscBool aij = PETSC_FALSE;
    if (interp[l])
      PetscCall(PetscObjectTypeCompareAny((PetscObject)interp[l], &aij, MATSEQAIJ, MATMPIAIJ, ""));
    usable = aij;
  }
  if (usable) { // the finest level's rows are this rank's nodes
    PetscInt r0, r1;
    PetscCall(MatGetOwnershipRange(interp.back(), &r0, &r1));
    usable = r1 - r0 == 3 * nodes;
  }
  PetscCallMPI(MPI_Allreduce(&usable, &all_usable, 1, MPI_INT, MPI_LAND, comm));
  if (!all_usable) PetscFunctionReturn(0);
  // every level computed before any is written: a level that cannot be refitted leaves all as they were
  PetscCall(RefitRegisterEvent());
  PetscCall(PetscLogEventBegin(REFIT_Event, 0, 0, 0, 0));
  std::vector<LocalRows> mine(interp.size());
  std::vector<PetscReal> modes, coarse;
  PetscCall(AllGather(comm, RigidBodyModes(coords, nodes), MPIU_REAL, &modes));
  PetscInt bs = 3;
  bool     ok = true;
  for (size_t l = interp.size() - 1; l >= 1 && ok; --l) {
    PetscCall(RefitLevel(interp[l], bs, modes, &mine[l], &coarse, &ok));
    modes.swap(coarse);
    bs = kModes;
  }
  if (ok)
    for (size_t l = 1; l < interp.size(); ++l) { // existing entries only: the pattern stays
      const LocalRows &rows = mine[l];
      for (size_t k = 0; k + 1 < rows.offsets.size(); ++k) {
        const PetscInt row = rows.r0 + (PetscInt)k, at = rows.offsets[k];
        PetscCall(MatSetValues(interp[l], 1, &row, rows.offsets[k + 1] - at, rows.cols.data() + at,
                               rows.vals.data() + at, INSERT_VALUES));
      }
      PetscCall(MatAssemblyBegin(interp[l], MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(interp[l], MAT_FINAL_ASSEMBLY));
    }
  PetscCall(PetscLogEventEnd(REFIT_Event, 0, 0, 0, 0));
  *refit = ok ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}
