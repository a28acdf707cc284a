/* MATSEQBINBCSR rows, copies, conversions and ASCII views. */
#include "binbcsr.h"
#include "binbcsr_ops.h"
#include "../kernels/binbcsr_kernels.h"
#include <petscviewer.h>
#include <algorithm>
#include <vector>

PetscErrorCode MatGetRow_SeqBinBCSR(Mat A, PetscInt row, PetscInt *nz, PetscInt **idx, PetscScalar **v)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatGetRow needs an assembled MATSEQBINBCSR matrix");
  PetscCheck(row >= 0 && row < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", row, A->rmap->n);
  PetscCheck(!a->getrowactive, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatRestoreRow the previous row first");
  const PetscInt bs = a->bs, br = row / bs, ri = row % bs;
  PetscInt       n = 0;
  if (a->sym) { /* the full row: the transposed blocks (c, br), c < br, then the stored ones */
    PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
    for (PetscInt p = a->lower_off[br]; p < a->lower_off[br + 1]; p++, n++) {
      const PetscInt s = a->lower_slot[2 * p], c = a->lower_slot[2 * p + 1];
      for (PetscInt j = 0; j < bs; j++) {
        a->rowbuf_cols[n * bs + j] = c * bs + j;
        a->rowbuf_vals[n * bs + j] = BinBCSRGetValue(a, BinBCSRValueIndex(s, j * bs + ri, a->bw, a->bs2));
      }
    }
  }
  for (PetscInt k = 0; k < a->row_nz[br]; k++, n++) {
    const PetscInt s = BinBCSRSlot(a, br, k);
    for (PetscInt j = 0; j < bs; j++) {
      a->rowbuf_cols[n * bs + j] = a->col[s] * bs + j;
      a->rowbuf_vals[n * bs + j] = BinBCSRGetValue(a, BinBCSRValueIndex(s, ri * bs + j, a->bw, a->bs2));
    }
  }
  if (nz) *nz = n * bs;
  if (idx) *idx = n ? a->rowbuf_cols : nullptr;
  if (v) *v = n ? a->rowbuf_vals : nullptr;
  a->getrowactive = PETSC_TRUE;
  PetscFunctionReturn(0);
}

PetscErrorCode MatRestoreRow_SeqBinBCSR(Mat A, PetscInt row, PetscInt *nz, PetscInt **idx, PetscScalar **v)
{
  PetscFunctionBegin;
  (void)row;
  (void)nz;
  ((Mat_SeqBinBCSR *)A->data)->getrowactive = PETSC_FALSE;
  if (idx) *idx = nullptr;
  if (v) *v = nullptr;
  PetscFunctionReturn(0);
}

/* An empty matrix of the given type with A's sizes and block sizes (a conversion's target). */
PetscErrorCode MatBinBCSRCreateLike_Private(Mat A, MatType type, Mat *B)
{
  PetscFunctionBegin;
  PetscCall(MatCreate(PetscObjectComm((PetscObject)A), B));
  PetscCall(MatSetSizes(*B, A->rmap->n, A->cmap->n, A->rmap->N, A->cmap->N));
  PetscCall(MatSetBlockSizesFromMats(*B, A, A));
  PetscCall(MatSetType(*B, type));
  PetscFunctionReturn(0);
}

/* B gets A's layout (and values if copyvalues), in A's precision. B is a fresh MATSEQBINBCSR. */
static PetscErrorCode MatSeqBinBCSRCopyLayout(Mat A, Mat B, PetscBool copyvalues)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data, *b = (Mat_SeqBinBCSR *)B->data;
  const size_t    nv = (size_t)a->nslots * a->bs2;

  PetscFunctionBegin;
  b->bw           = a->bw;
  b->bw_set       = a->bw_set;
  b->precision    = a->precision;
  b->nonew        = a->nonew;
  b->roworiented  = a->roworiented;
  b->streams      = a->streams;
  b->streams_set  = a->streams_set;
  b->prefetch     = a->prefetch;
  b->prefetch_set = a->prefetch_set;
  b->xload        = a->xload;
  b->xload_set    = a->xload_set;
  b->kernel       = a->kernel;
  b->kernel_tuned = a->kernel_tuned;
  b->tune         = a->tune;
  b->tune_cache   = a->tune_cache;
  PetscCall(PetscStrncpy(b->tune_info, a->tune_info, sizeof(b->tune_info)));
  b->sym = a->sym;
  b->bs  = a->bs;
  b->bs2 = a->bs2;
  b->mbs = a->mbs;
  b->nbs = a->nbs;
  if (a->built) {
    b->nbins      = a->nbins;
    b->nslots     = a->nslots;
    b->nz         = a->nz;
    b->max_row_nz = a->max_row_nz;
    PetscCall(PetscMalloc1(a->nbins + 1, &b->bin_start));
    PetscCall(PetscArraycpy(b->bin_start, a->bin_start, a->nbins + 1));
    PetscCall(PetscMalloc1(a->mbs, &b->row_nz));
    PetscCall(PetscArraycpy(b->row_nz, a->row_nz, a->mbs));
    PetscCall(PetscMalloc1(a->mbs, &b->diag_slot));
    PetscCall(PetscArraycpy(b->diag_slot, a->diag_slot, a->mbs));
    PetscCall(PetscMalloc1(a->nslots, &b->col));
    PetscCall(PetscArraycpy(b->col, a->col, a->nslots));
    PetscCall(MatSeqBinBCSRAllocValues_Private(
      b, a->val ? MAT_BINBCSR_PRECISION_DOUBLE : MAT_BINBCSR_PRECISION_SINGLE, nv,
      copyvalues ? PETSC_FALSE : PETSC_TRUE));
    if (copyvalues && a->val) PetscCall(PetscArraycpy(b->val, a->val, nv));
    else if (copyvalues) PetscCall(PetscArraycpy(b->valf, a->valf, nv));
    if (a->sym) {
      PetscCall(PetscMalloc1(a->mbs + 1, &b->row_off));
      PetscCall(PetscArraycpy(b->row_off, a->row_off, a->mbs + 1));
      PetscCall(PetscMalloc1(a->nz, &b->real_slot));
      PetscCall(PetscArraycpy(b->real_slot, a->real_slot, a->nz));
    }
    {
      const size_t nrow = (size_t)(a->sym ? PetscMax(a->nbs, 1) : a->max_row_nz) * a->bs;
      PetscCall(PetscMalloc2(nrow, &b->rowbuf_cols, nrow, &b->rowbuf_vals));
    }
    if (a->coo_jmap) { /* the copy can be refilled with MatSetValuesCOO too: the same maps, shared */
      if (!a->coo_shared) a->coo_shared = new BinBCSRSharedCOO{1};
      a->coo_shared->refs++;
      b->coo_shared = a->coo_shared;
      b->coo_n      = a->coo_n;
      b->coo_jmap   = a->coo_jmap;
      b->coo_perm   = a->coo_perm;
    }
    b->built = PETSC_TRUE;
  } else PetscCall(MatSeqBinBCSRDuplicateStaging(A, B, copyvalues));
  PetscFunctionReturn(0);
}

PetscErrorCode MatDuplicate_SeqBinBCSR(Mat A, MatDuplicateOption op, Mat *M)
{
  Mat B;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRCreateLike_Private(A, ((PetscObject)A)->type_name, &B));
  PetscCall(PetscLayoutSetUp(B->rmap));
  PetscCall(PetscLayoutSetUp(B->cmap));
  PetscCall(MatSeqBinBCSRCopyLayout(A, B, op == MAT_COPY_VALUES ? PETSC_TRUE : PETSC_FALSE));
  B->preallocated = PETSC_TRUE;
  B->assembled    = A->assembled;
  B->nonzerostate = A->nonzerostate;
  *M              = B;
  PetscFunctionReturn(0);
}

/* Same pattern: copy values (converting precision); otherwise row by row through MatSetValues. */
PetscErrorCode MatCopy_SeqBinBCSR(Mat A, Mat B, MatStructure str)
{
  Mat_SeqBinBCSR *a    = (Mat_SeqBinBCSR *)A->data;
  PetscBool       same = PETSC_FALSE, isbin;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatCopy needs an assembled MATSEQBINBCSR matrix");
  PetscCall(PetscObjectTypeCompare((PetscObject)B, MATSEQBINBCSR, &isbin));
  if (isbin) {
    Mat_SeqBinBCSR *b = (Mat_SeqBinBCSR *)B->data;
    PetscCheck(b->bs == a->bs || !b->built, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
               "Block sizes differ: %" PetscInt_FMT " and %" PetscInt_FMT, a->bs, b->bs);
    if (b->built && b->bw == a->bw && b->mbs == a->mbs && b->nbs == a->nbs && b->nslots == a->nslots &&
        b->sym == a->sym) {
      same = (PetscBool)(str == SAME_NONZERO_PATTERN);
      if (!same) {
        PetscCall(PetscArraycmp(a->bin_start, b->bin_start, a->nbins + 1, &same));
        if (same) PetscCall(PetscArraycmp(a->row_nz, b->row_nz, a->mbs, &same));
        if (same) PetscCall(PetscArraycmp(a->col, b->col, a->nslots, &same));
        if (same && a->sym) PetscCall(PetscArraycmp(a->real_slot, b->real_slot, a->nz, &same));
      }
    }
    if (same) {
      const size_t nv = (size_t)a->nslots * a->bs2;
      if (a->val && b->val) PetscCall(PetscArraycpy(b->val, a->val, nv));
      else if (a->valf && b->valf) PetscCall(PetscArraycpy(b->valf, a->valf, nv));
      else if (a->val)
        for (size_t i = 0; i < nv; i++) b->valf[i] = (float)a->val[i];
      else
        for (size_t i = 0; i < nv; i++) b->val[i] = (MatScalar)a->valf[i];
      PetscCall(PetscObjectStateIncrease((PetscObject)B));
      PetscFunctionReturn(0);
    }
  }
  /* different pattern or type: B's own pattern rules apply (a frozen BinBCSR pattern must hold A's) */
  if (isbin && ((Mat_SeqBinBCSR *)B->data)->built) {
    Mat_SeqBinBCSR *b = (Mat_SeqBinBCSR *)B->data;
    if (b->val) PetscCall(PetscArrayzero(b->val, (size_t)b->nslots * b->bs2));
    else PetscCall(PetscArrayzero(b->valf, (size_t)b->nslots * b->bs2));
  } else if (!isbin && B->assembled) PetscCall(MatZeroEntries(B));
  PetscCall(MatBinBCSRInsertRows_Private(A, B));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRAddBlockRowPattern(Mat X, PetscInt br, PetscInt bs, std::vector<PetscInt> &bcols)
{
  PetscFunctionBegin;
  for (PetscInt r = br * bs; r < (br + 1) * bs; r++) {
    PetscInt        n;
    const PetscInt *cols;
    PetscCall(MatGetRow(X, r, &n, &cols, nullptr));
    for (PetscInt k = 0; k < n; k++) bcols.push_back(cols[k] / bs);
    PetscCall(MatRestoreRow(X, r, &n, &cols, nullptr));
  }
  std::sort(bcols.begin(), bcols.end());
  bcols.erase(std::unique(bcols.begin(), bcols.end()), bcols.end());
  PetscFunctionReturn(0);
}

/* Any matrix with MatGetRow -> MATSEQBINBCSR, with the source's block size (1 if its row and column
   block sizes differ or do not divide the sizes). */
PetscErrorCode MatConvertFrom_SeqBinBCSR(Mat A, MatType type, MatReuse reuse, Mat *newmat)
{
  Mat                   B;
  PetscInt              bs = A->rmap->bs, m = A->rmap->n, mbs, *bi, *bj;
  std::vector<PetscInt> rowcols;
  PetscBool             is_sbaij;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQSBAIJ, &is_sbaij));
  if (!A->ops->getrow || is_sbaij) {
    /* a source without rows (MATTRANSPOSEVIRTUAL, ...) or with upper rows only (seqsbaij): through
       its own conversion to seqaij */
    Mat T, C = reuse == MAT_REUSE_MATRIX ? *newmat : nullptr;
    PetscCall(MatConvert(A, MATSEQAIJ, MAT_INITIAL_MATRIX, &T));
    PetscCall(MatConvertFrom_SeqBinBCSR(
      T, type, reuse == MAT_REUSE_MATRIX ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, &C));
    PetscCall(MatDestroy(&T));
    if (reuse == MAT_INPLACE_MATRIX) PetscCall(MatHeaderReplace(A, &C));
    else *newmat = C;
    PetscFunctionReturn(0);
  }
  if (bs < 1 || bs != A->cmap->bs || m % bs || A->cmap->n % bs) bs = 1;
  mbs = m / bs;
  if (reuse == MAT_REUSE_MATRIX) {
    B = *newmat;
    PetscCheck(B->rmap->bs == bs || bs == 1, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
               "Block size of the reused matrix %" PetscInt_FMT " differs from %" PetscInt_FMT, B->rmap->bs,
               bs);
  } else {
    PetscCall(MatCreate(PetscObjectComm((PetscObject)A), &B));
    PetscCall(MatSetSizes(B, A->rmap->n, A->cmap->n, A->rmap->N, A->cmap->N));
    PetscCall(MatSetBlockSize(B, bs));
    PetscCall(MatSetType(B, type));
    PetscCall(MatBinBCSRSetFromOptions(B)); /* the -mat_binbcsr_* options apply to converted matrices too */
  }
  bs  = PetscAbs(B->rmap->bs);
  mbs = m / bs;
  /* block pattern: the union of the block columns of each block row's point rows */
  PetscCall(PetscMalloc1(mbs + 1, &bi));
  bi[0] = 0;
  std::vector<PetscInt> all;
  for (PetscInt br = 0; br < mbs; br++) {
    rowcols.clear();
    PetscCall(MatSeqBinBCSRAddBlockRowPattern(A, br, bs, rowcols));
    all.insert(all.end(), rowcols.begin(), rowcols.end());
    bi[br + 1] = (PetscInt)all.size();
  }
  PetscCall(PetscMalloc1(all.size(), &bj));
  std::copy(all.begin(), all.end(), bj);
  PetscCall(MatSeqBinBCSRBuildLayout(B, bi, bj));
  {
    Mat_SeqBinBCSR *b = (Mat_SeqBinBCSR *)B->data;
    for (PetscInt r = 0; r < m; r++) {
      PetscInt           n, br = r / bs, k = 0;
      const PetscInt    *cols;
      const PetscScalar *vals;
      PetscCall(MatGetRow(A, r, &n, &cols, &vals));
      for (PetscInt p = 0; p < n; p++) { /* both sorted: walk the block row */
        const PetscInt bc = cols[p] / bs;
        if (b->sym) { /* upper triangle only, slots where the colouring put them */
          if (bc >= br)
            BinBCSRSetValue(b,
                            BinBCSRValueIndex(MatSeqBinBCSRFindSlot(b, br, bc), (r % bs) * bs + cols[p] % bs,
                                              b->bw, b->bs2),
                            vals[p]);
          continue;
        }
        while (bj[bi[br] + k] != bc) k++;
        BinBCSRSetValue(
          b, BinBCSRValueIndex(BinBCSRSlot(b, br, k), (r % bs) * bs + cols[p] % bs, b->bw, b->bs2), vals[p]);
      }
      PetscCall(MatRestoreRow(A, r, &n, &cols, &vals));
    }
  }
  PetscCall(PetscFree(bi));
  PetscCall(PetscFree(bj));
  PetscCall(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY));
  if (reuse == MAT_INPLACE_MATRIX) PetscCall(MatHeaderReplace(A, &B));
  else *newmat = B;
  PetscFunctionReturn(0);
}

/* v <- the values of A's full rows in the order of B's value array (seqbaij: blocks column-major). */
template <typename V>
static void FullRowValues(const Mat_SeqBinBCSR *a, const V *val, PetscBool blocked, PetscScalar *v)
{
  const PetscInt bs = a->bs, bw = a->bw;
  size_t         n = 0;
  /* entry (i, j) of the block at vb: (i, j) of a stored block, (j, i) of a transposed one */
  const auto entry = [&](PetscInt vb, bool t, PetscInt i, PetscInt j) {
    return (PetscScalar)val[FullRowEntry(vb, t, i, j, bs, bw)];
  };
  for (PetscInt br = 0; br < a->mbs; br++) {
    if (blocked)
      ForEachFullRowBlock(a, br, [&](PetscInt, PetscInt vb, bool t) {
        for (PetscInt j = 0; j < bs; j++)
          for (PetscInt i = 0; i < bs; i++) v[n++] = entry(vb, t, i, j);
      });
    else
      for (PetscInt i = 0; i < bs; i++)
        ForEachFullRowBlock(a, br, [&](PetscInt, PetscInt vb, bool t) {
          for (PetscInt j = 0; j < bs; j++) v[n++] = entry(vb, t, i, j);
        });
  }
}

/* MATSEQBINBCSR -> a new seqaij (bs 1 rows) or seqbaij (bs x bs blocks). The rows come out sorted and
   the pattern is known, so B is preallocated exactly, handed all its column indices at once
   (MatSeq[B]AIJSetColumnIndices) and its value array filled in place: inserting the rows through
   MatSetValues searched every entry's place (PCGAMG's graph of the 40K-unknown FE matrix starts from
   this conversion). */
static PetscErrorCode MatConvert_SeqBinBCSR_XAIJ_New(Mat A, MatType newtype, PetscBool blocked, Mat *newmat)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bs = a->bs, bs2 = a->bs2, mbs = a->mbs;
  Mat             B;
  PetscInt       *nnz, *idx;
  PetscScalar    *v;
  size_t          nblocks = 0, n = 0;

  PetscFunctionBegin;
  if (a->sym) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  PetscCall(MatBinBCSRCreateLike_Private(A, newtype, &B));
  PetscCall(PetscMalloc1(blocked ? mbs : A->rmap->n, &nnz));
  for (PetscInt br = 0; br < mbs; br++) {
    const PetscInt nb = a->row_nz[br] + (a->sym ? a->lower_off[br + 1] - a->lower_off[br] : 0);
    nblocks += (size_t)nb;
    if (blocked) nnz[br] = nb;
    else
      for (PetscInt i = 0; i < bs; i++) nnz[br * bs + i] = nb * bs;
  }
  PetscCheck(nblocks * bs2 <= (size_t)PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_SUP,
             "MatConvert: %zu entries exceed PETSc's index range", nblocks * bs2);
  if (blocked) PetscCall(MatSeqBAIJSetPreallocation(B, bs, 0, nnz));
  else PetscCall(MatSeqAIJSetPreallocation(B, 0, nnz));
  PetscCall(PetscFree(nnz));
  PetscCall(PetscMalloc1(blocked ? nblocks : nblocks * bs2, &idx));
  for (PetscInt br = 0; br < mbs; br++) {
    if (blocked) ForEachFullRowBlock(a, br, [&](PetscInt bc, PetscInt, bool) { idx[n++] = bc; });
    else
      for (PetscInt i = 0; i < bs; i++)
        ForEachFullRowBlock(a, br, [&](PetscInt bc, PetscInt, bool) {
          for (PetscInt j = 0; j < bs; j++) idx[n++] = bc * bs + j;
        });
  }
  if (blocked) PetscCall(MatSeqBAIJSetColumnIndices(B, idx));
  else PetscCall(MatSeqAIJSetColumnIndices(B, idx));
  PetscCall(PetscFree(idx));
  if (blocked) PetscCall(MatSeqBAIJGetArray(B, &v));
  else PetscCall(MatSeqAIJGetArray(B, &v));
  if (a->val) FullRowValues(a, a->val, blocked, v);
  else FullRowValues(a, a->valf, blocked, v);
  if (blocked) PetscCall(MatSeqBAIJRestoreArray(B, &v));
  else PetscCall(MatSeqAIJRestoreArray(B, &v));
  PetscCall(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatPropagateSymmetryOptions(A, B));
  *newmat = B;
  PetscFunctionReturn(0);
}

/* MATSEQBINBCSR -> seqaij (bs 1 rows) or seqbaij (bs x bs blocks): a new matrix by its arrays, into a
   reused one (whose pattern may differ) row by row. */
static PetscErrorCode MatConvert_SeqBinBCSR_XAIJ(Mat A, MatType newtype, MatReuse reuse, Mat *newmat,
                                                 PetscBool blocked)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  Mat             B;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatConvert needs an assembled MATSEQBINBCSR matrix");
  if (reuse == MAT_REUSE_MATRIX) {
    B = *newmat;
    PetscCall(MatZeroEntries(B));
    PetscCall(MatBinBCSRInsertRows_Private(A, B));
    PetscFunctionReturn(0);
  }
  PetscCall(MatConvert_SeqBinBCSR_XAIJ_New(A, newtype, blocked, &B));
  if (reuse == MAT_INPLACE_MATRIX) PetscCall(MatHeaderReplace(A, &B));
  else *newmat = B;
  PetscFunctionReturn(0);
}

PetscErrorCode MatConvert_SeqBinBCSR_SeqAIJ(Mat A, MatType newtype, MatReuse reuse, Mat *newmat)
{
  PetscFunctionBegin;
  PetscCall(MatConvert_SeqBinBCSR_XAIJ(A, newtype, reuse, newmat, PETSC_FALSE));
  PetscFunctionReturn(0);
}

PetscErrorCode MatConvert_SeqBinBCSR_SeqBAIJ(Mat A, MatType newtype, MatReuse reuse, Mat *newmat)
{
  PetscFunctionBegin;
  PetscCall(MatConvert_SeqBinBCSR_XAIJ(A, newtype, reuse, newmat, PETSC_TRUE));
  PetscFunctionReturn(0);
}

static PetscInt CountDiagonalBlocks(const Mat_SeqBinBCSR *a)
{
  PetscInt n = 0;
  for (PetscInt r = 0; r < a->mbs; r++) n += a->diag_slot[r] >= 0;
  return n;
}

/* slot groups whose lanes read consecutive block columns: the products load x there (and y with
   symmetric storage) instead of gathering it */
static PetscInt MatSeqBinBCSRCountUnitStrideGroups(const Mat_SeqBinBCSR *a)
{
  PetscInt n = 0;
  for (PetscInt g = 0; g < a->nslots / a->bw; g++) n += binbcsr::unit_stride(a->col + g * a->bw, (int)a->bw);
  return n;
}

PetscErrorCode MatView_SeqBinBCSR_ASCII(Mat A, PetscViewer viewer)
{
  Mat_SeqBinBCSR   *a = (Mat_SeqBinBCSR *)A->data;
  PetscViewerFormat format;

  PetscFunctionBegin;
  PetscCall(PetscViewerGetFormat(viewer, &format));
  if (format == PETSC_VIEWER_ASCII_FACTOR_INFO) PetscFunctionReturn(0);
  if (format == PETSC_VIEWER_ASCII_INFO || format == PETSC_VIEWER_ASCII_INFO_DETAIL) {
    const size_t vbytes = (size_t)a->nslots * a->bs2 *
                          (a->precision == MAT_BINBCSR_PRECISION_DOUBLE ? sizeof(MatScalar) : sizeof(float));
    const size_t ibytes = (size_t)a->nslots * sizeof(PetscInt) + (size_t)(a->nbins + 1) * sizeof(PetscInt);
    PetscCall(PetscViewerASCIIPrintf(viewer,
                                     "%s, block size %" PetscInt_FMT ", bin width %" PetscInt_FMT
                                     ", values in %s precision (double accumulation), %s storage\n",
                                     a->bs == 1 ? "BIN-CSR" : "BIN-BCSR", a->bs, a->bw,
                                     MatBinBCSRPrecisions[a->precision],
                                     a->sym ? "upper-triangle" : "whole"));
    if (!a->built) {
      PetscCall(
        PetscViewerASCIIPrintf(viewer, "bin layout not built yet (built at the first final assembly)\n"));
      PetscFunctionReturn(0);
    }
    PetscCall(PetscViewerASCIIPrintf(
      viewer,
      "bins %" PetscInt_FMT ", stored blocks %" PetscInt_FMT ", slots %" PetscInt_FMT
      " (padding overhead %.2f%%), longest row %" PetscInt_FMT " blocks\n",
      a->nbins, a->nz, a->nslots, a->nz ? 100.0 * (double)(a->nslots - a->nz) / (double)a->nz : 0.0,
      a->max_row_nz));
    PetscCall(PetscViewerASCIIPrintf(
      viewer, "bytes: values %zu, indices %zu (column per slot and bin offsets)\n", vbytes, ibytes));
    if ((a->bs == 1 || a->bs == 3) &&
        (a->bw == 4 || a->bw == 8 || a->bw == 16 || a->bw == 32)) { /* the shapes of the vectorised sweeps */
      const PetscInt groups = a->nslots / a->bw, unit = MatSeqBinBCSRCountUnitStrideGroups(a);
      PetscCall(PetscViewerASCIIPrintf(
        viewer,
        "slot groups over consecutive block columns (x%s read without gathers): %" PetscInt_FMT
        " of %" PetscInt_FMT " (%.1f%%)\n",
        a->sym ? " and y" : "", unit, groups, groups ? 100.0 * (double)unit / (double)groups : 0.0));
      PetscCall(PetscViewerASCIIPrintf(
        viewer, "product: %" PetscInt_FMT " run(s) of bins swept side by side (-mat_binbcsr_streams)\n",
        a->streams));
      PetscCall(PetscViewerASCIIPrintf(
        viewer, "product: values prefetched %" PetscInt_FMT " bytes ahead%s (-mat_binbcsr_prefetch)\n",
        a->prefetch, a->prefetch ? "" : " (no software prefetch)"));
      if (MatSeqBinBCSRReadsXLoad(a))
        PetscCall(PetscViewerASCIIPrintf(
          viewer, "product: x read by %s (-mat_binbcsr_xload %s)\n",
          a->xload == MAT_BINBCSR_XLOAD_GATHER
            ? "gathers in every slot group"
            : "block loads in the bins of mostly consecutive columns, lane by lane elsewhere",
          MatBinBCSRXLoads[a->xload]));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "product body: %s (-mat_binbcsr_kernel %s)\n",
                                     binbcsr::body_set_name(MatSeqBinBCSRSelectBody(a).set),
                                     MatBinBCSRKernels[a->kernel]));
    if (a->tune_info[0])
      PetscCall(PetscViewerASCIIPrintf(viewer, "tuning (-mat_binbcsr_tune): %s\n", a->tune_info));
    if (a->coo_jmap || a->coo_mirror) {
      const char *refill = a->coo_slot_state == 1    ? "by whole blocks"
                           : a->coo_slot_state == -1 ? "value by value (the list is not made of whole blocks)"
                                                     : "path chosen at the first refill";
      if (a->coo_jmap)
        PetscCall(PetscViewerASCIIPrintf(
          viewer, "COO: %" PetscCount_FMT " entries, refill %s%s\n", a->coo_n, refill,
          a->coo_mirror ? "; mirror on (entries of off-diagonal blocks also fill the transposed place)"
                        : ""));
      else PetscCall(PetscViewerASCIIPrintf(viewer, "COO mirror on (for MatSetPreallocationCOO)\n"));
    }
    if (a->sym)
      PetscCall(PetscViewerASCIIPrintf(viewer,
                                       "symmetric storage: upper triangle, %" PetscInt_FMT
                                       " stored blocks (the lower %" PetscInt_FMT " implied), %" PetscInt_FMT
                                       " padding slots; slots ordered by edge colouring\n",
                                       a->nz, a->nz - CountDiagonalBlocks(a), a->nslots - a->nz));
    PetscFunctionReturn(0);
  }
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatView of the entries needs an assembled matrix");
  PetscCall(PetscViewerASCIIUseTabs(viewer, PETSC_FALSE));
  for (PetscInt r = 0; r < A->rmap->n; r++) {
    const PetscInt bs = a->bs, br = r / bs, ri = r % bs;
    PetscCall(PetscViewerASCIIPrintf(viewer, "row %" PetscInt_FMT ":", r));
    if (a->sym) { /* both triangles, as AIJ lists them */
      PetscInt           n;
      const PetscInt    *cols;
      const PetscScalar *vals;
      PetscCall(MatGetRow_SeqBinBCSR(A, r, &n, (PetscInt **)&cols, (PetscScalar **)&vals));
      for (PetscInt k = 0; k < n; k++)
        PetscCall(PetscViewerASCIIPrintf(viewer, " (%" PetscInt_FMT ", %g) ", cols[k], (double)vals[k]));
      PetscCall(MatRestoreRow_SeqBinBCSR(A, r, &n, (PetscInt **)&cols, (PetscScalar **)&vals));
      PetscCall(PetscViewerASCIIPrintf(viewer, "\n"));
      continue;
    }
    for (PetscInt k = 0; k < a->row_nz[br]; k++) {
      const PetscInt s = BinBCSRSlot(a, br, k);
      for (PetscInt j = 0; j < bs; j++)
        PetscCall(PetscViewerASCIIPrintf(
          viewer, " (%" PetscInt_FMT ", %g) ", a->col[s] * bs + j,
          (double)BinBCSRGetValue(a, BinBCSRValueIndex(s, ri * bs + j, a->bw, a->bs2))));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "\n"));
  }
  PetscCall(PetscViewerASCIIUseTabs(viewer, PETSC_TRUE));
  PetscFunctionReturn(0);
}

PetscErrorCode MatView_SeqBinBCSR(Mat A, PetscViewer viewer)
{
  PetscBool isascii;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &isascii));
  if (isascii) PetscCall(MatView_SeqBinBCSR_ASCII(A, viewer));
  else PetscCall(MatView_SeqBinBCSR_Other(A, viewer)); /* binary natively, the rest through a seqaij copy */
  PetscFunctionReturn(0);
}
