#include "sim/gamg_coarse_space.h"

#include <petsc/private/petscimpl.h> // PetscObjectStateIncrease: the values were written through the array

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
// kModes, row-major, upper), the first kModes columns of Q over a. LAPACK's geqrf and orgqr, as
// PCGAMG's formProl0 calls them, up to the signs of Q's columns and R's rows (the same span, the same
// coarse space); written out here since a driver of this project links PETSc, not LAPACK.
void HouseholderQR(std::vector<PetscReal> &a, PetscInt ld, PetscReal r[kModes][kModes])
{
  std::vector<PetscReal> v((size_t)ld * kModes, 0.0); // the reflectors, column j from row j on
  PetscReal              beta[kModes];
  for (PetscInt j = 0; j < kModes; ++j) {
    PetscReal below = 0; // as LAPACK's dlarfg: no reflection where the column is zero below the diagonal
    for (PetscInt i = j + 1; i < ld; ++i) below += a[j * ld + i] * a[j * ld + i];
    const PetscReal x0 = a[j * ld + j], norm = std::sqrt(x0 * x0 + below), alpha = x0 >= 0 ? -norm : norm;
    PetscReal      *vj = v.data() + (size_t)j * ld;
    for (PetscInt i = j; i < ld; ++i) vj[i] = a[j * ld + i];
    vj[j] -= alpha;
    PetscReal vv = 0;
    for (PetscInt i = j; i < ld; ++i) vv += vj[i] * vj[i];
    beta[j] = below > 0 ? 2 / vv : 0;
    for (PetscInt k = j; k < kModes; ++k) {
      PetscReal dot = 0;
      for (PetscInt i = j; i < ld; ++i) dot += vj[i] * a[k * ld + i];
      for (PetscInt i = j; i < ld; ++i) a[k * ld + i] -= beta[j] * dot * vj[i];
    }
  }
  for (PetscInt i = 0; i < kModes; ++i)
    for (PetscInt k = 0; k < kModes; ++k) r[i][k] = k >= i ? a[k * ld + i] : 0.0;
  // Q's first kModes columns: H_0 H_1 ... H_5 applied to those of the identity
  std::fill(a.begin(), a.end(), 0.0);
  for (PetscInt k = 0; k < kModes; ++k) a[k * ld + k] = 1;
  for (PetscInt j = kModes - 1; j >= 0; --j) {
    const PetscReal *vj = v.data() + (size_t)j * ld;
    for (PetscInt k = 0; k < kModes; ++k) {
      PetscReal dot = 0;
      for (PetscInt i = j; i < ld; ++i) dot += vj[i] * a[k * ld + i];
      for (PetscInt i = j; i < ld; ++i) a[k * ld + i] -= beta[j] * dot * vj[i];
    }
  }
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

// One prolongator P (SeqAIJ, bs fine rows per node, kModes columns per aggregate): the refitted values
// in P's value order (into *values) and the next level's modes (per aggregate a kModes x kModes block,
// row-major), from this level's modes (per node a bs x kModes block). False where P is not plain
// aggregation or lacks an entry of the refit.
PetscErrorCode RefitLevel(Mat P, PetscInt bs, const std::vector<PetscReal> &modes,
                          std::vector<PetscScalar> *values, std::vector<PetscReal> *coarse_modes, bool *ok)
{
  PetscInt           m, n, nrows, nz;
  const PetscInt    *ia, *ja;
  const PetscScalar *a;
  PetscBool          done;

  PetscFunctionBegin;
  *ok = false;
  PetscCall(MatGetSize(P, &m, &n));
  if (m % bs || n % kModes || (size_t)m * kModes != modes.size()) PetscFunctionReturn(0);
  const PetscInt nodes = m / bs, aggregates = n / kModes;
  PetscCall(MatGetRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done));
  if (!done) PetscFunctionReturn(0);
  nz = ia[nrows];
  // each node's aggregate: the column block of its rows' entries, which must all lie in one block
  std::vector<PetscInt> first(aggregates + 1, 0), members(nodes), aggregate_of(nodes, -1);
  bool                  plain = true;
  for (PetscInt i = 0; i < nodes && plain; ++i)
    for (PetscInt r = bs * i; r < bs * (i + 1) && plain; ++r)
      for (PetscInt k = ia[r]; k < ia[r + 1]; ++k) {
        const PetscInt g = ja[k] / kModes;
        if (aggregate_of[i] < 0) aggregate_of[i] = g;
        plain = plain && g == aggregate_of[i];
      }
  if (plain) {
    for (PetscInt i = 0; i < nodes; ++i)
      if (aggregate_of[i] >= 0) first[aggregate_of[i] + 1]++;
    for (PetscInt g = 0; g < aggregates; ++g) {
      plain = plain && first[g + 1] > 0; // every column block is an aggregate of some nodes
      first[g + 1] += first[g];
    }
    std::vector<PetscInt> fill(first.begin(), first.end() - 1);
    for (PetscInt i = 0; i < nodes; ++i)
      if (aggregate_of[i] >= 0) members[fill[aggregate_of[i]]++] = i; // ascending within each aggregate
  }
  if (!plain) {
    PetscCall(MatRestoreRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done));
    PetscFunctionReturn(0);
  }
  PetscCall(MatSeqAIJGetArrayRead(P, &a));
  values->assign(a, a + nz);
  PetscCall(MatSeqAIJRestoreArrayRead(P, &a));
  coarse_modes->assign((size_t)aggregates * kModes * kModes, 0.0);
  std::vector<PetscReal> qr;
  bool                   fits = true;
  for (PetscInt g = 0; g < aggregates && fits; ++g) {
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
    for (PetscInt t = first[g]; t < first[g + 1] && fits; ++t)
      for (PetscInt d = 0; d < bs && fits; ++d) {
        const PetscInt row = members[t] * bs + d;
        for (PetscInt j = 0; j < kModes; ++j) {
          const PetscReal q   = qr[(size_t)j * ld + (t - first[g]) * bs + d];
          const PetscInt  col = g * kModes + j;
          const PetscInt *at  = std::lower_bound(ja + ia[row], ja + ia[row + 1], col);
          if (at != ja + ia[row + 1] && *at == col) (*values)[at - ja] = q;
          else if (q != 0.0) fits = false; // an entry the pattern lacks
        }
      }
  }
  PetscCall(MatRestoreRowIJ(P, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done));
  *ok = fits;
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode GAMGRefitCoarseSpace(MPI_Comm comm, const std::vector<Mat> &interp, const PetscReal *coords,
                                    PetscInt nodes, PetscBool *refit)
{
  PetscMPIInt size;

  PetscFunctionBegin;
  *refit = PETSC_FALSE;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (size > 1 || interp.size() < 2) PetscFunctionReturn(0);
  for (PetscInt k = 0; k < 3 * nodes; ++k)
    if (!std::isfinite(coords[k])) PetscFunctionReturn(0); // (a set-up from scratch says what breaks)
  for (size_t l = 1; l < interp.size(); ++l) {
    PetscBool aij;
    if (!interp[l]) PetscFunctionReturn(0);
    PetscCall(PetscObjectTypeCompare((PetscObject)interp[l], MATSEQAIJ, &aij));
    if (!aij) PetscFunctionReturn(0);
  }
  // every level's values first, then written: a level that cannot be refitted leaves all as they were
  PetscCall(RefitRegisterEvent());
  PetscCall(PetscLogEventBegin(REFIT_Event, 0, 0, 0, 0));
  std::vector<std::vector<PetscScalar>> values(interp.size());
  std::vector<PetscReal>                modes = RigidBodyModes(coords, nodes), coarse;
  PetscInt                              bs    = 3;
  bool                                  ok    = true;
  for (size_t l = interp.size() - 1; l >= 1 && ok; --l) {
    PetscCall(RefitLevel(interp[l], bs, modes, &values[l], &coarse, &ok));
    modes.swap(coarse);
    bs = kModes;
  }
  PetscCall(PetscLogEventEnd(REFIT_Event, 0, 0, 0, 0));
  if (!ok) PetscFunctionReturn(0);
  for (size_t l = 1; l < interp.size(); ++l) {
    PetscScalar *a;
    PetscCall(MatSeqAIJGetArrayWrite(interp[l], &a));
    std::copy(values[l].begin(), values[l].end(), a);
    PetscCall(MatSeqAIJRestoreArrayWrite(interp[l], &a));
    PetscCall(PetscObjectStateIncrease((PetscObject)interp[l]));
  }
  *refit = PETSC_TRUE;
  PetscFunctionReturn(0);
}
