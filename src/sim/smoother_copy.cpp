#include "sim/smoother_copy.h"

#include <petscbinbcsr.h>
#include <petsc/private/pcimpl.h>    // whether PCSetUp will rebuild
#include <petsc/private/pcmgimpl.h>  // the levels' smoothers as they are
#include <petsc/private/petscimpl.h> // PetscObjectStateGet

#include <utility>

namespace {

PetscLogEvent COPIES_Update = 0;

// -log_view event: making or refilling the copies of the levels' operators and transfers
PetscErrorCode SmootherCopiesRegisterEvents()
{
  static PetscClassId classid = 0;
  PetscFunctionBegin;
  if (classid) PetscFunctionReturn(0);
  PetscCall(PetscClassIdRegister("GAMGSmootherCopies", &classid));
  PetscCall(PetscLogEventRegister("GAMGCopies", classid, &COPIES_Update));
  PetscFunctionReturn(0);
}

PetscErrorCode IsBinBCSR(Mat A, PetscBool *binbcsr)
{
  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)A, binbcsr, MATSEQBINBCSR, MATMPIBINBCSR, ""));
  PetscFunctionReturn(0);
}

// A single-precision binbcsr on comm for the scalar COO list (i, j) (global indices) of an operator
// with A's row and column layout (block size 3 where every rank's share allows, else 1), upper-triangle
// storage if `upper`, its values to come in the list's order.
// (PETSc 3.18's MatSetPreallocationCOO may reorder the lists it is given: they are the callee's.)
PetscErrorCode CreateSingle(Mat A, PetscBool upper, std::vector<PetscInt> i, std::vector<PetscInt> j,
                            Mat *copy)
{
  MPI_Comm comm;
  PetscInt m, n, M, N;
  int      by3, all_by3;

  PetscFunctionBegin;
  PetscCall(PetscObjectGetComm((PetscObject)A, &comm));
  PetscCall(MatGetLocalSize(A, &m, &n));
  PetscCall(MatGetSize(A, &M, &N));
  by3 = m % 3 == 0 && n % 3 == 0;
  PetscCallMPI(MPI_Allreduce(&by3, &all_by3, 1, MPI_INT, MPI_LAND, comm));
  PetscCall(MatCreate(comm, copy));
  PetscCall(MatSetSizes(*copy, m, n, M, N));
  PetscCall(MatSetBlockSize(*copy, all_by3 ? 3 : 1));
  PetscCall(MatSetType(*copy, MATBINBCSR));
  if (upper) PetscCall(MatBinBCSRSetSymmetricStorage(*copy, PETSC_TRUE));
  PetscCall(MatBinBCSRSetPrecision(*copy, MAT_BINBCSR_PRECISION_SINGLE));
  PetscCall(MatSetPreallocationCOO(*copy, (PetscCount)i.size(), i.data(), j.data()));
  PetscFunctionReturn(0);
}

// SeqBAIJ (block size 3, the block Galerkin products): the COO list in the order of the value array.
PetscErrorCode RefillFromBAIJ(Mat A, PetscBool upper, Mat *copy)
{
  PetscFunctionBegin;
  if (!*copy) {
    PetscInt        bs, nb;
    const PetscInt *ia, *ja;
    PetscBool       done;
    PetscCall(MatGetBlockSize(A, &bs));
    PetscCall(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &nb, &ia, &ja, &done)); // block rows
    PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP,
               "SmootherCopyRefill: no row structure from this BAIJ matrix");
    std::vector<PetscInt> i, j;
    i.reserve((size_t)ia[nb] * bs * bs);
    j.reserve((size_t)ia[nb] * bs * bs);
    for (PetscInt br = 0; br < nb; ++br)
      for (PetscInt k = ia[br]; k < ia[br + 1]; ++k)
        for (PetscInt c = 0; c < bs; ++c) // BAIJ blocks are column-major
          for (PetscInt r = 0; r < bs; ++r) i.push_back(bs * br + r), j.push_back(bs * ja[k] + c);
    PetscCall(MatRestoreRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &nb, &ia, &ja, &done));
    PetscCall(CreateSingle(A, upper, std::move(i), std::move(j), copy));
  }
  PetscScalar *a;
  PetscCall(MatSeqBAIJGetArray(A, &a));
  PetscCall(MatSetValuesCOO(*copy, a, INSERT_VALUES));
  PetscCall(MatSeqBAIJRestoreArray(A, &a));
  PetscFunctionReturn(0);
}

// The copy of an AIJ matrix (seq or MPI), made from this rank's rows through MatGetRow (global columns;
// AIJ's MatGetRowIJ hands i-node matrices out compressed or not at all); `upper` for a symmetric level
// operator, whole storage for a transfer.
PetscErrorCode CreateFromAIJRows(Mat A, PetscBool upper, Mat *copy)
{
  PetscInt              r0, r1;
  std::vector<PetscInt> i, j;

  PetscFunctionBegin;
  PetscCall(MatGetOwnershipRange(A, &r0, &r1));
  for (PetscInt r = r0; r < r1; ++r) {
    PetscInt        ncols;
    const PetscInt *cols;
    PetscCall(MatGetRow(A, r, &ncols, &cols, nullptr));
    for (PetscInt k = 0; k < ncols; ++k) i.push_back(r), j.push_back(cols[k]);
    PetscCall(MatRestoreRow(A, r, &ncols, &cols, nullptr));
  }
  PetscCall(CreateSingle(A, upper, std::move(i), std::move(j), copy));
  PetscFunctionReturn(0);
}

// SeqAIJ (PCGAMG's coarse levels and transfers): values from the CSR array, in MatGetRow's order.
PetscErrorCode RefillFromAIJ(Mat A, PetscBool upper, Mat *copy)
{
  const PetscScalar *a;

  PetscFunctionBegin;
  if (!*copy) PetscCall(CreateFromAIJRows(A, upper, copy));
  PetscCall(MatSeqAIJGetArrayRead(A, &a));
  PetscCall(MatSetValuesCOO(*copy, a, INSERT_VALUES));
  PetscCall(MatSeqAIJRestoreArrayRead(A, &a));
  PetscFunctionReturn(0);
}

// MPIAIJ (PCGAMG's levels on more ranks, the cloth's coarse levels on more ranks), symmetric: values
// row by row through MatGetRow (the same order at every call), into upper-triangle storage if `upper`.
PetscErrorCode RefillFromMPIAIJ(Mat A, PetscBool upper, Mat *copy)
{
  PetscInt                 r0, r1;
  std::vector<PetscScalar> v;

  PetscFunctionBegin;
  if (!*copy) PetscCall(CreateFromAIJRows(A, upper, copy));
  PetscCall(MatGetOwnershipRange(A, &r0, &r1));
  for (PetscInt r = r0; r < r1; ++r) {
    PetscInt           ncols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(A, r, &ncols, nullptr, &vals));
    v.insert(v.end(), vals, vals + ncols);
    PetscCall(MatRestoreRow(A, r, &ncols, nullptr, &vals));
  }
  PetscCall(MatSetValuesCOO(*copy, v.data(), INSERT_VALUES));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode SmootherCopySupported(Mat A, PetscBool *supported)
{
  PetscFunctionBegin;
  PetscCall(IsBinBCSR(A, supported));
  if (!*supported) PetscCall(PetscObjectTypeCompareAny((PetscObject)A, supported, MATSEQAIJ, MATSEQBAIJ, ""));
  if (!*supported) { // MPIAIJ where every rank holds rows (GAMG may leave a coarse level to fewer ranks)
    PetscBool mpiaij;
    PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpiaij));
    if (mpiaij) {
      MPI_Comm comm;
      PetscInt m;
      int      rows, min_rows;
      PetscCall(PetscObjectGetComm((PetscObject)A, &comm));
      PetscCall(MatGetLocalSize(A, &m, nullptr));
      rows = m > 0;
      PetscCallMPI(MPI_Allreduce(&rows, &min_rows, 1, MPI_INT, MPI_MIN, comm));
      *supported = min_rows ? PETSC_TRUE : PETSC_FALSE;
    }
  }
  PetscFunctionReturn(0);
}

PetscErrorCode SmootherCopyRefill(Mat A, PetscBool upper, Mat *copy)
{
  PetscBool binbcsr, aij, baij, mpiaij;

  PetscFunctionBegin;
  PetscCall(IsBinBCSR(A, &binbcsr));
  if (binbcsr) {
    if (*copy) PetscCall(MatCopy(A, *copy, SAME_NONZERO_PATTERN));
    else { // the layout without A's values (a fresh mapping, not touched), then the values in single
      PetscCall(MatDuplicate(A, MAT_DO_NOT_COPY_VALUES, copy));
      PetscCall(MatBinBCSRSetPrecision(*copy, MAT_BINBCSR_PRECISION_SINGLE));
      PetscCall(MatCopy(A, *copy, SAME_NONZERO_PATTERN));
    }
    PetscFunctionReturn(0);
  }
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQBAIJ, &baij));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQAIJ, &aij));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpiaij));
  if (baij) PetscCall(RefillFromBAIJ(A, upper, copy));
  else if (aij) PetscCall(RefillFromAIJ(A, upper, copy));
  else if (mpiaij) PetscCall(RefillFromMPIAIJ(A, upper, copy));
  else {
    MatType type;
    PetscCall(MatGetType(A, &type));
    SETERRQ(PetscObjectComm((PetscObject)A), PETSC_ERR_SUP,
            "single-precision smoother copies take binbcsr, aij or seqbaij level operators, not %s", type);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode GAMGSmootherCopiesFromOptions(MPI_Comm comm, GAMGSmootherCopies *c)
{
  const char *precisions[] = {"double", "single"}, *storages[] = {"whole", "upper"};
  PetscInt    precision = c->enabled ? 1 : 0, storage = c->upper ? 1 : 0;

  PetscFunctionBegin;
  PetscOptionsBegin(comm, nullptr, "Multigrid smoothers", "");
  PetscCall(
    PetscOptionsEList("-gamg_smoother_precision",
                      "PCGAMG: smooth, compute residuals and transfer on single-precision binbcsr copies "
                      "of the levels' operators (the outer Krylov method stays on the operator)",
                      "", precisions, 2, precisions[precision], &precision, nullptr));
  PetscCall(PetscOptionsEList("-gamg_smoother_storage",
                              "With -gamg_smoother_precision single: the AIJ levels' copies in whole or "
                              "upper-triangle binbcsr storage",
                              "", storages, 2, storages[storage], &storage, nullptr));
  PetscOptionsEnd();
  c->enabled = precision == 1;
  c->upper   = storage == 1 ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

namespace {

// Every copy and held operator released and the per-level arrays sized for nlev levels (0: none); the
// options (enabled, upper) stay.
PetscErrorCode ResizeLevels(GAMGSmootherCopies *c, PetscInt nlev)
{
  PetscFunctionBegin;
  for (std::vector<Mat> *v :
       {&c->source, &c->copy, &c->interp_source, &c->interp_copy, &c->restrict_copy, &c->restrict_source}) {
    for (Mat &m : *v) PetscCall(MatDestroy(&m));
    v->assign(nlev, nullptr);
  }
  for (std::vector<PetscObjectState> *v :
       {&c->source_state, &c->source_nzstate, &c->interp_state, &c->interp_nzstate})
    v->assign(nlev, 0);
  PetscFunctionReturn(0);
}

// Level l's pre- and post-smoother as PCMG holds them (PCMGGetSmootherUp would make a distinct
// post-smoother, without the pre-smoother's options).
void LevelSmoothers(PC pc, PetscInt l, KSP *down, KSP *up)
{
  *down = ((PC_MG *)pc->data)->levels[l]->smoothd;
  *up   = ((PC_MG *)pc->data)->levels[l]->smoothu;
}

// *held <- A, referenced (the one held before released).
PetscErrorCode Hold(Mat A, Mat *held)
{
  PetscFunctionBegin;
  PetscCall(PetscObjectReference((PetscObject)A));
  PetscCall(MatDestroy(held));
  *held = A;
  PetscFunctionReturn(0);
}

PetscErrorCode InstallLevel(PC pc, PetscInt l, Mat A)
{
  KSP down, up;

  PetscFunctionBegin;
  LevelSmoothers(pc, l, &down, &up);
  PetscCall(KSPSetOperators(down, A, A));
  if (up != down) PetscCall(KSPSetOperators(up, A, A));
  PetscCall(PCMGSetResidual(pc, l, PCMGResidualDefault, A));
  PetscFunctionReturn(0);
}

// Before a set-up that rebuilds the hierarchy: GAMG gets back its own operators and transfers, since
// it builds the new coarse levels from what PCMG holds (with -pc_gamg_reuse_interpolation, the
// default in PETSc 3.18: MatPtAP of the fine smoother's operator with PCMG's interpolation).
PetscErrorCode RestoreGAMGOwn(PC pc, GAMGSmootherCopies *c)
{
  PetscFunctionBegin;
  for (size_t l = 1; l < c->copy.size(); ++l) {
    KSP down, up;
    Mat Amat, P;
    LevelSmoothers(pc, (PetscInt)l, &down, &up);
    PetscCall(KSPGetOperators(down, &Amat, nullptr));
    if (c->copy[l] && Amat == c->copy[l]) PetscCall(InstallLevel(pc, (PetscInt)l, c->source[l]));
    PetscCall(PCMGGetInterpolation(pc, (PetscInt)l, &P));
    if (c->interp_copy[l] && P == c->interp_copy[l]) {
      PetscCall(PCMGSetInterpolation(pc, (PetscInt)l, c->interp_source[l]));
      PetscCall(PCMGSetRestriction(pc, (PetscInt)l, c->interp_source[l]));
    }
  }
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode GAMGSmootherCopiesUpdate(KSP ksp, GAMGSmootherCopies *c)
{
  PC        pc;
  PetscBool gamg;
  PetscInt  nlev;

  PetscFunctionBegin;
  if (!c->enabled) PetscFunctionReturn(0);
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCGAMG, &gamg));
  if (!gamg) PetscFunctionReturn(0);
  if (pc->setupcalled && !pc->reusepreconditioner && pc->pmat) { // will PCSetUp rebuild?
    PetscObjectState state;
    PetscCall(PetscObjectStateGet((PetscObject)pc->pmat, &state));
    if (state != pc->matstate) PetscCall(RestoreGAMGOwn(pc, c));
  }
  // PCGAMG's hierarchy, built at the first call, then rebuilt (the PC's operator changed) or reused,
  // here rather than in KSPSolve: after a KSP's first solve KSPSetUp leaves the PC to KSPSolve
  PetscCall(KSPSetUp(ksp));
  PetscCall(PCSetUp(pc));
  PetscCall(PCMGGetLevels(pc, &nlev));
  PetscCall(SmootherCopiesRegisterEvents());
  PetscCall(PetscLogEventBegin(COPIES_Update, 0, 0, 0, 0));
  if ((PetscInt)c->copy.size() != nlev) PetscCall(ResizeLevels(c, nlev));
  // A level's operator or transfer is copied when it will serve more than one solve: with the hierarchy
  // reused (-ksp_reuse_preconditioner) at once, so that the first solve, which takes the most
  // iterations, runs on the copies too; rebuilt at every solve without reusing its interpolation,
  // GAMG's new coarse levels and transfers are not copied at all (copying them at every set-up cost more
  // than it saved), while the fine operator, the same Mat refilled, is from its second solve on.
  PetscBool reuse;
  PetscCall(PCGetReusePreconditioner(pc, &reuse));
  for (PetscInt l = 1; l < nlev; ++l) {
    KSP              down, up;
    Mat              Amat;
    PetscBool        supported;
    PetscObjectState nz, state;
    LevelSmoothers(pc, l, &down, &up);
    PetscCall(KSPGetOperators(down, &Amat, nullptr));
    if (c->copy[l] && Amat == c->copy[l]) { // installed: refilled when the operator's values changed
      PetscCall(PetscObjectStateGet((PetscObject)c->source[l], &state));
      if (state == c->source_state[l]) continue;
      PetscCall(SmootherCopyRefill(c->source[l], c->upper, &c->copy[l]));
      c->source_state[l] = state;
      continue;
    }
    PetscCall(SmootherCopySupported(Amat, &supported));
    if (!supported) continue;
    PetscCall(MatGetNonzeroState(Amat, &nz));
    if (Amat != c->source[l] || nz != c->source_nzstate[l]) { // a new operator: remembered
      PetscCall(MatDestroy(&c->copy[l]));
      PetscCall(Hold(Amat, &c->source[l]));
      c->source_nzstate[l] = nz;
      if (!reuse) continue;
    }
    // the same operator (and pattern) for another solve, or a reused hierarchy's: its copy, made or
    // refilled, goes in
    PetscCall(PetscObjectStateGet((PetscObject)Amat, &state));
    if (!c->copy[l] || state != c->source_state[l])
      PetscCall(SmootherCopyRefill(Amat, c->upper, &c->copy[l]));
    c->source_state[l] = state;
    PetscCall(InstallLevel(pc, l, c->copy[l]));
  }
  for (PetscInt l = 1; l < nlev; ++l) { // the transfers into level l
    Mat              P;
    PetscBool        aij;
    PetscObjectState state;
    PetscCall(PCMGGetInterpolation(pc, l, &P));
    if (c->interp_copy[l] && P == c->interp_copy[l]) continue;
    PetscCall(PetscObjectTypeCompare((PetscObject)P, MATSEQAIJ, &aij));
    if (!aij) continue;
    PetscCall(PetscObjectStateGet((PetscObject)P, &state));
    if (P != c->interp_source[l]) { // a new interpolation: remembered
      PetscCall(MatDestroy(&c->interp_copy[l]));
      PetscCall(MatDestroy(&c->restrict_copy[l]));
      PetscCall(MatDestroy(&c->restrict_source[l]));
      PetscCall(Hold(P, &c->interp_source[l]));
      c->interp_state[l] = state;
      if (!reuse) continue;
    }
    if (!c->interp_copy[l] || state != c->interp_state[l]) {
      PetscObjectState nz;
      PetscCall(MatGetNonzeroState(P, &nz));
      if (nz != c->interp_nzstate[l]) { // another pattern: the copies made anew
        PetscCall(MatDestroy(&c->interp_copy[l]));
        PetscCall(MatDestroy(&c->restrict_copy[l]));
        PetscCall(MatDestroy(&c->restrict_source[l]));
      }
      // made, or refilled in place (a refitted coarse space, gamg_coarse_space.h); restriction by
      // products of a copy of P^T, not by transposed products
      PetscCall(RefillFromAIJ(P, PETSC_FALSE, &c->interp_copy[l]));
      PetscCall(MatTranspose(P, c->restrict_source[l] ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX,
                             &c->restrict_source[l]));
      PetscCall(RefillFromAIJ(c->restrict_source[l], PETSC_FALSE, &c->restrict_copy[l]));
      c->interp_state[l]   = state;
      c->interp_nzstate[l] = nz;
    }
    PetscCall(PCMGSetInterpolation(pc, l, c->interp_copy[l]));
    PetscCall(PCMGSetRestriction(pc, l, c->restrict_copy[l]));
  }
  PetscCall(PetscLogEventEnd(COPIES_Update, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode GAMGSmootherCopiesOwnInterpolations(PC pc, const GAMGSmootherCopies *c,
                                                   std::vector<Mat> *interp)
{
  PetscInt nlev;

  PetscFunctionBegin;
  PetscCall(PCMGGetLevels(pc, &nlev));
  interp->assign(nlev, nullptr);
  for (PetscInt l = 1; l < nlev; ++l) {
    PetscCall(PCMGGetInterpolation(pc, l, &(*interp)[l]));
    if (c && (size_t)l < c->interp_copy.size() && c->interp_copy[l] && (*interp)[l] == c->interp_copy[l])
      (*interp)[l] = c->interp_source[l];
  }
  PetscFunctionReturn(0);
}

void GAMGSmootherCopiesCount(const GAMGSmootherCopies &c, int *levels, int *transfers)
{
  *levels = *transfers = 0;
  for (Mat m : c.copy) *levels += m != nullptr;
  for (Mat m : c.interp_copy) *transfers += m != nullptr;
}

PetscErrorCode GAMGSmootherCopiesDestroy(GAMGSmootherCopies *c)
{
  PetscFunctionBegin;
  PetscCall(ResizeLevels(c, 0));
  *c = GAMGSmootherCopies{};
  PetscFunctionReturn(0);
}
