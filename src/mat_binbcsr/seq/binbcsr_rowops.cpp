/*
   MATSEQBINBCSR operations over whole rows and columns: diagonal scaling, row extremes
   (MatGetRowMaxAbs, MatGetRowMax, MatGetRowMin, MatGetRowMinAbs), column reductions (MatGetColumnNorms and the other
   MatGetColumnReductions, also the 1-norm), the missing-diagonal check and equality.

   Symmetric storage keeps only the blocks (r, c) with c >= r; these operations see the full matrix:
   a row is the transposed blocks (c, r), c < r, then the stored ones (ascending columns, as MatGetRow
   gives it), and a stored off-diagonal block reduces into its columns and, transposed, into its row's.
   Scaling keeps the storage symmetric only as D A D, so a different left and right scaling is refused.
*/
#include "binbcsr.h"
#include "binbcsr_ops.h"
#include "../kernels/binbcsr_value_kernels.h"

#include <algorithm>
#include <vector>

namespace {

/* f(values) with the storage's value array, typed (double or float) */
template <typename F> void WithValues(const Mat_SeqBinBCSR *a, F &&f)
{
  if (a->val) f(a->val);
  else f(a->valf);
}

/* f(slot, block column, transposed) for the blocks of block row r's full row in ascending column
   order. Symmetric storage: the lower index must exist (MatSeqBinBCSRBuildLowerIndex). */
template <typename F> void ForEachRowBlock(const Mat_SeqBinBCSR *a, PetscInt r, F &&f)
{
  if (a->sym)
    for (PetscInt p = a->lower_off[r]; p < a->lower_off[r + 1]; p++)
      f(a->lower_slot[2 * p], a->lower_slot[2 * p + 1], true);
  for (PetscInt k = 0; k < a->row_nz[r]; k++) {
    const PetscInt s = BinBCSRSlot(a, r, k);
    f(s, a->col[s], false);
  }
}

PetscErrorCode CheckBuilt(Mat A, const char *op)
{
  PetscFunctionBegin;
  PetscCheck(((Mat_SeqBinBCSR *)A->data)->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "%s needs an assembled MATSEQBINBCSR matrix", op);
  PetscFunctionReturn(0);
}

/* The same scaling on both sides: the same vector, or equal entries (the MPI type passes two views of
   one vector). */
PetscErrorCode SameScaling(Vec l, Vec r, PetscBool *same)
{
  const PetscScalar *la, *ra;
  PetscInt           n;
  PetscFunctionBegin;
  *same = l == r ? PETSC_TRUE : PETSC_FALSE;
  if (*same || !l || !r) PetscFunctionReturn(0);
  PetscCall(VecGetLocalSize(l, &n));
  PetscCall(VecGetArrayRead(l, &la));
  PetscCall(VecGetArrayRead(r, &ra));
  *same = PETSC_TRUE;
  for (PetscInt i = 0; i < n && *same; i++)
    if (la[i] != ra[i]) *same = PETSC_FALSE;
  PetscCall(VecRestoreArrayRead(l, &la));
  PetscCall(VecRestoreArrayRead(r, &ra));
  PetscFunctionReturn(0);
}

/* v[i] (and idx[i]) = the extreme of the kind over row i, PETSc's AIJ rules (binbcsr::row_extreme_start) */
PetscErrorCode RowExtremes(Mat A, Vec v, PetscInt idx[], int kind, const char *op)
{
  Mat_SeqBinBCSR       *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt        bs = a->bs;
  PetscScalar          *x;
  std::vector<double>   best(bs);
  std::vector<PetscInt> at(bs);

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, op));
  PetscCheck(!A->factortype, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Not for factored matrix");
  PetscCall(MatBinBCSRCheckVecLocalSize(v, A->rmap->n, "The row vector"));
  if (!A->cmap->n) PetscFunctionReturn(0); /* MatGetRowMax/Min/MaxAbs have set v and idx */
  PetscCall(VecGetArrayWrite(v, &x));
  if (kind == binbcsr::extreme_max_abs) { /* whole bins at a time, straight into v (and idx) */
    std::vector<PetscInt> scratch(idx ? 0 : A->rmap->n);
    PetscInt             *col = idx ? idx : scratch.data();
    std::fill(x, x + A->rmap->n, 0.0);
    std::fill(col, col + A->rmap->n, 0);
    for (PetscInt b = 0; b < a->nbins; b++) {
      const PetscInt s0 = a->bin_start[b], len = (a->bin_start[b + 1] - s0) / a->bw;
      WithValues(a, [&](const auto *val) {
        if (a->sym)
          binbcsr::bin_row_max_abs<true>(val + (size_t)s0 * a->bs2, a->col + s0, (int)len, (int)a->bw,
                                         (int)bs, b * a->bw, a->mbs, x, col);
        else
          binbcsr::bin_row_max_abs<false>(val + (size_t)s0 * a->bs2, a->col + s0, (int)len, (int)a->bw,
                                          (int)bs, b * a->bw, a->mbs, x, col);
      });
    }
    PetscCall(VecRestoreArrayWrite(v, &x));
    PetscFunctionReturn(0);
  }
  if (a->sym) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  for (PetscInt r = 0; r < a->mbs; r++) {
    PetscInt nb = 0, gap = -1; /* blocks of the full row, first block column it does not hold */
    ForEachRowBlock(a, r, [&](PetscInt, PetscInt c, bool) {
      if (gap < 0 && c != nb) gap = nb;
      nb++;
    });
    if (gap < 0) gap = nb;
    for (PetscInt i = 0; i < bs; i++)
      binbcsr::row_extreme_start(kind, nb * bs == A->cmap->n, gap * bs, &best[i], &at[i]);
    WithValues(a, [&](const auto *val) {
      ForEachRowBlock(a, r, [&](PetscInt s, PetscInt c, bool transposed) {
        binbcsr::slot_row_extremes(val + BinBCSRValueIndex(s, 0, a->bw, a->bs2), (int)a->bw, (int)bs,
                                   transposed, c * bs, kind, best.data(), at.data());
      });
    });
    for (PetscInt i = 0; i < bs; i++) {
      x[r * bs + i] = best[i];
      if (idx) idx[r * bs + i] = at[i];
    }
  }
  PetscCall(VecRestoreArrayWrite(v, &x));
  PetscFunctionReturn(0);
}

} // namespace

namespace {
template <int KIND, bool MIRROR> void ColumnReductionsOf(const Mat_SeqBinBCSR *a, double *red)
{
  for (PetscInt b = 0; b < a->nbins; b++) {
    const PetscInt s0 = a->bin_start[b], len = (a->bin_start[b + 1] - s0) / a->bw;
    WithValues(a, [&](const auto *val) {
      binbcsr::bin_col_reductions<KIND, MIRROR>(val + (size_t)s0 * a->bs2, a->col + s0, (int)len, (int)a->bw,
                                                (int)a->bs, b * a->bw, a->mbs, red);
    });
  }
}
template <int KIND> void ColumnReductionsOf(const Mat_SeqBinBCSR *a, double *red)
{
  if (a->sym) ColumnReductionsOf<KIND, true>(a, red);
  else ColumnReductionsOf<KIND, false>(a, red);
}
} // namespace

PetscErrorCode MatSeqBinBCSRColumnReductions(Mat A, int kind, double *red)
{
  const Mat_SeqBinBCSR *a = (const Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "A column reduction"));
  PetscCall(PetscArrayzero(red, A->cmap->n));
  switch (kind) {
  case binbcsr::reduce_abs_sum:
    ColumnReductionsOf<binbcsr::reduce_abs_sum>(a, red);
    break;
  case binbcsr::reduce_square_sum:
    ColumnReductionsOf<binbcsr::reduce_square_sum>(a, red);
    break;
  case binbcsr::reduce_abs_max:
    ColumnReductionsOf<binbcsr::reduce_abs_max>(a, red);
    break;
  default:
    ColumnReductionsOf<binbcsr::reduce_sum>(a, red);
  }
  PetscCall(PetscLogFlops((a->sym ? 2.0 : 1.0) * a->nz * a->bs2));
  PetscFunctionReturn(0);
}

PetscErrorCode MatGetColumnReductions_SeqBinBCSR(Mat A, PetscInt type, PetscReal *reductions)
{
  const PetscInt n = A->cmap->n;

  PetscFunctionBegin;
  if (type == REDUCTION_SUM_IMAGINARYPART || type == REDUCTION_MEAN_IMAGINARYPART) { /* real values */
    PetscCall(CheckBuilt(A, "MatGetColumnReductions"));
    PetscCall(PetscArrayzero(reductions, n));
    PetscFunctionReturn(0);
  }
  int kind;
  if (type == NORM_1) kind = binbcsr::reduce_abs_sum;
  else if (type == NORM_2) kind = binbcsr::reduce_square_sum;
  else if (type == NORM_INFINITY) kind = binbcsr::reduce_abs_max;
  else if (type == REDUCTION_SUM_REALPART || type == REDUCTION_MEAN_REALPART) kind = binbcsr::reduce_sum;
  else SETERRQ(PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Unknown reduction type %" PetscInt_FMT, type);
  PetscCall(MatSeqBinBCSRColumnReductions(A, kind, reductions));
  if (type == NORM_2)
    for (PetscInt j = 0; j < n; j++) reductions[j] = PetscSqrtReal(reductions[j]);
  if (type == REDUCTION_MEAN_REALPART)
    for (PetscInt j = 0; j < n; j++) reductions[j] /= A->rmap->n;
  PetscFunctionReturn(0);
}

PetscErrorCode MatDiagonalScale_SeqBinBCSR(Mat A, Vec ll, Vec rr)
{
  Mat_SeqBinBCSR    *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt     bs = a->bs;
  const PetscScalar *l = nullptr, *r = nullptr;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "MatDiagonalScale"));
  if (ll) PetscCall(MatBinBCSRCheckVecLocalSize(ll, A->rmap->n, "The left scaling vector"));
  if (rr) PetscCall(MatBinBCSRCheckVecLocalSize(rr, A->cmap->n, "The right scaling vector"));
  if (a->sym) {
    PetscBool same;
    PetscCall(SameScaling(ll, rr, &same));
    PetscCheck(
      same, PETSC_COMM_SELF, PETSC_ERR_SUP,
      "MatDiagonalScale with symmetric storage (-mat_binbcsr_symmetric_storage) needs the same left and right scaling: D A D stays symmetric, L A R does not; use full storage for that");
  }
  if (ll) PetscCall(VecGetArrayRead(ll, &l));
  if (rr) PetscCall(VecGetArrayRead(rr, &r));
  WithValues(a, [&](auto *val) {
    if (a->sym) { /* the real slots are scattered over the bin by the colouring */
      for (PetscInt row = 0; row < a->mbs; row++)
        for (PetscInt k = 0; k < a->row_nz[row]; k++) {
          const PetscInt s = BinBCSRSlot(a, row, k);
          binbcsr::slot_diagonal_scale(val + BinBCSRValueIndex(s, 0, a->bw, a->bs2), (int)a->bw, (int)bs,
                                       l ? l + row * bs : nullptr, r ? r + a->col[s] * bs : nullptr);
        }
      return;
    }
    for (PetscInt b = 0; b < a->nbins; b++) {
      const PetscInt r0 = b * a->bw, r1 = PetscMin(a->mbs, r0 + a->bw);
      for (PetscInt row = r0; row < r1; row++)
        binbcsr::lane_diagonal_scale(val + (size_t)a->bin_start[b] * a->bs2, a->col + a->bin_start[b],
                                     (int)a->row_nz[row], (int)a->bw, (int)bs, (int)(row - r0),
                                     l ? l + row * bs : nullptr, r);
    }
  });
  if (ll) PetscCall(VecRestoreArrayRead(ll, &l));
  if (rr) PetscCall(VecRestoreArrayRead(rr, &r));
  PetscCall(PetscLogFlops((ll && rr ? 2.0 : 1.0) * a->nz * a->bs2));
  PetscFunctionReturn(0);
}

/* MatGetRowMaxAbs, MatGetRowMax, MatGetRowMin, MatGetRowMinAbs: kind (binbcsr::row_extreme_kind) a
   template argument, so that each is an ops-table slot of its own with one body. */
template <int kind> PetscErrorCode MatGetRowExtreme_SeqBinBCSR(Mat A, Vec v, PetscInt idx[])
{
  static const char *const op[] = {"MatGetRowMaxAbs", "MatGetRowMax", "MatGetRowMin", "MatGetRowMinAbs"};

  PetscFunctionBegin;
  PetscCall(RowExtremes(A, v, idx, kind, op[kind]));
  PetscFunctionReturn(0);
}
template PetscErrorCode MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_max_abs>(Mat, Vec, PetscInt[]);
template PetscErrorCode MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_max>(Mat, Vec, PetscInt[]);
template PetscErrorCode MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_min>(Mat, Vec, PetscInt[]);
template PetscErrorCode MatGetRowExtreme_SeqBinBCSR<binbcsr::extreme_min_abs>(Mat, Vec, PetscInt[]);

/* As AIJ, *d is the first point row whose diagonal entry has no place in the pattern (BAIJ gives the
   block row); it is left alone when nothing is missing. */
PetscErrorCode MatMissingDiagonal_SeqBinBCSR(Mat A, PetscBool *missing, PetscInt *d)
{
  const Mat_SeqBinBCSR *a = (const Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "MatMissingDiagonal"));
  *missing = PETSC_FALSE;
  for (PetscInt r = 0; r < PetscMin(a->mbs, a->nbs); r++)
    if (a->diag_slot[r] < 0) {
      *missing = PETSC_TRUE;
      if (d) *d = r * a->bs;
      PetscCall(PetscInfo(A, "Matrix is missing diagonal block %" PetscInt_FMT "\n", r));
      break;
    }
  PetscFunctionReturn(0);
}

/* Equal entries in the same pattern (as AIJ and BAIJ: a stored zero is not an absent entry). Two
   matrices of one layout compare slot by slot, whatever their precisions; others row by row. */
PetscErrorCode MatEqual_SeqBinBCSR(Mat A, Mat B, PetscBool *flg)
{
  const Mat_SeqBinBCSR *a = (const Mat_SeqBinBCSR *)A->data, *b = (const Mat_SeqBinBCSR *)B->data;

  PetscFunctionBegin;
  PetscCall(CheckBuilt(A, "MatEqual"));
  PetscCall(CheckBuilt(B, "MatEqual"));
  *flg = PETSC_FALSE;
  if (A->rmap->n != B->rmap->n || A->cmap->n != B->cmap->n) PetscFunctionReturn(0);
  if (MatSeqBinBCSRSameLayout(a, b)) {
    const size_t n = (size_t)a->nslots * a->bs2; /* padding is zero on both sides */
    *flg           = PETSC_TRUE;
    WithValues(a, [&](const auto *av) {
      WithValues(b, [&](const auto *bv) {
        for (size_t i = 0; i < n && *flg; i++)
          if ((double)av[i] != (double)bv[i]) *flg = PETSC_FALSE;
      });
    });
    PetscFunctionReturn(0);
  }
  for (PetscInt i = 0; i < A->rmap->n; i++) {
    PetscInt           na, nb;
    const PetscInt    *ca, *cb;
    const PetscScalar *va, *vb;
    PetscBool          same;
    PetscCall(MatGetRow(A, i, &na, &ca, &va));
    PetscCall(MatGetRow(B, i, &nb, &cb, &vb));
    same = na == nb ? PETSC_TRUE : PETSC_FALSE;
    for (PetscInt k = 0; k < na && same; k++)
      if (ca[k] != cb[k] || va[k] != vb[k]) same = PETSC_FALSE;
    PetscCall(MatRestoreRow(B, i, &nb, &cb, &vb));
    PetscCall(MatRestoreRow(A, i, &na, &ca, &va));
    if (!same) PetscFunctionReturn(0);
  }
  *flg = PETSC_TRUE;
  PetscFunctionReturn(0);
}
