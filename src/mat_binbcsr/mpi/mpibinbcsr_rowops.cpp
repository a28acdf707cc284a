/* MATMPIBINBCSR operations over rows, columns and whole matrices: diagonal scaling, row extremes,
   column reductions, the missing-diagonal check, equality, MatGetValues, MatAXPY, MatTranspose. As in
   PETSc's MPIAIJ, each works through the parts' own operations where the split A (owned columns) /
   B (ghost columns, compressed through garray) allows it; the rest goes through whole rows. */
#include "mpibinbcsr.h"
#include "../kernels/binbcsr_value_kernels.h"

#include <algorithm>
#include <vector>

namespace {

/* Global point column of local column c of the off-diagonal part. */
inline PetscInt GhostColumn(const Mat_MPIBinBCSR *b, PetscInt bs, PetscInt c)
{
  return b->garray[c / bs] * bs + c % bs;
}

/* MatGetRowMax/Min/MinAbs as MPIAIJ computes them (PETSc's own tests compare the printed columns): the
   diagonal part's own answer over the owned columns, the off-diagonal part's over the others (its
   implicit zeros at the first global column outside the owned ones that it does not store), the better
   of the two, the smaller column on a tie. The off-diagonal rows run the sequential kernels over point
   entries (bw = bs = 1). */
PetscErrorCode RowExtremesByParts(Mat mat, Vec v, PetscInt idx[], int kind,
                                  PetscErrorCode (*part_op)(Mat, Vec, PetscInt[]))
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  const PetscInt  m = mat->rmap->n, n = mat->cmap->n, N = mat->cmap->N, cstart = mat->cmap->rstart,
                 bs = mat->cmap->bs;
  std::vector<PetscInt> ia(m);
  PetscScalar          *x;
  LocalView             xv;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRCheckVecLocalSize(v, m, "The row vector"));
  if (!N) PetscFunctionReturn(0); /* set by MatGetRowMax/Min */
  if (!n) {                       /* no owned columns: MPIAIJ's answer */
    PetscCall(VecGetArrayWrite(v, &x));
    for (PetscInt r = 0; r < m; r++) {
      x[r] = kind == binbcsr::extreme_max   ? PETSC_MIN_REAL
             : kind == binbcsr::extreme_min ? PETSC_MAX_REAL
                                            : 0.0;
      if (idx) idx[r] = -1;
    }
    PetscCall(VecRestoreArrayWrite(v, &x));
    PetscFunctionReturn(0);
  }
  PetscCall(xv.open(v));
  PetscCall(part_op(b->A, xv.seq, ia.data()));
  PetscCall(xv.close());
  if (N == n) { /* every column owned */
    if (idx)
      for (PetscInt r = 0; r < m; r++) idx[r] = ia[r] < 0 ? ia[r] : ia[r] + cstart;
    PetscFunctionReturn(0);
  }
  const PetscBool ghosts   = MPIBinBCSRGhosts(mat) ? PETSC_TRUE : PETSC_FALSE;
  auto            position = [&](PetscInt j) {
    return j < cstart ? j : j + n;
  }; /* global column of the j-th not owned one */
  std::vector<PetscInt> gcols;
  PetscCall(VecGetArray(v, &x));
  for (PetscInt r = 0; r < m; r++) {
    PetscInt           nz = 0, gap = -1, at;
    const PetscInt    *cols = nullptr;
    const PetscScalar *vals = nullptr;
    double             best;
    if (ghosts) PetscCall(MatGetRow(b->B, r, &nz, &cols, &vals));
    gcols.resize(nz);
    for (PetscInt k = 0; k < nz; k++) gcols[k] = GhostColumn(b, bs, cols[k]);
    for (PetscInt k = 0; k < nz && gap < 0; k++)
      if (gcols[k] != position(k)) gap = position(k);
    binbcsr::row_extreme_start(kind, nz == N - n, gap < 0 ? position(nz) : gap, &best, &at);
    for (PetscInt k = 0; k < nz; k++)
      binbcsr::slot_row_extremes(vals + k, 1, 1, false, gcols[k], kind, &best, &at);
    if (ghosts) PetscCall(MatRestoreRow(b->B, r, &nz, &cols, &vals));
    /* the better of the two parts; the smaller column on a tie */
    const PetscInt da = ia[r] + cstart;
    if (binbcsr::row_extreme_beats(kind, best, x[r])) {
      x[r] = best;
      if (idx) idx[r] = at;
    } else if (idx) idx[r] = binbcsr::row_extreme_beats(kind, x[r], best) || da <= at ? da : at;
  }
  PetscCall(VecRestoreArray(v, &x));
  PetscFunctionReturn(0);
}

/* Every entry of X's local rows has a place in Y's pattern (collective answer). */
PetscErrorCode PatternContains(Mat Y, Mat X, PetscBool *contains)
{
  PetscBool local = PETSC_TRUE;

  PetscFunctionBegin;
  for (PetscInt r = Y->rmap->rstart; r < Y->rmap->rend && local; r++) {
    PetscInt        nx, ny;
    const PetscInt *cx, *cy;
    PetscCall(MatGetRow(X, r, &nx, &cx, nullptr));
    PetscCall(MatGetRow(Y, r, &ny, &cy, nullptr));
    local = std::includes(cy, cy + ny, cx, cx + nx) ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(MatRestoreRow(Y, r, &ny, &cy, nullptr));
    PetscCall(MatRestoreRow(X, r, &nx, &cx, nullptr));
  }
  PetscCall(MPIU_Allreduce(&local, contains, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)Y)));
  PetscFunctionReturn(0);
}

/* dst += a * src's local rows (ADD_VALUES; dst holds every entry already, or is being filled) */
PetscErrorCode AddRows(Mat dst, PetscScalar a, Mat src)
{
  std::vector<PetscScalar> scaled;

  PetscFunctionBegin;
  for (PetscInt r = src->rmap->rstart; r < src->rmap->rend; r++) {
    PetscInt           nz;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(src, r, &nz, &cols, &vals));
    scaled.assign(vals, vals + nz);
    for (PetscScalar &v : scaled) v *= a;
    PetscCall(MatSetValues(dst, 1, &r, nz, cols, scaled.data(), ADD_VALUES));
    PetscCall(MatRestoreRow(src, r, &nz, &cols, &vals));
  }
  PetscFunctionReturn(0);
}

} // namespace

PETSC_INTERN PetscErrorCode MatDiagonalScale_MPIBinBCSR(Mat mat, Vec ll, Vec rr)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  LocalView       lv, rv;

  PetscFunctionBegin;
  if (ll) PetscCall(MatBinBCSRCheckVecLocalSize(ll, mat->rmap->n, "The left scaling vector"));
  if (rr) PetscCall(MatBinBCSRCheckVecLocalSize(rr, mat->cmap->n, "The right scaling vector"));
  if (b->sym && ll != rr) { /* decided together, before any rank starts the collective scatter */
    PetscBool same = (ll && rr) ? PETSC_TRUE : PETSC_FALSE, all;
    if (same) PetscCall(VecEqual(ll, rr, &same));
    PetscCall(MPIU_Allreduce(&same, &all, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)mat)));
    PetscCheck(
      all, PetscObjectComm((PetscObject)mat), PETSC_ERR_SUP,
      "MatDiagonalScale with symmetric storage (-mat_binbcsr_symmetric_storage) needs the same left and right scaling: D A D stays symmetric, L A R does not; use full storage for that");
  }
  if (rr) PetscCall(VecScatterBegin(b->Mvctx, rr, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  if (ll) PetscCall(lv.open(ll, true));
  if (rr) PetscCall(rv.open(rr, true));
  PetscCall(MatDiagonalScale(b->A, lv.seq, rv.seq));
  if (ll && MPIBinBCSRGhosts(mat)) PetscCall(MatDiagonalScale(b->B, lv.seq, nullptr));
  PetscCall(lv.close());
  PetscCall(rv.close());
  if (rr) {
    PetscCall(VecScatterEnd(b->Mvctx, rr, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
    if (MPIBinBCSRGhosts(mat)) PetscCall(MatDiagonalScale(b->B, nullptr, b->lvec));
  }
  PetscFunctionReturn(0);
}

/* As MPIAIJ: the larger of the parts' row maxima; on a tie the smaller global column; 0 for a row of
   zeros. */
PETSC_INTERN PetscErrorCode MatGetRowMaxAbs_MPIBinBCSR(Mat mat, Vec v, PetscInt idx[])
{
  Mat_MPIBinBCSR       *b = MPIBinBCSR(mat);
  const PetscInt        m = mat->rmap->n, bs = mat->cmap->bs, cstart = mat->cmap->rstart;
  std::vector<PetscInt> ia(m, 0), ib(m, -1);
  Vec                   va, vb = nullptr;
  const PetscScalar    *a, *bb = nullptr;
  PetscScalar          *x;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRCheckVecLocalSize(v, m, "The row vector"));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, m, &va));
  PetscCall(MatGetRowMaxAbs(b->A, va, ia.data()));
  if (MPIBinBCSRGhosts(mat)) {
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, m, &vb));
    PetscCall(MatGetRowMaxAbs(b->B, vb, ib.data()));
    PetscCall(VecGetArrayRead(vb, &bb));
  }
  PetscCall(VecGetArrayRead(va, &a));
  PetscCall(VecGetArrayWrite(v, &x));
  for (PetscInt i = 0; i < m; i++) {
    PetscInt col = a[i] != 0.0 ? ia[i] + cstart : ia[i];
    x[i]         = a[i];
    if (bb) {
      const PetscInt gb = ib[i] >= 0 ? GhostColumn(b, bs, ib[i]) : -1;
      if (PetscAbsScalar(a[i]) < PetscAbsScalar(bb[i])) {
        x[i] = bb[i];
        col  = gb;
      } else if (PetscAbsScalar(a[i]) == PetscAbsScalar(bb[i]) && gb >= 0 && col > gb) col = gb;
    }
    if (idx) idx[i] = col;
  }
  PetscCall(VecRestoreArrayWrite(v, &x));
  PetscCall(VecRestoreArrayRead(va, &a));
  if (vb) PetscCall(VecRestoreArrayRead(vb, &bb));
  PetscCall(VecDestroy(&va));
  PetscCall(VecDestroy(&vb));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatGetRowMax_MPIBinBCSR(Mat mat, Vec v, PetscInt idx[])
{
  PetscFunctionBegin;
  PetscCall(RowExtremesByParts(mat, v, idx, binbcsr::extreme_max, MatGetRowMax));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatGetRowMin_MPIBinBCSR(Mat mat, Vec v, PetscInt idx[])
{
  PetscFunctionBegin;
  PetscCall(RowExtremesByParts(mat, v, idx, binbcsr::extreme_min, MatGetRowMin));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatGetRowMinAbs_MPIBinBCSR(Mat mat, Vec v, PetscInt idx[])
{
  PetscFunctionBegin;
  PetscCall(RowExtremesByParts(mat, v, idx, binbcsr::extreme_min_abs, MatGetRowMinAbs));
  PetscFunctionReturn(0);
}

/* The parts' reductions of their own columns, placed at their global columns and reduced over the
   ranks (as MPIAIJ; every rank gets all N). */
PETSC_INTERN PetscErrorCode MatGetColumnReductions_MPIBinBCSR(Mat mat, PetscInt type, PetscReal *reductions)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  const PetscInt  N = mat->cmap->N, n = mat->cmap->n, bs = mat->cmap->bs, ng = MPIBinBCSRGhosts(mat) * bs;
  PetscInt        part_type = type;
  std::vector<PetscReal> work(N, 0.0), ra(n), rb(ng);

  PetscFunctionBegin;
  if (type == REDUCTION_MEAN_REALPART) part_type = REDUCTION_SUM_REALPART; /* the mean is over all M rows */
  if (type == REDUCTION_MEAN_IMAGINARYPART) part_type = REDUCTION_SUM_IMAGINARYPART;
  PetscCall(MatGetColumnReductions(b->A, part_type, ra.data()));
  if (ng) PetscCall(MatGetColumnReductions(b->B, part_type, rb.data()));
  if (type == NORM_2) { /* the parts give square roots; sums of squares add */
    for (PetscReal &r : ra) r *= r;
    for (PetscReal &r : rb) r *= r;
  }
  for (PetscInt j = 0; j < n; j++) work[mat->cmap->rstart + j] = ra[j];
  for (PetscInt j = 0; j < ng; j++) work[GhostColumn(b, bs, j)] = rb[j];
  PetscCall(MPIU_Allreduce(work.data(), reductions, N, MPIU_REAL, type == NORM_INFINITY ? MPIU_MAX : MPIU_SUM,
                           PetscObjectComm((PetscObject)mat)));
  if (type == NORM_2)
    for (PetscInt j = 0; j < N; j++) reductions[j] = PetscSqrtReal(reductions[j]);
  if (type == REDUCTION_MEAN_REALPART || type == REDUCTION_MEAN_IMAGINARYPART)
    for (PetscInt j = 0; j < N; j++) reductions[j] /= mat->rmap->N;
  PetscFunctionReturn(0);
}

/* Not collective: this rank's rows; *d (a global row) only when one is missing. */
PETSC_INTERN PetscErrorCode MatMissingDiagonal_MPIBinBCSR(Mat mat, PetscBool *missing, PetscInt *d)
{
  PetscFunctionBegin;
  PetscCheck(mat->rmap->rstart == mat->cmap->rstart && mat->rmap->n == mat->cmap->n, PETSC_COMM_SELF,
             PETSC_ERR_SUP, "Only for matrices whose row and column layouts agree");
  PetscCall(MatMissingDiagonal(MPIBinBCSR(mat)->A, missing, d));
  if (*missing && d) *d += mat->rmap->rstart;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatEqual_MPIBinBCSR(Mat A, Mat B, PetscBool *flg)
{
  Mat_MPIBinBCSR *a = MPIBinBCSR(A), *b = MPIBinBCSR(B);
  PetscBool       local;

  PetscFunctionBegin;
  /* the off-diagonal parts compare column by column only over the same ghost columns */
  local = (A->rmap->n == B->rmap->n && A->cmap->n == B->cmap->n && a->garray == b->garray) ? PETSC_TRUE
                                                                                           : PETSC_FALSE;
  if (local) PetscCall(MatEqual(a->A, b->A, &local));
  if (local && MPIBinBCSRGhosts(A)) PetscCall(MatEqual(a->B, b->B, &local));
  PetscCall(MPIU_Allreduce(&local, flg, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)A)));
  PetscFunctionReturn(0);
}

/* As MPIAIJ: rows of this rank only, columns anywhere (0 where the pattern has no entry); negative
   indices are skipped. */
PETSC_INTERN PetscErrorCode MatGetValues_MPIBinBCSR(Mat mat, PetscInt m, const PetscInt idxm[], PetscInt n,
                                                    const PetscInt idxn[], PetscScalar v[])
{
  Mat_MPIBinBCSR *b      = MPIBinBCSR(mat);
  const PetscInt  rstart = mat->rmap->rstart, rend = mat->rmap->rend, cstart = mat->cmap->rstart,
                 cend = mat->cmap->rend;

  PetscFunctionBegin;
  PetscCheck(mat->assembled, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatGetValues needs an assembled MATMPIBINBCSR matrix");
  for (PetscInt i = 0; i < m; i++) {
    if (idxm[i] < 0) continue;
    PetscCheck(idxm[i] < mat->rmap->N, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", idxm[i], mat->rmap->N);
    PetscCheck(idxm[i] >= rstart && idxm[i] < rend, PETSC_COMM_SELF, PETSC_ERR_SUP,
               "Only local rows: row %" PetscInt_FMT " is not in [%" PetscInt_FMT ", %" PetscInt_FMT ")",
               idxm[i], rstart, rend);
    const PetscInt row = idxm[i] - rstart;
    for (PetscInt j = 0; j < n; j++) {
      if (idxn[j] < 0) continue;
      PetscCheck(idxn[j] < mat->cmap->N, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "Column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", idxn[j], mat->cmap->N);
      PetscScalar *out = v + i * n + j;
      if (idxn[j] >= cstart && idxn[j] < cend) {
        const PetscInt col = idxn[j] - cstart;
        PetscCall(MatGetValues(b->A, 1, &row, 1, &col, out));
      } else {
        PetscInt col;
        PetscCall(MatMPIBinBCSRGhostIndex(mat, idxn[j], &col));
        if (col < 0) *out = 0.0;
        else PetscCall(MatGetValues(b->B, 1, &row, 1, &col, out));
      }
    }
  }
  PetscFunctionReturn(0);
}

/* Y += a X. X of this type over the same ghost columns: the parts' own MatAXPY (slot by slot for the
   same layout, in place for a contained pattern, a new part layout for a larger one). Otherwise X's
   rows are added in place when Y's pattern holds them, else Y is rebuilt over the union of the
   patterns with its configuration (bin width, precision, storage). */
PETSC_INTERN PetscErrorCode MatAXPY_MPIBinBCSR(Mat Y, PetscScalar a, Mat X, MatStructure str)
{
  Mat_MPIBinBCSR *y = MPIBinBCSR(Y);
  PetscBool       xbin, local_same, same_ghosts, contains;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)X, MATMPIBINBCSR, &xbin));
  local_same =
    (xbin && MPIBinBCSR(X)->garray == y->garray && MPIBinBCSR(X)->sym == y->sym) ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(
    MPIU_Allreduce(&local_same, &same_ghosts, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)Y)));
  if (same_ghosts) {
    Mat_MPIBinBCSR  *x     = MPIBinBCSR(X);
    PetscObjectState nz_a0 = y->A->nonzerostate, nz_b0 = y->B ? y->B->nonzerostate : 0;
    PetscCall(MatAXPY(y->A, a, x->A, str));
    if (MPIBinBCSRGhosts(Y)) PetscCall(MatAXPY(y->B, a, x->B, str));
    if (y->A->nonzerostate != nz_a0 || (y->B && y->B->nonzerostate != nz_b0)) {
      /* a part took a larger pattern: what was derived from the old one goes */
      PetscCall(MatMPIBinBCSRDestroyCoo(Y));
      y->offdiag_rows_known = PETSC_FALSE;
      Y->nonzerostate++;
    }
    PetscFunctionReturn(0);
  }
  PetscCall(PatternContains(Y, X, &contains));
  if (contains) {
    PetscCall(AddRows(Y, a, X));
    PetscCall(MatAssemblyBegin(Y, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(Y, MAT_FINAL_ASSEMBLY));
    PetscFunctionReturn(0);
  }
  Mat C;
  PetscCall(MatBinBCSRCreateEmptyLike_Private(Y, Y->rmap->n, Y->cmap->n, Y->rmap->bs, Y->cmap->bs, &C));
  PetscCall(AddRows(C, 1.0, Y));
  PetscCall(AddRows(C, a, X));
  PetscCall(MatAssemblyBegin(C, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(C, MAT_FINAL_ASSEMBLY));
  PetscCall(MatPropagateSymmetryOptions(Y, C));
  PetscCall(MatHeaderReplace(Y, &C));
  PetscFunctionReturn(0);
}

/* Each local row's entries (r, c) become (c, r) of a new matrix of this type and configuration, sent
   to the owner of row c at assembly. Symmetric storage is its own transpose. */
PETSC_INTERN PetscErrorCode MatTranspose_MPIBinBCSR(Mat mat, MatReuse reuse, Mat *B)
{
  Mat C;

  PetscFunctionBegin;
  PetscCheck(mat->assembled, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatTranspose needs an assembled MATMPIBINBCSR matrix");
  if (MPIBinBCSR(mat)->sym) {
    if (reuse == MAT_INITIAL_MATRIX) PetscCall(MatDuplicate(mat, MAT_COPY_VALUES, B));
    else if (reuse == MAT_REUSE_MATRIX && *B != mat) PetscCall(MatCopy(mat, *B, SAME_NONZERO_PATTERN));
    PetscFunctionReturn(0);
  }
  PetscCall(
    MatBinBCSRCreateEmptyLike_Private(mat, mat->cmap->n, mat->rmap->n, mat->cmap->bs, mat->rmap->bs, &C));
  for (PetscInt r = mat->rmap->rstart; r < mat->rmap->rend; r++) {
    PetscInt           nz;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(mat, r, &nz, &cols, &vals));
    PetscCall(MatSetValues(C, nz, cols, 1, &r, vals, INSERT_VALUES)); /* nz x 1 values: one per row of C */
    PetscCall(MatRestoreRow(mat, r, &nz, &cols, &vals));
  }
  PetscCall(MatAssemblyBegin(C, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(C, MAT_FINAL_ASSEMBLY));
  if (reuse == MAT_INITIAL_MATRIX) *B = C;
  else if (reuse == MAT_INPLACE_MATRIX || *B == mat) PetscCall(MatHeaderReplace(mat, &C));
  else {
    PetscCall(MatCopy(C, *B, SAME_NONZERO_PATTERN));
    PetscCall(MatDestroy(&C));
  }
  PetscFunctionReturn(0);
}
