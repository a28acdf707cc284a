/* MATMPIBINBCSR operations: products with the ghost exchange overlapped, diagonal, scaling, zeroing
   rows/columns, rows with global columns, norms, info. The parts are called through their own ops
   (as PETSc's MPIAIJ does) so that their kernels read the local arrays of the parallel vectors. */
#include "mpibinbcsr.h"

#include <algorithm>
#include <cmath>

static inline PetscInt Ghosts(Mat_MPIBinBCSR *b) { return static_cast<PetscInt>(b->garray.size()); }

PETSC_INTERN PetscErrorCode MatMult_MPIBinBCSR(Mat mat, Vec x, Vec y)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(VecScatterBegin(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  PetscUseTypeMethod(b->A, mult, x, y);
  PetscCall(VecScatterEnd(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  if (Ghosts(b)) PetscUseTypeMethod(b->B, multadd, b->lvec, y, y);
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMultAdd_MPIBinBCSR(Mat mat, Vec x, Vec y, Vec z)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(VecScatterBegin(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  PetscUseTypeMethod(b->A, multadd, x, y, z);
  PetscCall(VecScatterEnd(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  if (Ghosts(b)) PetscUseTypeMethod(b->B, multadd, b->lvec, z, z);
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMultTranspose_MPIBinBCSR(Mat mat, Vec x, Vec y)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (Ghosts(b)) PetscUseTypeMethod(b->B, multtranspose, x, b->lvec);
  else PetscCall(VecSet(b->lvec, 0.0));
  PetscUseTypeMethod(b->A, multtranspose, x, y);
  /* collective: ranks without ghosts still receive other ranks' contributions */
  PetscCall(VecScatterBegin(b->Mvctx, b->lvec, y, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecScatterEnd(b->Mvctx, b->lvec, y, ADD_VALUES, SCATTER_REVERSE));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatMultTransposeAdd_MPIBinBCSR(Mat mat, Vec x, Vec y, Vec z)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  if (Ghosts(b)) PetscUseTypeMethod(b->B, multtranspose, x, b->lvec);
  else PetscCall(VecSet(b->lvec, 0.0));
  PetscUseTypeMethod(b->A, multtransposeadd, x, y, z);
  PetscCall(VecScatterBegin(b->Mvctx, b->lvec, z, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecScatterEnd(b->Mvctx, b->lvec, z, ADD_VALUES, SCATTER_REVERSE));
  PetscFunctionReturn(0);
}

/* y = A x and the local part of x.y (see MatMultDotLocal()), in one pass over the diagonal part:
   its fused kernel gives y = A_d x and x.(A_d x) while the ghosts travel; the off-diagonal part then
   adds B x_ghost, which changes only the few rows with off-diagonal entries, and x.(B x_ghost) is
   summed over those rows alone (from their values before and after). */
PETSC_INTERN PetscErrorCode MatMultDotLocal_MPIBinBCSR(Mat mat, Vec x, Vec y, PetscScalar *xdoty)
{
  Mat_MPIBinBCSR *b                                     = MPIBinBCSR(mat);
  PetscErrorCode (*fused)(Mat, Vec, Vec, PetscScalar *) = nullptr;
  PetscScalar d_diag = 0, d_off = 0;

  PetscFunctionBegin;
  PetscCall(PetscObjectQueryFunction((PetscObject)b->A, "MatMultDotLocal_C", &fused));
  if (!fused) { /* parts without a fused kernel: product, then one pass for the dot */
    PetscCall(MatMult_MPIBinBCSR(mat, x, y));
    const PetscScalar *xa, *ya;
    PetscCall(VecGetArrayRead(x, &xa));
    PetscCall(VecGetArrayRead(y, &ya));
    for (PetscInt i = 0; i < mat->rmap->n; i++) d_diag += xa[i] * ya[i];
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(VecRestoreArrayRead(y, &ya));
    PetscCall(PetscLogFlops(2.0 * mat->rmap->n));
    *xdoty = d_diag;
    PetscFunctionReturn(0);
  }
  if (!b->offdiag_rows_known && Ghosts(b)) {
    b->offdiag_rows.clear();
    for (PetscInt r = 0; r < mat->rmap->n; r++) {
      PetscInt nz;
      PetscCall(MatGetRow(b->B, r, &nz, nullptr, nullptr));
      if (nz) b->offdiag_rows.push_back(r);
      PetscCall(MatRestoreRow(b->B, r, &nz, nullptr, nullptr));
    }
    b->offdiag_saved.resize(b->offdiag_rows.size());
  }
  b->offdiag_rows_known = PETSC_TRUE;
  PetscCall(VecScatterBegin(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(fused(b->A, x, y, &d_diag));
  PetscCall(VecScatterEnd(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
  if (Ghosts(b)) {
    const PetscScalar *ya, *xa;
    const std::size_t  nr = b->offdiag_rows.size();
    PetscCall(VecGetArrayRead(y, &ya));
    for (std::size_t k = 0; k < nr; k++) b->offdiag_saved[k] = ya[b->offdiag_rows[k]];
    PetscCall(VecRestoreArrayRead(y, &ya));
    PetscUseTypeMethod(b->B, multadd, b->lvec, y, y);
    PetscCall(VecGetArrayRead(y, &ya));
    PetscCall(VecGetArrayRead(x, &xa));
    for (std::size_t k = 0; k < nr; k++)
      d_off += xa[b->offdiag_rows[k]] * (ya[b->offdiag_rows[k]] - b->offdiag_saved[k]);
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(VecRestoreArrayRead(y, &ya));
    PetscCall(PetscLogFlops(3.0 * nr));
  }
  *xdoty = d_diag + d_off;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatGetDiagonal_MPIBinBCSR(Mat mat, Vec d)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCheck(mat->rmap->rstart == mat->cmap->rstart && mat->rmap->n == mat->cmap->n, PETSC_COMM_SELF,
             PETSC_ERR_SUP, "Only for matrices whose row and column layouts agree");
  PetscUseTypeMethod(b->A, getdiagonal, d);
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatDiagonalSet_MPIBinBCSR(Mat mat, Vec d, InsertMode mode)
{
  LocalView dl;

  PetscFunctionBegin;
  PetscCall(dl.open(d));
  PetscCall(MatDiagonalSet(MPIBinBCSR(mat)->A, dl.seq, mode));
  PetscCall(dl.close());
  PetscFunctionReturn(0);
}

/* As MPIAIJ, the zero pivot the diagonal part met is reported on the matrix (PCPBJACOBI and KSPMCG's
   fused point-block Jacobi look for it there), its row as a global row. */
PETSC_INTERN PetscErrorCode MatInvertBlockDiagonal_MPIBinBCSR(Mat mat, const PetscScalar **values)
{
  Mat A = MPIBinBCSR(mat)->A;

  PetscFunctionBegin;
  PetscCall(MatFactorClearError(A));
  PetscCall(MatInvertBlockDiagonal(A, values));
  mat->factorerrortype = A->factorerrortype;
  if (A->factorerrortype) {
    mat->factorerror_zeropivot_row   = A->factorerror_zeropivot_row + mat->rmap->rstart;
    mat->factorerror_zeropivot_value = A->factorerror_zeropivot_value;
  }
  PetscFunctionReturn(0);
}

/* The variable blocks lie in the rows of this rank (MatSetVariableBlockSizes checks their sum), so in the
   diagonal part, as for MPIAIJ. Unlike MPIAIJ, the matrix's MatSetErrorIfFailure reaches the part and a
   zero pivot the part met is reported on the matrix, where PCVPBJACOBI looks for it. */
PETSC_INTERN PetscErrorCode MatInvertVariableBlockDiagonal_MPIBinBCSR(Mat mat, PetscInt nblocks,
                                                                      const PetscInt *bsizes,
                                                                      PetscScalar    *diag)
{
  Mat A = MPIBinBCSR(mat)->A;

  PetscFunctionBegin;
  PetscCheck(mat->rmap->rstart == mat->cmap->rstart && mat->rmap->n == mat->cmap->n, PETSC_COMM_SELF,
             PETSC_ERR_SUP, "Only for matrices whose row and column layouts agree");
  A->erroriffailure = mat->erroriffailure;
  PetscCall(MatFactorClearError(A));
  PetscCall(MatInvertVariableBlockDiagonal(A, nblocks, bsizes, diag));
  if (A->factorerrortype) {
    mat->factorerrortype             = A->factorerrortype;
    mat->factorerror_zeropivot_row   = A->factorerror_zeropivot_row + mat->rmap->rstart;
    mat->factorerror_zeropivot_value = A->factorerror_zeropivot_value;
  }
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatScale_MPIBinBCSR(Mat mat, PetscScalar a)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatScale(b->A, a));
  if (b->B) PetscCall(MatScale(b->B, a));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatShift_MPIBinBCSR(Mat mat, PetscScalar a)
{
  PetscFunctionBegin;
  PetscCheck(mat->rmap->rstart == mat->cmap->rstart && mat->rmap->n == mat->cmap->n, PETSC_COMM_SELF,
             PETSC_ERR_SUP, "Only for matrices whose row and column layouts agree");
  PetscCall(MatShift(MPIBinBCSR(mat)->A, a));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatZeroEntries_MPIBinBCSR(Mat mat)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);

  PetscFunctionBegin;
  PetscCall(MatZeroEntries(b->A));
  if (b->B) PetscCall(MatZeroEntries(b->B));
  for (auto &e : b->b_staging) e.second = 0;
  PetscFunctionReturn(0);
}

/* The rows (global numbers, given by any rank) that this rank owns, as sorted local numbers. */
static PetscErrorCode OwnedRows(Mat mat, PetscInt n, const PetscInt rows[], std::vector<PetscInt> &lrows)
{
  MPI_Comm                 comm   = PetscObjectComm((PetscObject)mat);
  const PetscInt           rstart = mat->rmap->rstart, rend = mat->rmap->rend;
  std::vector<PetscMPIInt> dest;
  std::vector<PetscInt>    send;

  PetscFunctionBegin;
  lrows.clear();
  for (PetscInt k = 0; k < n; k++) {
    const PetscInt r = rows[k];
    PetscCheck(r >= 0 && r < mat->rmap->N, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", r, mat->rmap->N);
    if (r >= rstart && r < rend) lrows.push_back(r - rstart);
    else {
      PetscCheck(!mat->nooffproczerorows, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
                 "Row %" PetscInt_FMT " is not owned although MAT_NO_OFF_PROC_ZERO_ROWS was set", r);
      PetscMPIInt owner;
      PetscCall(PetscLayoutFindOwner(mat->rmap, r, &owner));
      dest.push_back(owner);
      send.push_back(r);
    }
  }
  if (!mat->nooffproczerorows) {
    PetscSF  sf;
    PetscInt nrecv;
    PetscCall(MatMPIBinBCSRBuildSendSF(comm, static_cast<PetscInt>(dest.size()), dest.data(), &sf, &nrecv));
    std::vector<PetscInt> recv(nrecv);
    PetscCall(PetscSFReduceBegin(sf, MPIU_INT, send.data(), recv.data(), MPI_REPLACE));
    PetscCall(PetscSFReduceEnd(sf, MPIU_INT, send.data(), recv.data(), MPI_REPLACE));
    PetscCall(PetscSFDestroy(&sf));
    for (PetscInt r : recv) lrows.push_back(r - rstart);
  }
  std::sort(lrows.begin(), lrows.end());
  lrows.erase(std::unique(lrows.begin(), lrows.end()), lrows.end());
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatZeroRows_MPIBinBCSR(Mat mat, PetscInt n, const PetscInt rows[],
                                                   PetscScalar diag, Vec x, Vec rhs)
{
  Mat_MPIBinBCSR       *b = MPIBinBCSR(mat);
  std::vector<PetscInt> lrows;

  PetscFunctionBegin;
  PetscCall(OwnedRows(mat, n, rows, lrows));
  if (x && rhs) {
    const PetscScalar *xa;
    PetscScalar       *ba;
    PetscCall(VecGetArrayRead(x, &xa));
    PetscCall(VecGetArray(rhs, &ba));
    for (PetscInt r : lrows) ba[r] = diag * xa[r];
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(VecRestoreArray(rhs, &ba));
  }
  const PetscInt nl = static_cast<PetscInt>(lrows.size());
  PetscCall(MatZeroRows(b->A, nl, lrows.data(), diag, nullptr, nullptr));
  if (Ghosts(b)) PetscCall(MatZeroRows(b->B, nl, lrows.data(), 0.0, nullptr, nullptr));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatZeroRowsColumns_MPIBinBCSR(Mat mat, PetscInt n, const PetscInt rows[],
                                                          PetscScalar diag, Vec x, Vec rhs)
{
  Mat_MPIBinBCSR       *b  = MPIBinBCSR(mat);
  const PetscInt        ng = Ghosts(b) * mat->cmap->bs;
  std::vector<PetscInt> lrows;
  Vec                   mask, ghost_mask;

  PetscFunctionBegin;
  PetscCheck(mat->rmap->rstart == mat->cmap->rstart && mat->rmap->n == mat->cmap->n, PETSC_COMM_SELF,
             PETSC_ERR_SUP, "Only for matrices whose row and column layouts agree");
  PetscCall(OwnedRows(mat, n, rows, lrows));
  const PetscInt nl = static_cast<PetscInt>(lrows.size());

  /* which ghost columns are zeroed: a 0/1 mask on the owned columns, scattered to the ghosts */
  PetscCall(MatCreateVecs(mat, &mask, nullptr));
  PetscCall(VecDuplicate(b->lvec, &ghost_mask));
  {
    PetscScalar *ma;
    PetscCall(VecSet(mask, 0.0));
    PetscCall(VecGetArray(mask, &ma));
    for (PetscInt r : lrows) ma[r] = 1.0;
    PetscCall(VecRestoreArray(mask, &ma));
  }
  PetscCall(VecScatterBegin(b->Mvctx, mask, ghost_mask, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(b->Mvctx, mask, ghost_mask, INSERT_VALUES, SCATTER_FORWARD));

  if (x && rhs) {
    /* rhs -= B(:, zeroed ghost columns) x_ghost; A's part is done by its own ZeroRowsColumns */
    PetscCall(VecScatterBegin(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(b->Mvctx, x, b->lvec, INSERT_VALUES, SCATTER_FORWARD));
    if (ng) {
      Vec       tmp;
      LocalView bl;
      PetscCall(VecPointwiseMult(b->lvec, b->lvec, ghost_mask));
      PetscCall(VecCreateSeq(PETSC_COMM_SELF, mat->rmap->n, &tmp));
      PetscCall(MatMult(b->B, b->lvec, tmp));
      PetscCall(bl.open(rhs));
      PetscCall(VecAXPY(bl.seq, -1.0, tmp));
      PetscCall(bl.close());
      PetscCall(VecDestroy(&tmp));
    }
    LocalView xl, bl;
    PetscCall(xl.open(x, true));
    PetscCall(bl.open(rhs));
    PetscCall(MatZeroRowsColumns(b->A, nl, lrows.data(), diag, xl.seq, bl.seq));
    PetscCall(xl.close());
    PetscCall(bl.close());
  } else {
    PetscCall(MatZeroRowsColumns(b->A, nl, lrows.data(), diag, nullptr, nullptr));
  }

  if (ng) {
    /* zero the masked columns of B in place (the pattern is kept), then the rows */
    const PetscScalar    *gm;
    std::vector<PetscInt> zr, zc; /* all entries first: MatSetValues unassembles B */
    PetscCall(VecGetArrayRead(ghost_mask, &gm));
    for (PetscInt r = 0; r < mat->rmap->n; r++) {
      PetscInt        nz;
      const PetscInt *cols;
      PetscCall(MatGetRow(b->B, r, &nz, &cols, nullptr));
      for (PetscInt k = 0; k < nz; k++)
        if (gm[cols[k]] != 0.0) {
          zr.push_back(r);
          zc.push_back(cols[k]);
        }
      PetscCall(MatRestoreRow(b->B, r, &nz, &cols, nullptr));
    }
    const PetscScalar zero = 0.0;
    for (std::size_t k = 0; k < zr.size(); k++)
      PetscCall(MatSetValues(b->B, 1, &zr[k], 1, &zc[k], &zero, INSERT_VALUES));
    PetscCall(VecRestoreArrayRead(ghost_mask, &gm));
    PetscCall(MatAssemblyBegin(b->B, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(b->B, MAT_FINAL_ASSEMBLY));
    PetscCall(MatZeroRows(b->B, nl, lrows.data(), 0.0, nullptr, nullptr));
  }
  PetscCall(VecDestroy(&mask));
  PetscCall(VecDestroy(&ghost_mask));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatGetRow_MPIBinBCSR(Mat mat, PetscInt row, PetscInt *nz, PetscInt **idx,
                                                 PetscScalar **v)
{
  Mat_MPIBinBCSR *b      = MPIBinBCSR(mat);
  const PetscInt  rstart = mat->rmap->rstart, cstart = mat->cmap->rstart, bs = mat->cmap->bs;

  PetscFunctionBegin;
  PetscCheck(!b->getrow_active, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatRestoreRow() not called for the previous row");
  PetscCheck(row >= rstart && row < mat->rmap->rend, PETSC_COMM_SELF, PETSC_ERR_SUP,
             "Only local rows (asked for %" PetscInt_FMT ", own [%" PetscInt_FMT ", %" PetscInt_FMT "))", row,
             rstart, mat->rmap->rend);
  b->getrow_active        = PETSC_TRUE;
  const PetscInt     lrow = row - rstart;
  PetscInt           na, nb = 0;
  const PetscInt    *ca, *cb;
  const PetscScalar *va, *vb;
  b->row_cols.clear();
  b->row_vals.clear();
  std::vector<std::pair<PetscInt, PetscScalar>> merged;
  PetscCall(MatGetRow(b->A, lrow, &na, &ca, &va));
  for (PetscInt k = 0; k < na; k++) merged.emplace_back(ca[k] + cstart, va[k]);
  PetscCall(MatRestoreRow(b->A, lrow, &na, &ca, &va));
  if (Ghosts(b)) {
    PetscCall(MatGetRow(b->B, lrow, &nb, &cb, &vb));
    for (PetscInt k = 0; k < nb; k++) merged.emplace_back(b->garray[cb[k] / bs] * bs + cb[k] % bs, vb[k]);
    PetscCall(MatRestoreRow(b->B, lrow, &nb, &cb, &vb));
  }
  std::sort(merged.begin(), merged.end(), [](const auto &p, const auto &q) { return p.first < q.first; });
  for (const auto &[c, val] : merged) {
    b->row_cols.push_back(c);
    b->row_vals.push_back(val);
  }
  *nz = static_cast<PetscInt>(merged.size());
  if (idx) *idx = b->row_cols.data();
  if (v) *v = b->row_vals.data();
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatRestoreRow_MPIBinBCSR(Mat mat, PetscInt row, PetscInt *nz, PetscInt **idx,
                                                     PetscScalar **v)
{
  PetscFunctionBegin;
  (void)row;
  (void)nz;
  (void)idx;
  (void)v;
  MPIBinBCSR(mat)->getrow_active = PETSC_FALSE;
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatNorm_MPIBinBCSR(Mat mat, NormType type, PetscReal *norm)
{
  Mat_MPIBinBCSR *b    = MPIBinBCSR(mat);
  MPI_Comm        comm = PetscObjectComm((PetscObject)mat);
  const PetscInt  m    = mat->rmap->n;

  PetscFunctionBegin;
  /* from the rows of the parts, so that every part type that gives rows will do */
  if (type == NORM_FROBENIUS) {
    PetscReal local = 0, global;
    for (Mat part : {b->A, Ghosts(b) ? b->B : nullptr}) {
      if (!part) continue;
      for (PetscInt r = 0; r < m; r++) {
        PetscInt           nz;
        const PetscScalar *v;
        PetscCall(MatGetRow(part, r, &nz, nullptr, &v));
        for (PetscInt k = 0; k < nz; k++) local += PetscRealPart(PetscConj(v[k]) * v[k]);
        PetscCall(MatRestoreRow(part, r, &nz, nullptr, &v));
      }
    }
    PetscCall(MPIU_Allreduce(&local, &global, 1, MPIU_REAL, MPIU_SUM, comm));
    *norm = PetscSqrtReal(global);
  } else if (type == NORM_INFINITY) {
    PetscReal local = 0;
    for (PetscInt r = 0; r < m; r++) {
      PetscInt           nz;
      const PetscScalar *v;
      PetscReal          sum = 0;
      PetscCall(MatGetRow(b->A, r, &nz, nullptr, &v));
      for (PetscInt k = 0; k < nz; k++) sum += PetscAbsScalar(v[k]);
      PetscCall(MatRestoreRow(b->A, r, &nz, nullptr, &v));
      if (Ghosts(b)) {
        PetscCall(MatGetRow(b->B, r, &nz, nullptr, &v));
        for (PetscInt k = 0; k < nz; k++) sum += PetscAbsScalar(v[k]);
        PetscCall(MatRestoreRow(b->B, r, &nz, nullptr, &v));
      }
      local = PetscMax(local, sum);
    }
    PetscCall(MPIU_Allreduce(&local, norm, 1, MPIU_REAL, MPIU_MAX, comm));
  } else if (type == NORM_1) {
    Vec          colsum, ghostsum;
    PetscScalar *cs, *gs;
    PetscCall(MatCreateVecs(mat, &colsum, nullptr));
    PetscCall(VecDuplicate(b->lvec, &ghostsum));
    PetscCall(VecSet(colsum, 0.0));
    PetscCall(VecSet(ghostsum, 0.0));
    PetscCall(VecGetArray(colsum, &cs));
    PetscCall(VecGetArray(ghostsum, &gs));
    for (PetscInt r = 0; r < m; r++) {
      PetscInt           nz;
      const PetscInt    *c;
      const PetscScalar *v;
      PetscCall(MatGetRow(b->A, r, &nz, &c, &v));
      for (PetscInt k = 0; k < nz; k++) cs[c[k]] += PetscAbsScalar(v[k]);
      PetscCall(MatRestoreRow(b->A, r, &nz, &c, &v));
      if (Ghosts(b)) {
        PetscCall(MatGetRow(b->B, r, &nz, &c, &v));
        for (PetscInt k = 0; k < nz; k++) gs[c[k]] += PetscAbsScalar(v[k]);
        PetscCall(MatRestoreRow(b->B, r, &nz, &c, &v));
      }
    }
    PetscCall(VecRestoreArray(colsum, &cs));
    PetscCall(VecRestoreArray(ghostsum, &gs));
    PetscCall(VecScatterBegin(b->Mvctx, ghostsum, colsum, ADD_VALUES, SCATTER_REVERSE));
    PetscCall(VecScatterEnd(b->Mvctx, ghostsum, colsum, ADD_VALUES, SCATTER_REVERSE));
    PetscCall(VecNorm(colsum, NORM_INFINITY, norm));
    PetscCall(VecDestroy(&colsum));
    PetscCall(VecDestroy(&ghostsum));
  } else SETERRQ(comm, PETSC_ERR_SUP, "Norm type %s not supported", NormTypes[type]);
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode MatGetInfo_MPIBinBCSR(Mat mat, MatInfoType flag, MatInfo *info)
{
  Mat_MPIBinBCSR *b = MPIBinBCSR(mat);
  MatInfo         ia, ib;
  PetscLogDouble  local[5], global[5];

  PetscFunctionBegin;
  PetscCall(MatGetInfo(b->A, MAT_LOCAL, &ia));
  if (b->B) PetscCall(MatGetInfo(b->B, MAT_LOCAL, &ib));
  else PetscCall(PetscMemzero(&ib, sizeof(ib)));
  local[0] = ia.nz_used + ib.nz_used;
  local[1] = ia.nz_allocated + ib.nz_allocated;
  local[2] = ia.nz_unneeded + ib.nz_unneeded;
  local[3] = ia.memory + ib.memory + static_cast<PetscLogDouble>(b->garray.size() * sizeof(PetscInt));
  local[4] = ia.mallocs + ib.mallocs;
  if (flag == MAT_LOCAL) {
    for (int k = 0; k < 5; k++) global[k] = local[k];
  } else {
    PetscCall(MPIU_Allreduce(local, global, 5, MPIU_PETSCLOGDOUBLE,
                             flag == MAT_GLOBAL_MAX ? MPI_MAX : MPI_SUM, PetscObjectComm((PetscObject)mat)));
  }
  info->block_size        = mat->rmap->bs;
  info->nz_used           = global[0];
  info->nz_allocated      = global[1];
  info->nz_unneeded       = global[2];
  info->memory            = global[3];
  info->mallocs           = global[4];
  info->assemblies        = mat->num_ass;
  info->fill_ratio_given  = 0;
  info->fill_ratio_needed = 0;
  info->factor_mallocs    = 0;
  PetscFunctionReturn(0);
}
