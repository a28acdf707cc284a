/* MATSEQBINBCSR: staging, preallocation, MatSetValues(Blocked), MatGetValues and assembly (the layout
   build itself: binbcsr_build.cpp; the type, its ops table and options: binbcsr.cpp). */
#include "binbcsr.h"
#include <algorithm>
#include <memory_resource>
#include <new>
#include <vector>

namespace {

/* Where the staging arena gets its buffers: those of 4 MiB and more from a mapping of their own on
   transparent huge pages, as the value arrays (MatSeqBinBCSRMapHuge); smaller ones from the heap.
   Filling the 48^3 stencil touches ~250 MB of staging; with 4 KiB pages that is 60,000 page faults,
   about 10 us each on a virtual machine. */
class HugePageUpstream final : public std::pmr::memory_resource {
  struct Mapping {
    void  *start, *base;
    size_t length;
  };
  std::vector<Mapping> maps;

  void *do_allocate(size_t bytes, size_t align) override
  {
    void  *base;
    size_t length;
    if (void *start = align <= ((size_t)2 << 20) ? MatSeqBinBCSRMapHuge(bytes, &base, &length) : nullptr) {
      maps.push_back({start, base, length});
      return start;
    }
    return ::operator new(bytes, std::align_val_t(align));
  }
  void do_deallocate(void *p, size_t bytes, size_t align) override
  {
    for (size_t k = 0; k < maps.size(); k++)
      if (maps[k].start == p) {
        MatSeqBinBCSRUnmapHuge(maps[k].base, maps[k].length);
        maps.erase(maps.begin() + (long)k);
        return;
      }
    ::operator delete(p, bytes, std::align_val_t(align));
  }
  bool do_is_equal(const std::pmr::memory_resource &o) const noexcept override { return this == &o; }
};

} // namespace

/* Staged pattern and values, per block row: sorted block columns and bs2 values per block
   (row-major). Kept as vectors because stock programs insert in any order before the first
   assembly; the bin layout is built once from it. The rows' memory comes from one arena, released
   with the staging: a heap allocation per row (two per block row) cost the 48^3 stencil's 110,592
   block rows about a second in glibc's malloc and its page faults. */
struct BinBCSRStaging {
  HugePageUpstream                         upstream; /* declared first: outlives the arena */
  std::pmr::monotonic_buffer_resource      arena;    /* ... which outlives the rows */
  std::vector<std::pmr::vector<PetscInt>>  cols;
  std::vector<std::pmr::vector<MatScalar>> vals;
  std::vector<PetscInt>                    prealloc; /* block nonzeros per block row, empty if unknown */

  /* expect: the bytes the rows will reserve, if known (the arena's first buffer) */
  explicit BinBCSRStaging(PetscInt mbs, size_t expect = 0)
      : arena(expect > 0 ? expect : (size_t)4096, &upstream)
  {
    cols.reserve((size_t)mbs);
    vals.reserve((size_t)mbs);
    for (PetscInt r = 0; r < mbs; r++) {
      cols.emplace_back(&arena);
      vals.emplace_back(&arena);
    }
  }
  BinBCSRStaging(const BinBCSRStaging &o) : BinBCSRStaging((PetscInt)o.cols.size(), o.bytes())
  {
    for (size_t r = 0; r < o.cols.size(); r++) {
      cols[r].assign(o.cols[r].begin(), o.cols[r].end());
      vals[r].assign(o.vals[r].begin(), o.vals[r].end());
    }
    prealloc = o.prealloc;
  }
  BinBCSRStaging &operator=(const BinBCSRStaging &) = delete;

  size_t bytes() const
  {
    size_t b = 0;
    for (size_t r = 0; r < cols.size(); r++)
      b += cols[r].size() * sizeof(PetscInt) + vals[r].size() * sizeof(MatScalar);
    return b;
  }
};

static PetscErrorCode MatSeqBinBCSRFreeLayout(Mat_SeqBinBCSR *a)
{
  PetscFunctionBegin;
  PetscCall(PetscFree(a->bin_start));
  PetscCall(PetscFree(a->row_nz));
  PetscCall(PetscFree(a->diag_slot));
  PetscCall(PetscFree(a->col));
  PetscCall(PetscFree(a->bin_xload));
  PetscCall(PetscFree(a->row_off));
  PetscCall(PetscFree(a->real_slot));
  PetscCall(PetscFree(a->lower_off));
  PetscCall(PetscFree(a->lower_slot));
  PetscCall(MatSeqBinBCSRFreeValues_Private(a));
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
  if (a->coo_shared && --a->coo_shared->refs > 0) { /* another matrix still holds them */
    a->coo_jmap = nullptr;
    a->coo_perm = nullptr;
  } else {
    delete a->coo_shared;
    PetscCall(PetscFree(a->coo_jmap));
    PetscCall(PetscFree(a->coo_perm));
  }
  a->coo_shared = nullptr;
  PetscCall(PetscFree(a->coo_perm_src));
  PetscCall(PetscFree(a->coo_slot_ptr));
  PetscCall(PetscFree(a->coo_slot_src));
  a->coo_slot_state = 0;
  a->coo_composed   = PETSC_FALSE;
  a->coo_n          = 0;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRFreeStorage(Mat_SeqBinBCSR *a)
{
  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRFreeLayout(a));
  delete a->staging;
  a->staging = nullptr;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRSetSizes(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        rbs, cbs;

  PetscFunctionBegin;
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCall(MatGetBlockSizes(A, &rbs, &cbs));
  PetscCheck(rbs == cbs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
             "MATSEQBINBCSR needs equal row and column block sizes, got %" PetscInt_FMT " and %" PetscInt_FMT,
             rbs, cbs);
  PetscCheck(A->rmap->n % rbs == 0 && A->cmap->n % rbs == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
             "Matrix sizes %" PetscInt_FMT " x %" PetscInt_FMT
             " are not multiples of the block size %" PetscInt_FMT,
             A->rmap->n, A->cmap->n, rbs);
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

/* A fresh, empty staging area; drops any layout (preallocation starts a new pattern, as in AIJ).
   block_nnz[r] (or block_nz for every row): at most this many blocks in block row r, the bound the
   MAT_NEW_NONZERO_ALLOCATION_ERR check holds the row to. Each row reserves room for bound / fill
   blocks: fill 1 for counts of blocks (BAIJ), the block size for counts of scalars (AIJ), whose bound
   is the largest point row's count, bs times the blocks of a row of full blocks. Reserving the whole
   bound there made a 3x3-block matrix reserve three times its size: the 48^3 stencil (110,592 block
   rows, 226 MB of values) peaked at 920 MB and took 3.3 s more than seqbaij to fill, most of it first
   touches of the reserved memory (MatXAIJSetPreallocation() preallocates as BAIJ, then as AIJ). A
   staging area of the same number of block rows is emptied and its rows' memory kept. */
static PetscErrorCode MatSeqBinBCSRResetStaging(Mat A, const PetscInt *block_nnz, PetscInt block_nz,
                                                PetscInt fill)
{
  Mat_SeqBinBCSR *a      = (Mat_SeqBinBCSR *)A->data;
  const bool      given  = block_nnz || block_nz > 0;
  const auto      bound  = [&](PetscInt r) { return PetscMin(block_nnz ? block_nnz[r] : block_nz, a->nbs); };
  const auto      blocks = [fill](PetscInt n) { return (n + fill - 1) / fill; }; /* what a row reserves */
  size_t          expect = 0; /* what the rows reserve, plus a little for the vectors' rounding */

  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRSetSizes(A));
  if (given) /* checked before anything is dropped */
    for (PetscInt r = 0; r < a->mbs; r++) {
      const PetscInt n = bound(r);
      PetscCheck(n >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "Negative preallocation %" PetscInt_FMT " for block row %" PetscInt_FMT, n, r);
      expect += (size_t)blocks(n) * (sizeof(PetscInt) + (size_t)a->bs2 * sizeof(MatScalar)) + 64;
    }
  PetscCall(MatSeqBinBCSRFreeLayout(a));
  if (a->staging && (PetscInt)a->staging->cols.size() == a->mbs) {
    for (auto &c : a->staging->cols) c.clear();
    for (auto &v : a->staging->vals) v.clear();
    a->staging->prealloc.clear();
  } else {
    delete a->staging;
    a->staging = new BinBCSRStaging(a->mbs, expect);
  }
  if (given) {
    a->staging->prealloc.resize(a->mbs);
    for (PetscInt r = 0; r < a->mbs; r++) {
      const PetscInt n        = bound(r);
      a->staging->prealloc[r] = n;
      a->staging->cols[r].reserve(blocks(n));
      a->staging->vals[r].reserve(blocks(n) * a->bs2);
    }
  }
  A->preallocated  = PETSC_TRUE;
  A->was_assembled = PETSC_FALSE;
  A->assembled     = PETSC_FALSE;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetUp_SeqBinBCSR(Mat A)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (!a->staging && !a->built) PetscCall(MatSeqBinBCSRResetStaging(A, nullptr, 0, 1));
  A->preallocated = PETSC_TRUE;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqAIJSetPreallocation_SeqBinBCSR(Mat A, PetscInt nz, const PetscInt nnz[])
{
  PetscInt *bnnz = nullptr, bs;

  PetscFunctionBegin;
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  if (A->rmap->bs !=
      A->cmap->bs) { /* a layout the bins cannot hold (PCGAMG's prolongators, made in the operator's type) */
    PetscCall(PetscInfo(
      A, "Row and column block sizes %" PetscInt_FMT " and %" PetscInt_FMT " differ: the matrix becomes %s\n",
      A->rmap->bs, A->cmap->bs, MATSEQAIJ));
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
  PetscCall(MatSeqBinBCSRResetStaging(A, bnnz, nz == PETSC_DEFAULT || nz == PETSC_DECIDE ? 0 : nz, bs));
  PetscCall(PetscFree(bnnz));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBAIJSetPreallocation_SeqBinBCSR(Mat A, PetscInt bs, PetscInt nz, const PetscInt nnz[])
{
  PetscFunctionBegin;
  PetscCall(MatSetBlockSize(A, PetscAbs(bs)));
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCheck(A->rmap->bs == PetscAbs(bs), PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
             "Block size %" PetscInt_FMT
             " given to the preallocation differs from the matrix block size %" PetscInt_FMT,
             bs, A->rmap->bs);
  PetscCall(MatSeqBinBCSRResetStaging(A, nnz, nz == PETSC_DEFAULT || nz == PETSC_DECIDE ? 0 : nz, 1));
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
    auto        &cols = a->staging->cols[r];
    const size_t nlow = (size_t)(std::lower_bound(cols.begin(), cols.end(), r) - cols.begin());
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
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  BinBCSRStaging *st = a->staging;
  PetscInt       *bi, *bj;
  const PetscInt  mbs = a->mbs, bs2 = a->bs2;

  PetscFunctionBegin;
  PetscCall(PetscMalloc1(mbs + 1, &bi));
  bi[0] = 0;
  for (PetscInt r = 0; r < mbs; r++) bi[r + 1] = bi[r] + (PetscInt)st->cols[r].size();
  PetscCall(PetscMalloc1(bi[mbs], &bj));
  for (PetscInt r = 0; r < mbs; r++) std::copy(st->cols[r].begin(), st->cols[r].end(), bj + bi[r]);
  a->staging = nullptr; /* keep the values while the layout is built */
  PetscCall(MatSeqBinBCSRBuildLayout(A, bi, bj));
  for (PetscInt r = 0; r < mbs; r++) {
    const auto &v = st->vals[r];
    for (PetscInt k = 0; k < bi[r + 1] - bi[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k);
      for (PetscInt e = 0; e < bs2; e++)
        BinBCSRSetValue(a, BinBCSRValueIndex(s, e, a->bw, bs2), v[k * bs2 + e]);
    }
  }
  delete st;
  PetscCall(PetscFree(bi));
  PetscCall(PetscFree(bj));
  PetscFunctionReturn(0);
}

PetscErrorCode MatAssemblyEnd_SeqBinBCSR(Mat A, MatAssemblyType type)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  if (type == MAT_FLUSH_ASSEMBLY) PetscFunctionReturn(0);
  if (!a->built && !a->staging) PetscCall(MatSetUp_SeqBinBCSR(A)); /* assembled without any entry */
  if (!a->built) PetscCall(MatSeqBinBCSRBuildFromStaging(A));
  PetscFunctionReturn(0);
}

/* The staged values of block (br, bc), inserted as zeros where the pattern lacks it; *blk is null
   where the block is new and new locations are ignored. (prow, pcol) name the entry in messages. */
static PetscErrorCode StagingBlock(Mat_SeqBinBCSR *a, PetscInt br, PetscInt bc, PetscInt prow, PetscInt pcol,
                                   MatScalar **blk)
{
  BinBCSRStaging *st   = a->staging;
  auto           &cols = st->cols[br];
  auto            it   = std::lower_bound(cols.begin(), cols.end(), bc);
  const size_t    k    = (size_t)(it - cols.begin());

  PetscFunctionBegin;
  *blk = nullptr;
  if (it == cols.end() || *it != bc) {
    if (a->nonew == 1) PetscFunctionReturn(0);
    PetscCheck(a->nonew != -1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Inserting a new nonzero at (%" PetscInt_FMT ", %" PetscInt_FMT
               ") in the matrix (MAT_NEW_NONZERO_LOCATION_ERR is set)",
               prow, pcol);
    PetscCheck(!(a->nonew == -2 && !st->prealloc.empty() && (PetscInt)cols.size() >= st->prealloc[br]),
               PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "New nonzero at (%" PetscInt_FMT ", %" PetscInt_FMT
               ") exceeds the preallocation (MAT_NEW_NONZERO_ALLOCATION_ERR is set)",
               prow, pcol);
    cols.insert(it, bc);
    st->vals[br].insert(st->vals[br].begin() + k * a->bs2, (size_t)a->bs2, 0.0);
  }
  *blk = st->vals[br].data() + k * a->bs2;
  PetscFunctionReturn(0);
}

/* The block the last StagingAdd wrote (blk null: ignored): a scalar row of a 3x3-block operator
   hits each block 3 times in a row. Only the last block is kept, so an insertion that moves the row's
   values cannot leave it pointing at stale memory: the insertion is the block found last. */
struct StagingLast {
  PetscInt   br = -1, bc = -1;
  MatScalar *blk = nullptr;
};

/* One value into the staged pattern (ignored where the location is new and new ones are ignored). */
static PetscErrorCode StagingAdd(Mat_SeqBinBCSR *a, PetscInt br, PetscInt bc, PetscInt e, PetscScalar v,
                                 InsertMode mode, PetscInt prow, PetscInt pcol, StagingLast &last)
{
  PetscFunctionBegin;
  if (last.br != br || last.bc != bc) {
    PetscCall(StagingBlock(a, br, bc, prow, pcol, &last.blk));
    last.br = br;
    last.bc = bc;
  }
  if (last.blk) last.blk[e] = (mode == ADD_VALUES) ? last.blk[e] + v : v;
  PetscFunctionReturn(0);
}

/* One value into the frozen layout. `cache` keeps the last block found: element matrices hit the
   same block bs times in a row. */
static inline PetscErrorCode LayoutAdd(Mat_SeqBinBCSR *a, PetscInt br, PetscInt bc, PetscInt e, PetscScalar v,
                                       InsertMode mode, PetscInt prow, PetscInt pcol, PetscInt cache[3])
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
    PetscCheck(
      a->nonew == 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
      "New nonzero at (%" PetscInt_FMT ", %" PetscInt_FMT
      "): the pattern of a MATSEQBINBCSR matrix is frozen at its first final assembly (use MatSetOption(A, MAT_NEW_NONZERO_LOCATIONS, PETSC_FALSE) to ignore new locations)",
      prow, pcol);
    PetscFunctionReturn(0);
  }
  {
    const PetscInt vi = BinBCSRValueIndex(s, e, a->bw, a->bs2);
    if (a->val) a->val[vi] = (mode == ADD_VALUES) ? a->val[vi] + v : v;
    else a->valf[vi] = (float)((mode == ADD_VALUES) ? (PetscScalar)a->valf[vi] + v : v);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetValues_SeqBinBCSR(Mat A, PetscInt m, const PetscInt im[], PetscInt n,
                                       const PetscInt in[], const PetscScalar v[], InsertMode mode)
{
  Mat_SeqBinBCSR *a        = (Mat_SeqBinBCSR *)A->data;
  PetscInt        cache[3] = {-1, -1, -1};
  StagingLast     last;

  PetscFunctionBegin;
  if (!a->built && !a->staging) PetscCall(MatSetUp_SeqBinBCSR(A));
  PetscCheck(PetscAbs(A->rmap->bs) == a->bs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
             "Block size changed from %" PetscInt_FMT " to %" PetscInt_FMT " after preallocation", a->bs,
             A->rmap->bs);
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt r = im[i];
    if (r < 0) continue;
    PetscCheck(r < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", r, A->rmap->n);
    const PetscInt br = r / a->bs, ri = r % a->bs;
    for (PetscInt j = 0; j < n; j++) {
      const PetscInt c = in[j];
      if (c < 0) continue;
      PetscCheck(c < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "Column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", c, A->cmap->n);
      const PetscScalar x  = v ? (a->roworiented ? v[i * n + j] : v[j * m + i]) : 0.0;
      const PetscInt    bc = c / a->bs, e = ri * a->bs + c % a->bs;
      if (a->sym && bc < br) continue; /* symmetric storage: the lower triangle is implied */
      if (a->built) PetscCall(LayoutAdd(a, br, bc, e, x, mode, r, c, cache));
      else PetscCall(StagingAdd(a, br, bc, e, x, mode, r, c, last));
    }
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetValuesBlocked_SeqBinBCSR(Mat A, PetscInt m, const PetscInt im[], PetscInt n,
                                              const PetscInt in[], const PetscScalar v[], InsertMode mode)
{
  Mat_SeqBinBCSR *a        = (Mat_SeqBinBCSR *)A->data;
  PetscInt        cache[3] = {-1, -1, -1}, bs;

  PetscFunctionBegin;
  if (!a->built && !a->staging) PetscCall(MatSetUp_SeqBinBCSR(A));
  PetscCheck(PetscAbs(A->rmap->bs) == a->bs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP,
             "Block size changed from %" PetscInt_FMT " to %" PetscInt_FMT " after preallocation", a->bs,
             A->rmap->bs);
  bs = a->bs;
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt br = im[i];
    if (br < 0) continue;
    PetscCheck(br < a->mbs, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Block row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", br, a->mbs);
    for (PetscInt j = 0; j < n; j++) {
      const PetscInt bc = in[j];
      if (bc < 0) continue;
      PetscCheck(bc < a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "Block column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", bc, a->nbs);
      if (a->sym && bc < br) continue; /* symmetric storage: the lower triangle is implied */
      MatScalar *blk = nullptr;        /* before the layout: the block's staged values, found once */
      if (!a->built) {
        PetscCall(StagingBlock(a, br, bc, br * bs, bc * bs, &blk));
        if (!blk) continue;
      }
      for (PetscInt ii = 0; ii < bs; ii++) {
        for (PetscInt jj = 0; jj < bs; jj++) {
          const PetscInt    prow = i * bs + ii, pcol = j * bs + jj;
          const PetscScalar x =
            v ? (a->roworiented ? v[prow * (n * bs) + pcol] : v[pcol * (m * bs) + prow]) : 0.0;
          if (blk) blk[ii * bs + jj] = (mode == ADD_VALUES) ? blk[ii * bs + jj] + x : x;
          else PetscCall(LayoutAdd(a, br, bc, ii * bs + jj, x, mode, br * bs + ii, bc * bs + jj, cache));
        }
      }
    }
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatGetValues_SeqBinBCSR(Mat A, PetscInt m, const PetscInt im[], PetscInt n,
                                       const PetscInt in[], PetscScalar v[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatGetValues needs an assembled MATSEQBINBCSR matrix");
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt r = im[i];
    if (r < 0) continue;
    PetscCheck(r < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", r, A->rmap->n);
    for (PetscInt j = 0; j < n; j++) {
      const PetscInt c = in[j];
      if (c < 0) continue;
      PetscCheck(c < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "Column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", c, A->cmap->n);
      if (a->sym && c / a->bs < r / a->bs) { /* the transposed entry of the stored upper block */
        const PetscInt s = MatSeqBinBCSRFindSlot(a, c / a->bs, r / a->bs);
        v[i * n + j] =
          s < 0 ? 0.0
                : BinBCSRGetValue(a, BinBCSRValueIndex(s, (c % a->bs) * a->bs + r % a->bs, a->bw, a->bs2));
        continue;
      }
      const PetscInt s = MatSeqBinBCSRFindSlot(a, r / a->bs, c / a->bs);
      v[i * n + j] =
        s < 0 ? 0.0
              : BinBCSRGetValue(a, BinBCSRValueIndex(s, (r % a->bs) * a->bs + c % a->bs, a->bw, a->bs2));
    }
  }
  PetscFunctionReturn(0);
}
