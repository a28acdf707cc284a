/* MATSEQBINBCSR: creation, options, staging, MatSetValues and assembly (the layout build itself:
   binbcsr_build.cpp). */
#include "binbcsr.h"
#include <algorithm>
#include <vector>

/* Staged pattern and values, per block row: sorted block columns and bs2 values per block
   (row-major). Kept as vectors because stock programs insert in any order before the first
   assembly; the bin layout is built once from it. */
struct BinBCSRStaging {
  std::vector<std::vector<PetscInt>>  cols;
  std::vector<std::vector<MatScalar>> vals;
  std::vector<PetscInt>               prealloc; /* block nonzeros per block row, empty if unknown */
};

static PetscErrorCode MatSeqBinBCSRFreeLayout(Mat_SeqBinBCSR *a)
{
  PetscFunctionBegin;
  PetscCall(PetscFree(a->bin_start));
  PetscCall(PetscFree(a->row_nz));
  PetscCall(PetscFree(a->diag_slot));
  PetscCall(PetscFree(a->col));
  PetscCall(PetscFree(a->row_off));
  PetscCall(PetscFree(a->real_slot));
  PetscCall(PetscFree(a->lower_off));
  PetscCall(PetscFree(a->lower_slot));
  PetscCall(PetscFree(a->val));
  PetscCall(PetscFree(a->valf));
  PetscCall(PetscFree2(a->rowbuf_cols, a->rowbuf_vals));
  PetscCall(PetscFree(a->idiag));
  PetscCall(PetscFree(a->sor_idiag));
  a->sor_state = 0;
  PetscCall(MatSeqBinBCSRDestroyCOO(a));
  a->built  = PETSC_FALSE;
  a->nbins  = 0;
  a->nslots = 0;
  a->nz     = 0;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRDestroyCOO(Mat_SeqBinBCSR *a)
{
  PetscFunctionBegin;
  PetscCall(PetscFree(a->coo_jmap));
  PetscCall(PetscFree(a->coo_perm));
  PetscCall(PetscFree(a->coo_perm_src));
  PetscCall(PetscFree(a->coo_slot_ptr));
  PetscCall(PetscFree(a->coo_slot_src));
  a->coo_slot_state = 0;
  a->coo_composed = PETSC_FALSE;
  a->coo_n        = 0;
  PetscFunctionReturn(0);
}

/* Block size and block counts from the layouts; the check every entry point shares. */
static PetscErrorCode MatSeqBinBCSRSetSizes(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        rbs, cbs;

  PetscFunctionBegin;
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCall(MatGetBlockSizes(A, &rbs, &cbs));
  PetscCheck(rbs == cbs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "MATSEQBINBCSR needs equal row and column block sizes, got %" PetscInt_FMT " and %" PetscInt_FMT, rbs, cbs);
  PetscCheck(A->rmap->n % rbs == 0 && A->cmap->n % rbs == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "Matrix sizes %" PetscInt_FMT " x %" PetscInt_FMT " are not multiples of the block size %" PetscInt_FMT, A->rmap->n, A->cmap->n, rbs);
  a->bs  = rbs;
  a->bs2 = rbs * rbs;
  a->mbs = A->rmap->n / rbs;
  a->nbs = A->cmap->n / rbs;
  PetscFunctionReturn(0);
}

/* Sizes checked, any layout and staging dropped: what a new layout build starts from. */
PetscErrorCode MatSeqBinBCSRResetLayout(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRSetSizes(A));
  PetscCall(MatSeqBinBCSRFreeLayout(a));
  delete a->staging;
  a->staging = nullptr;
  PetscFunctionReturn(0);
}

/* A fresh, empty staging area; drops any layout (preallocation starts a new pattern, as in AIJ). */
static PetscErrorCode MatSeqBinBCSRResetStaging(Mat A, const PetscInt *block_nnz, PetscInt block_nz)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRSetSizes(A));
  PetscCall(MatSeqBinBCSRFreeLayout(a));
  delete a->staging;
  a->staging = new BinBCSRStaging;
  a->staging->cols.resize(a->mbs);
  a->staging->vals.resize(a->mbs);
  if (block_nnz || block_nz > 0) {
    a->staging->prealloc.resize(a->mbs);
    for (PetscInt r = 0; r < a->mbs; r++) {
      const PetscInt n = PetscMin(block_nnz ? block_nnz[r] : block_nz, a->nbs);
      PetscCheck(n >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Negative preallocation %" PetscInt_FMT " for block row %" PetscInt_FMT, n, r);
      a->staging->prealloc[r] = n;
      a->staging->cols[r].reserve(n);
      a->staging->vals[r].reserve(n * a->bs2);
    }
  }
  A->preallocated = PETSC_TRUE;
  A->was_assembled = PETSC_FALSE;
  A->assembled     = PETSC_FALSE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetUp_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (!a->staging && !a->built) PetscCall(MatSeqBinBCSRResetStaging(A, nullptr, 0));
  A->preallocated = PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSeqAIJSetPreallocation_SeqBinBCSR(Mat A, PetscInt nz, const PetscInt nnz[])
{
  PetscInt *bnnz = nullptr, bs;

  PetscFunctionBegin;
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  if (A->rmap->bs != A->cmap->bs) { /* a layout the bins cannot hold (PCGAMG's prolongators, made in the operator's type) */
    PetscCall(PetscInfo(A, "Row and column block sizes %" PetscInt_FMT " and %" PetscInt_FMT " differ: the matrix becomes %s\n", A->rmap->bs, A->cmap->bs, MATSEQAIJ));
    PetscCall(MatSetType(A, MATSEQAIJ));
    PetscCall(MatSeqAIJSetPreallocation(A, nz, nnz));
    PetscFunctionReturn(0);
  }
  bs = PetscMax(A->rmap->bs, 1);
  if (nnz) { /* point rows -> block rows: the largest point row of a block row, in blocks (upper bound) */
    const PetscInt mbs = A->rmap->n / bs;
    PetscCall(PetscMalloc1(mbs, &bnnz));
    for (PetscInt r = 0; r < mbs; r++) {
      PetscInt mx = 0;
      for (PetscInt i = 0; i < bs; i++) mx = PetscMax(mx, nnz[r * bs + i]);
      bnnz[r] = mx;
    }
  }
  PetscCall(MatSeqBinBCSRResetStaging(A, bnnz, nz == PETSC_DEFAULT || nz == PETSC_DECIDE ? 0 : nz));
  PetscCall(PetscFree(bnnz));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSeqBAIJSetPreallocation_SeqBinBCSR(Mat A, PetscInt bs, PetscInt nz, const PetscInt nnz[])
{
  PetscFunctionBegin;
  PetscCall(MatSetBlockSize(A, PetscAbs(bs)));
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCheck(A->rmap->bs == PetscAbs(bs), PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "Block size %" PetscInt_FMT " given to the preallocation differs from the matrix block size %" PetscInt_FMT, bs, A->rmap->bs);
  PetscCall(MatSeqBinBCSRResetStaging(A, nnz, nz == PETSC_DEFAULT || nz == PETSC_DECIDE ? 0 : nz));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRStagingZeroValues(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (a->staging)
    for (auto &v : a->staging->vals) std::fill(v.begin(), v.end(), 0.0);
  PetscFunctionReturn(0);
}

/* Symmetric storage chosen after some values were staged: the staged lower triangle goes. */
PetscErrorCode MatSeqBinBCSRStagingDropLower(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  for (PetscInt r = 0; r < (PetscInt)a->staging->cols.size(); r++) {
    std::vector<PetscInt> &cols = a->staging->cols[r];
    const size_t           nlow = (size_t)(std::lower_bound(cols.begin(), cols.end(), r) - cols.begin());
    cols.erase(cols.begin(), cols.begin() + nlow);
    a->staging->vals[r].erase(a->staging->vals[r].begin(), a->staging->vals[r].begin() + nlow * a->bs2);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRDuplicateStaging(Mat A, Mat B, PetscBool copyvalues)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data, *b = (Mat_SeqBinBCSR *)B->data;

  PetscFunctionBegin;
  delete b->staging;
  b->staging = a->staging ? new BinBCSRStaging(*a->staging) : nullptr;
  if (b->staging && !copyvalues) PetscCall(MatSeqBinBCSRStagingZeroValues(B));
  PetscFunctionReturn(0);
}

/* Staging -> bins, with the staged values. */
static PetscErrorCode MatSeqBinBCSRBuildFromStaging(Mat A)
{
  Mat_SeqBinBCSR  *a = (Mat_SeqBinBCSR *)A->data;
  BinBCSRStaging  *st = a->staging;
  PetscInt        *bi, *bj;
  const PetscInt   mbs = a->mbs, bs2 = a->bs2;

  PetscFunctionBegin;
  PetscCall(PetscMalloc1(mbs + 1, &bi));
  bi[0] = 0;
  for (PetscInt r = 0; r < mbs; r++) bi[r + 1] = bi[r] + (PetscInt)st->cols[r].size();
  PetscCall(PetscMalloc1(bi[mbs], &bj));
  for (PetscInt r = 0; r < mbs; r++) std::copy(st->cols[r].begin(), st->cols[r].end(), bj + bi[r]);
  a->staging = nullptr; /* keep the values while the layout is built */
  PetscCall(MatSeqBinBCSRBuildLayout(A, bi, bj));
  for (PetscInt r = 0; r < mbs; r++) {
    const std::vector<MatScalar> &v = st->vals[r];
    for (PetscInt k = 0; k < bi[r + 1] - bi[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k);
      for (PetscInt e = 0; e < bs2; e++) BinBCSRSetValue(a, BinBCSRValueIndex(s, e, a->bw, bs2), v[k * bs2 + e]);
    }
  }
  delete st;
  PetscCall(PetscFree(bi));
  PetscCall(PetscFree(bj));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatAssemblyEnd_SeqBinBCSR(Mat A, MatAssemblyType type)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (type == MAT_FLUSH_ASSEMBLY) PetscFunctionReturn(0);
  if (!a->built && !a->staging) PetscCall(MatSetUp_SeqBinBCSR(A)); /* assembled without any entry */
  if (!a->built) PetscCall(MatSeqBinBCSRBuildFromStaging(A));
  PetscFunctionReturn(0);
}

/* One value into the staged pattern; `ok` is false when the location is new and ignored. */
static PetscErrorCode StagingAdd(Mat A, Mat_SeqBinBCSR *a, PetscInt br, PetscInt bc, PetscInt e, PetscScalar v, InsertMode mode, PetscInt prow, PetscInt pcol)
{
  BinBCSRStaging        *st   = a->staging;
  std::vector<PetscInt> &cols = st->cols[br];
  auto                   it   = std::lower_bound(cols.begin(), cols.end(), bc);
  const size_t           k    = (size_t)(it - cols.begin());

  PetscFunctionBegin;
  if (it == cols.end() || *it != bc) {
    if (a->nonew == 1) PetscFunctionReturn(0);
    PetscCheck(a->nonew != -1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Inserting a new nonzero at (%" PetscInt_FMT ", %" PetscInt_FMT ") in the matrix (MAT_NEW_NONZERO_LOCATION_ERR is set)", prow, pcol);
    PetscCheck(!(a->nonew == -2 && !st->prealloc.empty() && (PetscInt)cols.size() >= st->prealloc[br]), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "New nonzero at (%" PetscInt_FMT ", %" PetscInt_FMT ") exceeds the preallocation (MAT_NEW_NONZERO_ALLOCATION_ERR is set)", prow, pcol);
    cols.insert(it, bc);
    st->vals[br].insert(st->vals[br].begin() + k * a->bs2, (size_t)a->bs2, 0.0);
  }
  MatScalar &dst = st->vals[br][k * a->bs2 + e];
  dst            = (mode == ADD_VALUES) ? dst + v : v;
  (void)A;
  PetscFunctionReturn(0);
}

/* One value into the frozen layout. `cache` keeps the last block found: element matrices hit the
   same block bs times in a row. */
static inline PetscErrorCode LayoutAdd(Mat_SeqBinBCSR *a, PetscInt br, PetscInt bc, PetscInt e, PetscScalar v, InsertMode mode, PetscInt prow, PetscInt pcol, PetscInt cache[3])
{
  PetscInt s;

  PetscFunctionBegin;
  if (cache[0] == br && cache[1] == bc) s = cache[2];
  else {
    s        = MatSeqBinBCSRFindSlot(a, br, bc);
    cache[0] = br;
    cache[1] = bc;
    cache[2] = s;
  }
  if (s < 0) {
    PetscCheck(a->nonew == 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "New nonzero at (%" PetscInt_FMT ", %" PetscInt_FMT "): the pattern of a MATSEQBINBCSR matrix is frozen at its first final assembly (use MatSetOption(A, MAT_NEW_NONZERO_LOCATIONS, PETSC_FALSE) to ignore new locations)", prow, pcol);
    PetscFunctionReturn(0);
  }
  {
    const PetscInt vi = BinBCSRValueIndex(s, e, a->bw, a->bs2);
    if (a->val) a->val[vi] = (mode == ADD_VALUES) ? a->val[vi] + v : v;
    else a->valf[vi] = (float)((mode == ADD_VALUES) ? (PetscScalar)a->valf[vi] + v : v);
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetValues_SeqBinBCSR(Mat A, PetscInt m, const PetscInt im[], PetscInt n, const PetscInt in[], const PetscScalar v[], InsertMode mode)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        cache[3] = {-1, -1, -1};

  PetscFunctionBegin;
  if (!a->built && !a->staging) PetscCall(MatSetUp_SeqBinBCSR(A));
  PetscCheck(PetscAbs(A->rmap->bs) == a->bs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "Block size changed from %" PetscInt_FMT " to %" PetscInt_FMT " after preallocation", a->bs, A->rmap->bs);
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt r = im[i];
    if (r < 0) continue;
    PetscCheck(r < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", r, A->rmap->n);
    const PetscInt br = r / a->bs, ri = r % a->bs;
    for (PetscInt j = 0; j < n; j++) {
      const PetscInt c = in[j];
      if (c < 0) continue;
      PetscCheck(c < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", c, A->cmap->n);
      const PetscScalar x = v ? (a->roworiented ? v[i * n + j] : v[j * m + i]) : 0.0;
      const PetscInt    bc = c / a->bs, e = ri * a->bs + c % a->bs;
      if (a->sym && bc < br) continue; /* symmetric storage: the lower triangle is implied */
      if (a->built) PetscCall(LayoutAdd(a, br, bc, e, x, mode, r, c, cache));
      else PetscCall(StagingAdd(A, a, br, bc, e, x, mode, r, c));
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetValuesBlocked_SeqBinBCSR(Mat A, PetscInt m, const PetscInt im[], PetscInt n, const PetscInt in[], const PetscScalar v[], InsertMode mode)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        cache[3] = {-1, -1, -1}, bs;

  PetscFunctionBegin;
  if (!a->built && !a->staging) PetscCall(MatSetUp_SeqBinBCSR(A));
  PetscCheck(PetscAbs(A->rmap->bs) == a->bs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "Block size changed from %" PetscInt_FMT " to %" PetscInt_FMT " after preallocation", a->bs, A->rmap->bs);
  bs = a->bs;
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt br = im[i];
    if (br < 0) continue;
    PetscCheck(br < a->mbs, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Block row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", br, a->mbs);
    for (PetscInt j = 0; j < n; j++) {
      const PetscInt bc = in[j];
      if (bc < 0) continue;
      PetscCheck(bc < a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Block column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", bc, a->nbs);
      if (a->sym && bc < br) continue; /* symmetric storage: the lower triangle is implied */
      for (PetscInt ii = 0; ii < bs; ii++) {
        for (PetscInt jj = 0; jj < bs; jj++) {
          const PetscInt    prow = i * bs + ii, pcol = j * bs + jj;
          const PetscScalar x    = v ? (a->roworiented ? v[prow * (n * bs) + pcol] : v[pcol * (m * bs) + prow]) : 0.0;
          if (a->built) PetscCall(LayoutAdd(a, br, bc, ii * bs + jj, x, mode, br * bs + ii, bc * bs + jj, cache));
          else PetscCall(StagingAdd(A, a, br, bc, ii * bs + jj, x, mode, br * bs + ii, bc * bs + jj));
        }
      }
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatGetValues_SeqBinBCSR(Mat A, PetscInt m, const PetscInt im[], PetscInt n, const PetscInt in[], PetscScalar v[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatGetValues needs an assembled MATSEQBINBCSR matrix");
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt r = im[i];
    if (r < 0) continue;
    PetscCheck(r < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", r, A->rmap->n);
    for (PetscInt j = 0; j < n; j++) {
      const PetscInt c = in[j];
      if (c < 0) continue;
      PetscCheck(c < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", c, A->cmap->n);
      if (a->sym && c / a->bs < r / a->bs) { /* the transposed entry of the stored upper block */
        const PetscInt s = MatSeqBinBCSRFindSlot(a, c / a->bs, r / a->bs);
        v[i * n + j]     = s < 0 ? 0.0 : BinBCSRGetValue(a, BinBCSRValueIndex(s, (c % a->bs) * a->bs + r % a->bs, a->bw, a->bs2));
        continue;
      }
      const PetscInt s = MatSeqBinBCSRFindSlot(a, r / a->bs, c / a->bs);
      v[i * n + j]     = s < 0 ? 0.0 : BinBCSRGetValue(a, BinBCSRValueIndex(s, (r % a->bs) * a->bs + c % a->bs, a->bw, a->bs2));
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetOption_SeqBinBCSR(Mat A, MatOption op, PetscBool flg)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  switch (op) {
  case MAT_ROW_ORIENTED:
    a->roworiented = flg;
    break;
  case MAT_NEW_NONZERO_LOCATIONS:
    a->nonew = flg ? 0 : 1;
    break;
  case MAT_NEW_NONZERO_LOCATION_ERR:
    a->nonew = flg ? -1 : 0;
    break;
  case MAT_NEW_NONZERO_ALLOCATION_ERR:
    a->nonew = flg ? -2 : 0;
    break;
  case MAT_UNUSED_NONZERO_LOCATION_ERR:
  case MAT_SYMMETRIC:
  case MAT_STRUCTURALLY_SYMMETRIC:
  case MAT_HERMITIAN:
  case MAT_SPD:
  case MAT_SYMMETRY_ETERNAL:
  case MAT_STRUCTURAL_SYMMETRY_ETERNAL:
  case MAT_SPD_ETERNAL:
  case MAT_IGNORE_OFF_PROC_ENTRIES:
  case MAT_NO_OFF_PROC_ENTRIES:
  case MAT_KEEP_NONZERO_PATTERN: /* the pattern is always kept: it is frozen at the first assembly */
  case MAT_IGNORE_ZERO_ENTRIES:
  case MAT_USE_HASH_TABLE:
  case MAT_IGNORE_LOWER_TRIANGULAR:
  case MAT_GETROW_UPPERTRIANGULAR:
  case MAT_SORTED_FULL:
  case MAT_STRUCTURE_ONLY:
  case MAT_USE_INODES:
  case MAT_FORM_EXPLICIT_TRANSPOSE:
    PetscCall(PetscInfo(A, "Option %s accepted (no effect on the storage)\n", MatOptions[op]));
    break;
  default:
    PetscCall(PetscInfo(A, "Option %s ignored\n", MatOptions[op]));
    break;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetBinWidth_SeqBinBCSR(Mat A, PetscInt bw)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (bw == PETSC_DEFAULT || bw == PETSC_DECIDE) {
    PetscCheck(!a->built || !a->bw_set || a->bw == BinBCSRDefaultBinWidth(a->bs), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "The bin width must be set before the layout is built (first final assembly or COO preallocation)");
    a->bw_set = PETSC_FALSE;
    PetscFunctionReturn(0);
  }
  PetscCheck(bw >= 1 && bw <= 1024, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Bin width %" PetscInt_FMT " must lie in [1, 1024]", bw);
  PetscCheck(!a->built || bw == a->bw, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "The bin width must be set before the layout is built (first final assembly or COO preallocation)");
  a->bw     = bw;
  a->bw_set = PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetBinWidth_SeqBinBCSR(Mat A, PetscInt *bw)
{
  PetscFunctionBegin;
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  *bw                = (a->built || a->bw_set) ? a->bw : BinBCSRDefaultBinWidth(PetscAbs(A->rmap->bs));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetPrecision_SeqBinBCSR(Mat A, MatBinBCSRPrecision p)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  const size_t    nv = (size_t)a->nslots * a->bs2;

  PetscFunctionBegin;
  PetscCheck(p == MAT_BINBCSR_PRECISION_DOUBLE || p == MAT_BINBCSR_PRECISION_SINGLE, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Unknown precision %d", (int)p);
  if (p == a->precision) PetscFunctionReturn(0);
  if (a->built) {
    if (p == MAT_BINBCSR_PRECISION_SINGLE) {
      PetscCall(PetscMalloc1(nv, &a->valf));
      for (size_t i = 0; i < nv; i++) a->valf[i] = (float)a->val[i];
      PetscCall(PetscFree(a->val));
    } else {
      PetscCall(PetscMalloc1(nv, &a->val));
      for (size_t i = 0; i < nv; i++) a->val[i] = (MatScalar)a->valf[i];
      PetscCall(PetscFree(a->valf));
    }
    PetscCall(PetscObjectStateIncrease((PetscObject)A));
  }
  a->precision = p;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetPrecision_SeqBinBCSR(Mat A, MatBinBCSRPrecision *p)
{
  PetscFunctionBegin;
  *p = ((Mat_SeqBinBCSR *)A->data)->precision;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetSymmetricStorage_SeqBinBCSR(Mat A, PetscBool flg)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (flg == a->sym) PetscFunctionReturn(0);
  PetscCheck(!a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Symmetric storage must be chosen before the layout is built (first final assembly, COO preallocation, conversion or load)");
  PetscCheck(!flg || A->rmap->N < 0 || A->cmap->N < 0 || A->rmap->N == A->cmap->N, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Symmetric storage needs a square matrix, this one is %" PetscInt_FMT " x %" PetscInt_FMT, A->rmap->N, A->cmap->N);
  a->sym = flg;
  if (a->staging && flg) PetscCall(MatSeqBinBCSRStagingDropLower(A));
  if (flg) {
    PetscCall(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetSymmetricStorage_SeqBinBCSR(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = ((Mat_SeqBinBCSR *)A->data)->sym;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetCOOMirror_SeqBinBCSR(Mat A, PetscBool flg)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->coo_mirror = flg;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetCOOMirror_SeqBinBCSR(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = ((Mat_SeqBinBCSR *)A->data)->coo_mirror;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetStreams_SeqBinBCSR(Mat A, PetscInt streams)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->streams     = streams;
  ((Mat_SeqBinBCSR *)A->data)->streams_set = PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetTune_SeqBinBCSR(Mat A, MatBinBCSRTune t)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->tune = (PetscInt)t;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetTune_SeqBinBCSR(Mat A, MatBinBCSRTune *t)
{
  PetscFunctionBegin;
  *t = ((Mat_SeqBinBCSR *)A->data)->tune == (PetscInt)MAT_BINBCSR_TUNE_OFF ? MAT_BINBCSR_TUNE_OFF : MAT_BINBCSR_TUNE_AUTO;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRSetTuneCache_SeqBinBCSR(Mat A, PetscBool flg)
{
  PetscFunctionBegin;
  ((Mat_SeqBinBCSR *)A->data)->tune_cache = flg ? 1 : 0;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetTuneCache_SeqBinBCSR(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  *flg = ((Mat_SeqBinBCSR *)A->data)->tune_cache == 0 ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatBinBCSRGetStreams_SeqBinBCSR(Mat A, PetscInt *streams)
{
  PetscFunctionBegin;
  *streams = ((Mat_SeqBinBCSR *)A->data)->streams;
  PetscFunctionReturn(0);
}

static PetscErrorCode MatSetFromOptions_SeqBinBCSR(Mat A, PetscOptionItems *PetscOptionsObject)
{
  Mat_SeqBinBCSR     *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt            bw;
  MatBinBCSRPrecision p  = a->precision;
  PetscBool           set, sym;
  PetscInt            streams = a->streams;

  PetscFunctionBegin;
  PetscCall(MatBinBCSRGetBinWidth_SeqBinBCSR(A, &bw));
  PetscOptionsHeadBegin(PetscOptionsObject, "MATSEQBINBCSR options");
  PetscCall(PetscOptionsInt("-mat_binbcsr_bin_width", "Rows (block rows) per bin", "MatBinBCSRSetBinWidth", bw, &bw, &set));
  if (set) PetscCall(MatBinBCSRSetBinWidth_SeqBinBCSR(A, bw));
  PetscCall(PetscOptionsEnum("-mat_binbcsr_precision", "Storage precision of the values", "MatBinBCSRSetPrecision", MatBinBCSRPrecisions, (PetscEnum)p, (PetscEnum *)&p, &set));
  if (set) PetscCall(MatBinBCSRSetPrecision_SeqBinBCSR(A, p));
  sym = a->sym;
  PetscCall(PetscOptionsBool("-mat_binbcsr_symmetric_storage", "Store the upper triangle only (symmetric matrices; the lower triangle given is ignored)", "MatBinBCSRSetSymmetricStorage", sym, &sym, &set));
  if (set) PetscCall(MatBinBCSRSetSymmetricStorage_SeqBinBCSR(A, sym));
  PetscCall(PetscOptionsBool("-mat_binbcsr_coo_mirror", "COO entries of off-diagonal blocks also fill the transposed place (give one triangle of a symmetric matrix)", "MatBinBCSRSetCOOMirror", a->coo_mirror, &a->coo_mirror, nullptr));
  PetscCall(PetscOptionsInt("-mat_binbcsr_streams", "Runs of bins the product sweeps side by side (1, 2, 4, 8)", "MatBinBCSRSetStreams", streams, &streams, &set));
  if (set) PetscCall(MatBinBCSRSetStreams(A, streams));
  {
    PetscEnum t = (PetscEnum)(a->tune == (PetscInt)MAT_BINBCSR_TUNE_OFF ? MAT_BINBCSR_TUNE_OFF : MAT_BINBCSR_TUNE_AUTO);
    PetscBool c = a->tune_cache == 0 ? PETSC_FALSE : PETSC_TRUE;
    PetscCall(PetscOptionsEnum("-mat_binbcsr_tune", "Time bin widths and stream counts on this machine at the layout build and keep the fastest", "MatBinBCSRSetTune", MatBinBCSRTunes, t, &t, &set));
    if (set) a->tune = (PetscInt)t;
    PetscCall(PetscOptionsBool("-mat_binbcsr_tune_cache", "Read and write the tuner's cache file ($XDG_CACHE_HOME/petscbinbcsr/)", "MatBinBCSRSetTuneCache", c, &c, &set));
    if (set) a->tune_cache = c ? 1 : 0;
  }
  PetscCall(MatBinBCSRKernelFromOptions_Private(PetscOptionsObject, A, a->kernel));
  PetscOptionsHeadEnd();
  PetscFunctionReturn(0);
}

/* Minimal MatGetInfo so that programs asking for it work before binbcsr_ops.cpp provides the full one
   (MatSeqBinBCSRSetOps_Ops runs after this table is filled and may replace it). */
static PetscErrorCode MatGetInfo_SeqBinBCSR_Basic(Mat A, MatInfoType flag, MatInfo *info)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  (void)flag;
  PetscCall(PetscMemzero(info, sizeof(*info)));
  info->block_size   = (PetscLogDouble)a->bs;
  info->nz_used      = a->built ? (PetscLogDouble)a->nz * a->bs2 : 0;
  info->nz_allocated = a->built ? (PetscLogDouble)a->nslots * a->bs2 : 0;
  info->nz_unneeded  = info->nz_allocated - info->nz_used;
  info->assemblies   = (PetscLogDouble)A->num_ass;
  info->memory       = 0;
  PetscFunctionReturn(0);
}

static const char *const composed_names[] = {"MatBinBCSRSetBinWidth_C", "MatBinBCSRGetBinWidth_C", "MatBinBCSRSetPrecision_C", "MatBinBCSRGetPrecision_C", "MatBinBCSRSetSymmetricStorage_C", "MatBinBCSRGetSymmetricStorage_C", "MatBinBCSRSetCOOMirror_C", "MatBinBCSRGetCOOMirror_C", "MatBinBCSRSetStreams_C", "MatBinBCSRGetStreams_C", "MatBinBCSRSetTune_C", "MatBinBCSRGetTune_C", "MatBinBCSRSetTuneCache_C", "MatBinBCSRGetTuneCache_C", "MatSeqAIJSetPreallocation_C", "MatSeqBAIJSetPreallocation_C", "MatSetPreallocationCOO_C", "MatSetValuesCOO_C", "MatMultDotLocal_C", "MatConvert_seqbinbcsr_seqaij_C", "MatConvert_seqbinbcsr_seqbaij_C", "MatProductSetFromOptions_anytype_C", "MatAXPYGetPreallocation_C"};

static PetscErrorCode MatDestroy_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (a) {
    PetscCall(MatSeqBinBCSRFreeLayout(a));
    delete a->staging;
  }
  PetscCall(PetscFree(A->data));
  PetscCall(PetscObjectChangeTypeName((PetscObject)A, nullptr));
  for (const char *name : composed_names) PetscCall(PetscObjectComposeFunction((PetscObject)A, name, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode MatCreate_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a;
  PetscMPIInt     size;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)A), &size));
  PetscCheck(size == 1, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "MATSEQBINBCSR is for one process; use MATBINBCSR or MATMPIBINBCSR");
  PetscCall(PetscNew(&a));
  A->data        = (void *)a;
  a->bw          = BinBCSRDefaultBinWidth(1);
  a->precision   = MAT_BINBCSR_PRECISION_DOUBLE;
  a->streams     = BINBCSR_DEFAULT_STREAMS;
  a->tune        = -1;
  a->tune_cache  = -1;
  a->roworiented = PETSC_TRUE;
  a->bs          = 1;
  a->bs2         = 1;

  PetscCall(PetscMemzero(A->ops, sizeof(struct _MatOps)));
  A->ops->setvalues           = MatSetValues_SeqBinBCSR;
  A->ops->setvaluesblocked    = MatSetValuesBlocked_SeqBinBCSR;
  A->ops->getvalues           = MatGetValues_SeqBinBCSR;
  A->ops->getrow              = MatGetRow_SeqBinBCSR;
  A->ops->restorerow          = MatRestoreRow_SeqBinBCSR;
  A->ops->mult                = MatMult_SeqBinBCSR;
  A->ops->multadd             = MatMultAdd_SeqBinBCSR;
  A->ops->multtranspose       = MatMultTranspose_SeqBinBCSR;
  A->ops->multtransposeadd    = MatMultTransposeAdd_SeqBinBCSR;
  A->ops->getdiagonal         = MatGetDiagonal_SeqBinBCSR;
  A->ops->invertblockdiagonal = MatInvertBlockDiagonal_SeqBinBCSR;
  A->ops->invertvariableblockdiagonal = MatInvertVariableBlockDiagonal_SeqBinBCSR;
  A->ops->sor                 = MatSOR_SeqBinBCSR;
  A->ops->multdiagonalblock   = MatMultDiagonalBlock_SeqBinBCSR;
  A->ops->assemblyend         = MatAssemblyEnd_SeqBinBCSR;
  A->ops->setoption           = MatSetOption_SeqBinBCSR;
  A->ops->setup               = MatSetUp_SeqBinBCSR;
  A->ops->duplicate           = MatDuplicate_SeqBinBCSR;
  A->ops->copy                = MatCopy_SeqBinBCSR;
  A->ops->destroy             = MatDestroy_SeqBinBCSR;
  A->ops->view                = MatView_SeqBinBCSR;
  A->ops->convertfrom         = MatConvertFrom_SeqBinBCSR;
  A->ops->setfromoptions      = MatSetFromOptions_SeqBinBCSR;
  A->ops->getinfo             = MatGetInfo_SeqBinBCSR_Basic;
  A->ops->creategraph         = MatCreateGraph_BinBCSR; /* PCGAMG, through the AIJ shadow */
  A->ops->productsetfromoptions = MatProductSetFromOptions_BinBCSR;

  PetscCall(PetscObjectChangeTypeName((PetscObject)A, MATSEQBINBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetBinWidth_C", MatBinBCSRSetBinWidth_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetBinWidth_C", MatBinBCSRGetBinWidth_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetPrecision_C", MatBinBCSRSetPrecision_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetPrecision_C", MatBinBCSRGetPrecision_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetSymmetricStorage_C", MatBinBCSRSetSymmetricStorage_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetSymmetricStorage_C", MatBinBCSRGetSymmetricStorage_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetCOOMirror_C", MatBinBCSRSetCOOMirror_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetCOOMirror_C", MatBinBCSRGetCOOMirror_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetStreams_C", MatBinBCSRSetStreams_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetStreams_C", MatBinBCSRGetStreams_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetTune_C", MatBinBCSRSetTune_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetTune_C", MatBinBCSRGetTune_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRSetTuneCache_C", MatBinBCSRSetTuneCache_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatBinBCSRGetTuneCache_C", MatBinBCSRGetTuneCache_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatSeqAIJSetPreallocation_C", MatSeqAIJSetPreallocation_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatSeqBAIJSetPreallocation_C", MatSeqBAIJSetPreallocation_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatSetPreallocationCOO_C", MatSetPreallocationCOO_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatSetValuesCOO_C", MatSetValuesCOO_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatMultDotLocal_C", MatMultDotLocal_SeqBinBCSR));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatConvert_seqbinbcsr_seqaij_C", MatConvert_SeqBinBCSR_SeqAIJ));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatConvert_seqbinbcsr_seqbaij_C", MatConvert_SeqBinBCSR_SeqBAIJ));
  PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatProductSetFromOptions_anytype_C", MatProductSetFromOptions_BinBCSR)); /* products with other types */

  PetscCall(MatSeqBinBCSRSetOps_Ops(A));
  PetscFunctionReturn(0);
}
