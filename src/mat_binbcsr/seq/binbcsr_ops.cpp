/*
   MATSEQBINBCSR: the value operations (zero entries, scale, shift, diagonal set, AXPY, zero rows and
   rows+columns, norms, info). They work on the frozen bin layout in place, one lane at a time through
   the kernels of binbcsr_value_kernels.h, touching only real slots so padding stays zero. An operation
   that would need an entry the layout lacks (a shift on a row without its diagonal block, ...) is
   refused with an error before anything is changed; the pattern only grows through MatAXPY with a
   different pattern, which builds a new layout for the union.
*/
#include "binbcsr.h"
#include "binbcsr_ops.h"
#include "../kernels/binbcsr_value_kernels.h"

#include <algorithm>
#include <vector>

namespace {

/* f(bin_val, bin_col, row, lane, nz) for every real block row, bin_val typed as the storage. */
template <typename V, typename F> void ForEachLane(const Mat_SeqBinBCSR *a, V *val, F &&f)
{
  for (PetscInt b = 0; b < a->nbins; b++) {
    V              *bin_val = val + (size_t)a->bin_start[b] * a->bs2;
    const PetscInt *bin_col = a->col + a->bin_start[b];
    const PetscInt  r0 = b * a->bw, r1 = PetscMin(a->mbs, r0 + a->bw);
    for (PetscInt r = r0; r < r1; r++) f(bin_val, bin_col, r, (int)(r - r0), (int)a->row_nz[r]);
  }
}

template <typename F> void ForEachLane(const Mat_SeqBinBCSR *a, F &&f)
{
  if (a->val) ForEachLane(a, a->val, f);
  else ForEachLane(a, a->valf, f);
}

/* f(value index, row block r, column block c, i, j) for every stored value of a real slot (padding
   excluded), whatever the storage; used where symmetric storage scatters real slots over the bin. */
template <typename F> void ForEachRealValue(const Mat_SeqBinBCSR *a, F &&f)
{
  const PetscInt bs = a->bs;
  for (PetscInt r = 0; r < a->mbs; r++)
    for (PetscInt k = 0; k < a->row_nz[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
      for (PetscInt i = 0; i < bs; i++)
        for (PetscInt j = 0; j < bs; j++) f(BinBCSRValueIndex(s, i * bs + j, a->bw, a->bs2), r, c, i, j);
    }
}

PetscErrorCode CheckBuilt(Mat A, const char *op)
{
  const Mat_SeqBinBCSR *a = (const Mat_SeqBinBCSR *)A->data;
  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "%s needs an assembled MATSEQBINBCSR matrix", op);
  PetscFunctionReturn(0);
}

/* With MatSetErrorIfFailure(A, PETSC_TRUE), NaN or Inf operands are refused (PETSc checks only in
   debug builds; Debian's is not). */
PetscErrorCode CheckFinite(Mat A, PetscScalar v, const char *what)
{
  PetscFunctionBegin;
  if (A->erroriffailure)
    PetscCheck(!PetscIsInfOrNanScalar(v), PETSC_COMM_SELF, PETSC_ERR_FP,
               "%s is %g (MatSetErrorIfFailure is set)", what, (double)PetscRealPart(v));
  PetscFunctionReturn(0);
}

/* Value index of the diagonal entry (i, i); the block row must hold its diagonal block. */
PetscErrorCode DiagonalIndex(Mat A, PetscInt i, const char *op, PetscInt *v)
{
  const Mat_SeqBinBCSR *a  = (const Mat_SeqBinBCSR *)A->data;
  const PetscInt        br = i / a->bs, ii = i % a->bs;
  PetscFunctionBegin;
  PetscCheck(
    a->diag_slot[br] >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
    "%s: row %" PetscInt_FMT
    " has no diagonal entry and the MATSEQBINBCSR pattern is fixed once built; store the diagonal blocks (zeros are fine)",
    op, i);
  *v = BinBCSRValueIndex(a->diag_slot[br], ii * a->bs + ii, a->bw, a->bs2);
  PetscFunctionReturn(0);
}

PetscErrorCode CheckAllDiagonals(Mat A, const char *op)
{
  const PetscInt n = PetscMin(A->rmap->n, A->cmap->n);
  PetscInt       v;
  PetscFunctionBegin;
  for (PetscInt i = 0; i < n; i++) PetscCall(DiagonalIndex(A, i, op, &v));
  PetscFunctionReturn(0);
}

PetscErrorCode CheckRows(Mat A, PetscInt N, const PetscInt rows[], PetscScalar diag, Vec x, Vec b,
                         PetscBool columns_too, const char *op)
{
  PetscInt v;
  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, op));
  PetscCall(CheckFinite(A, diag, "the diagonal value"));
  for (PetscInt i = 0; i < N; i++)
    PetscCheck(rows[i] >= 0 && rows[i] < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "%s: row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", op, rows[i], A->rmap->n);
  if (columns_too)
    PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "%s needs a square matrix", op);
  if (x && b) {
    PetscInt nx, nb;
    PetscCall(VecGetLocalSize(x, &nx));
    PetscCall(VecGetLocalSize(b, &nb));
    PetscCheck(nx == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
               "%s: x has %" PetscInt_FMT " entries, the matrix %" PetscInt_FMT " columns", op, nx,
               A->cmap->n);
    PetscCheck(nb == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
               "%s: b has %" PetscInt_FMT " entries, the matrix %" PetscInt_FMT " rows", op, nb, A->rmap->n);
  }
  if (diag != 0.0)
    for (PetscInt i = 0; i < N; i++)
      if (rows[i] < A->cmap->n) PetscCall(DiagonalIndex(A, rows[i], op, &v));
  PetscFunctionReturn(0);
}

/* Every entry of X has a slot in Y's layout. */
PetscErrorCode PatternContains(Mat Y, Mat X, PetscBool *contains)
{
  const Mat_SeqBinBCSR *y = (const Mat_SeqBinBCSR *)Y->data;
  PetscFunctionBegin;
  *contains = PETSC_TRUE;
  for (PetscInt i = 0; i < Y->rmap->n && *contains; i++) {
    PetscInt        n;
    const PetscInt *cols;
    PetscCall(MatGetRow(X, i, &n, &cols, nullptr));
    for (PetscInt k = 0; k < n; k++)
      if (!(y->sym && cols[k] / y->bs < i / y->bs) &&
          MatSeqBinBCSRFindSlot(y, i / y->bs, cols[k] / y->bs) < 0) {
        *contains = PETSC_FALSE;
        break;
      }
    PetscCall(MatRestoreRow(X, i, &n, &cols, nullptr));
  }
  PetscFunctionReturn(0);
}

/* Y += a X through X's rows; X's entries must have slots in Y (PatternContains). */
PetscErrorCode AddRows(Mat Y, PetscScalar a, Mat X)
{
  Mat_SeqBinBCSR *y  = (Mat_SeqBinBCSR *)Y->data;
  const PetscInt  bs = y->bs;
  PetscFunctionBegin;
  for (PetscInt i = 0; i < Y->rmap->n; i++) {
    PetscInt           n;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(X, i, &n, &cols, &vals));
    for (PetscInt k = 0; k < n; k++) {
      if (y->sym && cols[k] / bs < i / bs) continue; /* symmetric storage: the lower triangle is implied */
      const PetscInt s = MatSeqBinBCSRFindSlot(y, i / bs, cols[k] / bs);
      const PetscInt v = BinBCSRValueIndex(s, (i % bs) * bs + cols[k] % bs, y->bw, y->bs2);
      BinBCSRSetValue(y, v, BinBCSRGetValue(y, v) + a * vals[k]);
    }
    PetscCall(PetscLogFlops(2.0 * n));
    PetscCall(MatRestoreRow(X, i, &n, &cols, &vals));
  }
  PetscFunctionReturn(0);
}

/* Y = Y + a X where X has entries outside Y's layout: a new layout for the union of the patterns
   (same bin width and precision), Y's values copied, a X added, and the new matrix takes Y's place. */
PetscErrorCode AXPYUnion(Mat Y, PetscScalar a, Mat X)
{
  Mat_SeqBinBCSR       *y  = (Mat_SeqBinBCSR *)Y->data;
  const PetscInt        bs = y->bs, mbs = y->mbs;
  std::vector<PetscInt> bi(mbs + 1, 0), bj, row;
  Mat                   B;

  PetscFunctionBegin;
  for (PetscInt r = 0; r < mbs; r++) {
    row.clear();
    for (PetscInt k = 0; k < y->row_nz[r]; k++) row.push_back(y->col[BinBCSRSlot(y, r, k)]);
    PetscCall(MatSeqBinBCSRAddBlockRowPattern(X, r, bs, row));
    bj.insert(bj.end(), row.begin(), row.end());
    bi[r + 1] = (PetscInt)bj.size();
  }
  PetscCall(MatSeqBinBCSRCreateWithPattern(Y, PETSC_FALSE, bi.data(), bj.data(), &B));
  {
    Mat_SeqBinBCSR *b = (Mat_SeqBinBCSR *)B->data;
    for (PetscInt r = 0; r < mbs; r++)
      for (PetscInt k = 0; k < y->row_nz[r]; k++) {
        const PetscInt sy = BinBCSRSlot(y, r, k), sb = MatSeqBinBCSRFindSlot(b, r, y->col[sy]);
        for (PetscInt e = 0; e < y->bs2; e++)
          BinBCSRSetValue(b, BinBCSRValueIndex(sb, e, b->bw, b->bs2),
                          BinBCSRGetValue(y, BinBCSRValueIndex(sy, e, y->bw, y->bs2)));
      }
  }
  PetscCall(AddRows(B, a, X));
  PetscCall(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatPropagateSymmetryOptions(Y, B));
  PetscCall(MatHeaderReplace(Y, &B));
  PetscFunctionReturn(0);
}

} // namespace

PetscBool MatSeqBinBCSRSameLayout(const Mat_SeqBinBCSR *y, const Mat_SeqBinBCSR *x)
{
  if (!y->built || !x->built) return PETSC_FALSE;
  /* nz too, before real_slot ([nz]) is compared: two patterns can have as many slots (the same bin
     widths) and differ in the padding, and real_slot of the smaller would be read past its end */
  if (y->bs != x->bs || y->bw != x->bw || y->mbs != x->mbs || y->nbs != x->nbs || y->nslots != x->nslots ||
      y->nz != x->nz || y->sym != x->sym)
    return PETSC_FALSE;
  if (y->bin_start == x->bin_start && y->col == x->col) return PETSC_TRUE;
  if (y->sym && !std::equal(y->real_slot, y->real_slot + y->nz, x->real_slot)) return PETSC_FALSE;
  return std::equal(y->bin_start, y->bin_start + y->nbins + 1, x->bin_start) &&
             std::equal(y->row_nz, y->row_nz + y->mbs, x->row_nz) &&
             std::equal(y->col, y->col + y->nslots, x->col)
           ? PETSC_TRUE
           : PETSC_FALSE;
}

PetscErrorCode MatZeroEntries_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (!a->built) {
    /* preallocated or partly filled, not assembled yet: the staged pattern stays */
    PetscCall(MatSeqBinBCSRStagingZeroValues(A));
    PetscFunctionReturn(0);
  }
  if (a->val) PetscCall(PetscArrayzero(a->val, (size_t)a->nslots * a->bs2));
  if (a->valf) PetscCall(PetscArrayzero(a->valf, (size_t)a->nslots * a->bs2));
  PetscFunctionReturn(0);
}

PetscErrorCode MatScale_SeqBinBCSR(Mat A, PetscScalar alpha)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "MatScale"));
  PetscCall(CheckFinite(A, alpha, "the scale factor"));
  if (PetscIsInfOrNanScalar(alpha)) {
    /* real slots only: 0 * Inf would put NaN into the padding */
    const int bw = (int)a->bw, bs2 = (int)a->bs2;
    if (a->sym)
      ForEachRealValue(a, [&](PetscInt v, PetscInt, PetscInt, PetscInt, PetscInt) {
        BinBCSRSetValue(a, v, alpha * BinBCSRGetValue(a, v));
      });
    else
      ForEachLane(a, [&](auto *bin_val, const PetscInt *, PetscInt, int lane, int nz) {
        binbcsr::lane_scale(bin_val, nz, bw, bs2, lane, alpha);
      });
  } else if (a->val) binbcsr::values_scale((long)a->nslots * a->bs2, a->val, alpha);
  else binbcsr::values_scale((long)a->nslots * a->bs2, a->valf, alpha);
  PetscCall(PetscLogFlops((PetscLogDouble)a->nz * a->bs2));
  PetscFunctionReturn(0);
}

PetscErrorCode MatShift_SeqBinBCSR(Mat A, PetscScalar alpha)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  n = PetscMin(A->rmap->n, A->cmap->n);
  PetscInt        v;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "MatShift"));
  PetscCall(CheckFinite(A, alpha, "the shift"));
  PetscCall(CheckAllDiagonals(A, "MatShift"));
  for (PetscInt i = 0; i < n; i++) {
    PetscCall(DiagonalIndex(A, i, "MatShift", &v));
    BinBCSRSetValue(a, v, BinBCSRGetValue(a, v) + alpha);
  }
  PetscCall(PetscLogFlops(n));
  PetscFunctionReturn(0);
}

PetscErrorCode MatDiagonalSet_SeqBinBCSR(Mat A, Vec D, InsertMode mode)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscScalar *d;
  PetscInt           v;

  PetscFunctionBegin;
  if (!a->built) {
    /* not assembled yet: the diagonal goes into the staged pattern like any value */
    PetscCall(VecGetArrayRead(D, &d));
    for (PetscInt i = 0; i < A->rmap->n; i++) PetscCall(MatSetValues(A, 1, &i, 1, &i, d + i, mode));
    PetscCall(VecRestoreArrayRead(D, &d));
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    PetscFunctionReturn(0);
  }
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "MatDiagonalSet needs a square matrix");
  PetscCall(CheckAllDiagonals(A, "MatDiagonalSet"));
  PetscCall(VecGetArrayRead(D, &d));
  if (A->erroriffailure) {
    for (PetscInt i = 0; i < A->rmap->n; i++) {
      if (PetscIsInfOrNanScalar(d[i])) {
        PetscCall(VecRestoreArrayRead(D, &d));
        SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FP,
                "Diagonal entry %" PetscInt_FMT " is not finite (MatSetErrorIfFailure is set)", i);
      }
    }
  }
  for (PetscInt i = 0; i < A->rmap->n; i++) {
    PetscCall(DiagonalIndex(A, i, "MatDiagonalSet", &v));
    BinBCSRSetValue(a, v, mode == INSERT_VALUES ? d[i] : BinBCSRGetValue(a, v) + d[i]);
  }
  PetscCall(VecRestoreArrayRead(D, &d));
  PetscFunctionReturn(0);
}

PetscErrorCode MatAXPY_SeqBinBCSR(Mat Y, PetscScalar alpha, Mat X, MatStructure str)
{
  Mat_SeqBinBCSR *y = (Mat_SeqBinBCSR *)Y->data;
  PetscBool       xbin, contains;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(Y, "MatAXPY"));
  PetscCall(CheckFinite(Y, alpha, "the AXPY factor"));
  PetscCall(PetscObjectTypeCompare((PetscObject)X, MATSEQBINBCSR, &xbin));
  if (xbin && MatSeqBinBCSRSameLayout(y, (Mat_SeqBinBCSR *)X->data)) {
    /* the fast path: slot by slot, whatever each side's precision */
    const Mat_SeqBinBCSR *x  = (const Mat_SeqBinBCSR *)X->data;
    const int             bw = (int)y->bw, bs2 = (int)y->bs2;
    const long            n = (long)y->nslots * y->bs2;
    if (!PetscIsInfOrNanScalar(alpha)) {
      /* padding: 0 + alpha 0 = 0, so one contiguous pass over all values */
      if (y->val && x->val) binbcsr::values_axpy(n, y->val, x->val, alpha);
      else if (y->val) binbcsr::values_axpy(n, y->val, x->valf, alpha);
      else if (x->val) binbcsr::values_axpy(n, y->valf, x->val, alpha);
      else binbcsr::values_axpy(n, y->valf, x->valf, alpha);
      PetscCall(PetscLogFlops(2.0 * y->nz * y->bs2));
      PetscFunctionReturn(0);
    }
    if (y->sym) { /* real slots only (the colouring scatters them over the bin) */
      ForEachRealValue(y, [&](PetscInt v, PetscInt, PetscInt, PetscInt, PetscInt) {
        BinBCSRSetValue(y, v, BinBCSRGetValue(y, v) + alpha * BinBCSRGetValue(x, v));
      });
      PetscCall(PetscLogFlops(2.0 * y->nz * y->bs2));
      PetscFunctionReturn(0);
    }
    for (PetscInt b = 0; b < y->nbins; b++) {
      const size_t   off = (size_t)y->bin_start[b] * y->bs2;
      const PetscInt r0 = b * y->bw, r1 = PetscMin(y->mbs, r0 + y->bw);
      for (PetscInt r = r0; r < r1; r++) {
        const int lane = (int)(r - r0), nz = (int)y->row_nz[r];
        if (y->val && x->val) binbcsr::lane_axpy(y->val + off, x->val + off, nz, bw, bs2, lane, alpha);
        else if (y->val) binbcsr::lane_axpy(y->val + off, x->valf + off, nz, bw, bs2, lane, alpha);
        else if (x->val) binbcsr::lane_axpy(y->valf + off, x->val + off, nz, bw, bs2, lane, alpha);
        else binbcsr::lane_axpy(y->valf + off, x->valf + off, nz, bw, bs2, lane, alpha);
      }
    }
    PetscCall(PetscLogFlops(2.0 * y->nz * y->bs2));
    PetscFunctionReturn(0);
  }
  /* X inside Y's layout (SUBSET_NONZERO_PATTERN, or another layout of the same pattern): in place
     through X's rows; otherwise (whatever str claims) a new layout for the union */
  (void)str;
  PetscCall(PatternContains(Y, X, &contains));
  if (contains) PetscCall(AddRows(Y, alpha, X));
  else PetscCall(AXPYUnion(Y, alpha, X));
  PetscFunctionReturn(0);
}

PetscErrorCode MatZeroRows_SeqBinBCSR(Mat A, PetscInt N, const PetscInt rows[], PetscScalar diag, Vec x,
                                      Vec b)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const int       bw = (int)a->bw, bs = (int)a->bs;
  PetscInt        v;

  PetscFunctionBegin;
  BinBCSRCheckNotSym(
    a,
    "MatZeroRows (zeroing rows but not columns would make the matrix non-symmetric; use MatZeroRowsColumns)");
  PetscCall(CheckRows(A, N, rows, diag, x, b, PETSC_FALSE, "MatZeroRows"));
  if (x && b) {
    const PetscScalar *xx;
    PetscScalar       *bb;
    PetscCall(VecGetArrayRead(x, &xx));
    PetscCall(VecGetArray(b, &bb));
    for (PetscInt i = 0; i < N; i++)
      if (rows[i] < A->cmap->n) bb[rows[i]] = diag * xx[rows[i]];
    PetscCall(VecRestoreArrayRead(x, &xx));
    PetscCall(VecRestoreArray(b, &bb));
  }
  for (PetscInt i = 0; i < N; i++) {
    const PetscInt r = rows[i] / bs, bin = r / bw;
    const size_t   off = (size_t)a->bin_start[bin] * a->bs2;
    if (a->val)
      binbcsr::lane_zero_row(a->val + off, (int)a->row_nz[r], bw, bs, (int)(r % bw), (int)(rows[i] % bs));
    else binbcsr::lane_zero_row(a->valf + off, (int)a->row_nz[r], bw, bs, (int)(r % bw), (int)(rows[i] % bs));
  }
  if (diag != 0.0)
    for (PetscInt i = 0; i < N; i++)
      if (rows[i] < A->cmap->n) {
        PetscCall(DiagonalIndex(A, rows[i], "MatZeroRows", &v));
        BinBCSRSetValue(a, v, diag);
      }
  PetscFunctionReturn(0);
}

PetscErrorCode MatZeroRowsColumns_SeqBinBCSR(Mat A, PetscInt N, const PetscInt rows[], PetscScalar diag,
                                             Vec x, Vec b)
{
  Mat_SeqBinBCSR    *a  = (Mat_SeqBinBCSR *)A->data;
  const int          bw = (int)a->bw, bs = (int)a->bs;
  const PetscScalar *xx = nullptr;
  PetscScalar       *bb = nullptr;
  char              *zeroed;
  PetscInt           v;

  PetscFunctionBegin;
  PetscCall(CheckRows(A, N, rows, diag, x, b, PETSC_TRUE, "MatZeroRowsColumns"));
  if (!N) PetscFunctionReturn(0);
  PetscCall(PetscCalloc1(A->rmap->n, &zeroed));
  for (PetscInt i = 0; i < N; i++) zeroed[rows[i]] = 1;
  if (x && b) {
    PetscCall(VecGetArrayRead(x, &xx));
    PetscCall(VecGetArray(b, &bb));
  }
  if (a->sym) {
    /* each stored entry (R, C) of an upper block stands for itself and, off the diagonal block, for
       (C, R): move the known values of both to b, then zero it if its row or column goes */
    ForEachRealValue(a, [&](PetscInt v, PetscInt r, PetscInt c, PetscInt i, PetscInt j) {
      const PetscInt R = r * bs + i, C = c * bs + j;
      if (!zeroed[R] && !zeroed[C]) return;
      const PetscScalar val = BinBCSRGetValue(a, v);
      if (bb) {
        if (!zeroed[R]) bb[R] -= val * xx[C];
        if (c != r && !zeroed[C]) bb[C] -= val * xx[R];
      }
      BinBCSRSetValue(a, v, 0.0);
    });
    for (PetscInt i = 0; i < A->rmap->n; i++) {
      if (!zeroed[i]) continue;
      if (bb) bb[i] = diag * xx[i];
      if (diag != 0.0) {
        PetscCall(DiagonalIndex(A, i, "MatZeroRowsColumns", &v));
        BinBCSRSetValue(a, v, diag);
      }
    }
  } else {
    /* the columns, in the rows that stay (moving the known values to b) */
    ForEachLane(a, [&](auto *bin_val, const PetscInt *bin_col, PetscInt r, int lane, int nz) {
      binbcsr::lane_zero_columns(bin_val, bin_col, nz, bw, bs, lane, zeroed, zeroed + r * bs, xx,
                                 bb ? bb + r * bs : nullptr);
    });
    /* then the rows */
    for (PetscInt i = 0; i < A->rmap->n; i++) {
      if (!zeroed[i]) continue;
      const PetscInt r   = i / bs;
      const size_t   off = (size_t)a->bin_start[r / bw] * a->bs2;
      if (a->val)
        binbcsr::lane_zero_row(a->val + off, (int)a->row_nz[r], bw, bs, (int)(r % bw), (int)(i % bs));
      else binbcsr::lane_zero_row(a->valf + off, (int)a->row_nz[r], bw, bs, (int)(r % bw), (int)(i % bs));
      if (bb) bb[i] = diag * xx[i];
      if (diag != 0.0) {
        PetscCall(DiagonalIndex(A, i, "MatZeroRowsColumns", &v));
        BinBCSRSetValue(a, v, diag);
      }
    }
  }
  if (x && b) {
    PetscCall(VecRestoreArrayRead(x, &xx));
    PetscCall(VecRestoreArray(b, &bb));
  }
  PetscCall(PetscFree(zeroed));
  PetscFunctionReturn(0);
}

/* The 1-norm: the largest column sum of |a_ij| over the full matrix (with symmetric storage also the
   infinity norm). */
static PetscErrorCode MaxColumnSum(Mat A, PetscReal *nrm)
{
  double *col_sum;

  PetscFunctionBegin;
  PetscCall(PetscMalloc1(A->cmap->n, &col_sum));
  PetscCall(MatSeqBinBCSRColumnReductions(A, binbcsr::reduce_abs_sum, col_sum));
  *nrm = 0.0;
  for (PetscInt j = 0; j < A->cmap->n; j++) *nrm = PetscMax(*nrm, col_sum[j]);
  PetscCall(PetscFree(col_sum));
  PetscFunctionReturn(0);
}

PetscErrorCode MatNorm_SeqBinBCSR(Mat A, NormType type, PetscReal *nrm)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const int       bw = (int)a->bw, bs = (int)a->bs, bs2 = (int)a->bs2;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "MatNorm"));
  if (a->sym) {
    /* Frobenius: off-diagonal blocks count twice; 1 = infinity (symmetric): row sums of the full
       matrix, i.e. the stored rows plus the stored off-diagonal blocks' columns */
    if (
      type ==
      NORM_FROBENIUS) { /* twice the contiguous sum over all values (padding is zero), less the diagonal blocks once */
      const long n = (long)a->nslots * a->bs2;
      double     sum =
        2.0 * (a->val ? binbcsr::values_sum_squares(n, a->val) : binbcsr::values_sum_squares(n, a->valf));
      for (PetscInt r = 0; r < a->mbs; r++) {
        if (a->diag_slot[r] < 0) continue;
        for (PetscInt e = 0; e < a->bs2; e++) {
          const double x =
            PetscAbsScalar(BinBCSRGetValue(a, BinBCSRValueIndex(a->diag_slot[r], e, a->bw, a->bs2)));
          sum -= x * x;
        }
      }
      *nrm = PetscSqrtReal(PetscMax(sum, 0.0));
    } else if (type == NORM_1 || type == NORM_INFINITY) {
      PetscCall(MaxColumnSum(A, nrm));
    } else SETERRQ(PETSC_COMM_SELF, PETSC_ERR_SUP, "MATSEQBINBCSR has no %s norm", NormTypes[type]);
    PetscCall(PetscLogFlops(2.0 * a->nz * a->bs2));
    PetscFunctionReturn(0);
  }
  if (type == NORM_FROBENIUS) {
    const long n = (long)a->nslots * a->bs2;
    *nrm         = PetscSqrtReal(a->val ? binbcsr::values_sum_squares(n, a->val)
                                        : binbcsr::values_sum_squares(n, a->valf));
  } else if (type == NORM_1) {
    PetscCall(MaxColumnSum(A, nrm));
  } else if (type == NORM_INFINITY) {
    double *row_sum;
    PetscCall(PetscMalloc1((size_t)bs * bw, &row_sum));
    *nrm = 0.0;
    for (PetscInt b = 0; b < a->nbins; b++) {
      const PetscInt s0 = a->bin_start[b], len = (a->bin_start[b + 1] - s0) / a->bw;
      PetscCall(PetscArrayzero(row_sum, (size_t)bs * bw));
      if (a->val) binbcsr::bin_row_abs_sums(a->val + (size_t)s0 * bs2, (int)len, bw, bs, row_sum);
      else binbcsr::bin_row_abs_sums(a->valf + (size_t)s0 * bs2, (int)len, bw, bs, row_sum);
      for (PetscInt i = 0; i < bs * bw; i++) *nrm = PetscMax(*nrm, row_sum[i]);
    }
    PetscCall(PetscFree(row_sum));
  } else SETERRQ(PETSC_COMM_SELF, PETSC_ERR_SUP, "MATSEQBINBCSR has no %s norm", NormTypes[type]);
  PetscCall(PetscLogFlops(2.0 * a->nz * a->bs2));
  PetscFunctionReturn(0);
}

/* As BAIJ: block_size is bs^2 (values per stored block); allocated counts padding slots. */
PetscErrorCode MatGetInfo_SeqBinBCSR(Mat A, MatInfoType flag, MatInfo *info)
{
  Mat_SeqBinBCSR *a   = (Mat_SeqBinBCSR *)A->data;
  const double    bs2 = (double)PetscMax(a->bs2, 1);

  PetscFunctionBegin;
  (void)flag;
  PetscCall(PetscMemzero(info, sizeof(*info)));
  info->block_size = bs2;
  info->assemblies = A->num_ass;
  info->mallocs    = A->info.mallocs;
  if (a->built) {
    const double value_bytes = a->val ? sizeof(MatScalar) : sizeof(float);
    info->nz_used            = (double)a->nz * bs2;
    info->nz_allocated       = (double)a->nslots * bs2;
    info->nz_unneeded        = info->nz_allocated - info->nz_used;
    info->memory =
      info->nz_allocated * value_bytes +
      (double)(a->nslots + a->nbins + 1 + 2 * a->mbs + (a->sym ? a->nz + a->mbs + 1 : 0)) * sizeof(PetscInt) +
      (a->coo_jmap ? (double)(a->nslots * bs2 + 1 + a->coo_n) * sizeof(PetscInt) : 0.0);
  }
  PetscFunctionReturn(0);
}
