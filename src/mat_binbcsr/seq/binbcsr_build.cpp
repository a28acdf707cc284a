/* MATSEQBINBCSR: the bin layout built from a block pattern (at the first final assembly, and by
   conversion, load, duplication), the lower-part index of symmetric storage, the slot lookup, and a
   new matrix laid out for a pattern. */
#include "binbcsr.h"
#include <cstdint>
#include <sys/mman.h>
#include <algorithm>
#include <vector>

PetscInt MatSeqBinBCSRFindSlot(const Mat_SeqBinBCSR *a, PetscInt brow, PetscInt bcol)
{
  PetscInt lo = 0, hi = a->row_nz[brow];
  if (a->sym && bcol < brow) return -1; /* not stored: the transposed block (bcol, brow) is */
  while (lo < hi) {
    const PetscInt mid = (lo + hi) / 2, s = BinBCSRSlot(a, brow, mid), c = a->col[s];
    if (c == bcol) return s;
    if (c < bcol) lo = mid + 1;
    else hi = mid;
  }
  return -1;
}

/* The block pattern given to MatSeqBinBCSRBuildLayout (CSR over block rows, bi[mbs + 1], bj[]) is
   checked before either layout is built from it: the builds trust every column and row length. */
static PetscErrorCode CheckPattern(const Mat_SeqBinBCSR *a, const PetscInt bi[], const PetscInt bj[])
{
  PetscFunctionBegin;
  for (PetscInt r = 0; r < a->mbs; r++) {
    const PetscInt n = bi[r + 1] - bi[r];
    PetscCheck(n >= 0 && n <= a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_CORRUPT,
               "Block row %" PetscInt_FMT " has %" PetscInt_FMT " blocks", r, n);
    for (PetscInt p = bi[r]; p < bi[r + 1]; p++) {
      PetscCheck(bj[p] >= 0 && bj[p] < a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "Block column %" PetscInt_FMT " of block row %" PetscInt_FMT
                 " out of range [0, %" PetscInt_FMT ")",
                 bj[p], r, a->nbs);
      PetscCheck(p == bi[r] || bj[p] > bj[p - 1], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
                 "Block columns of block row %" PetscInt_FMT " are not sorted and unique", r);
    }
  }
  PetscFunctionReturn(0);
}

/* Asks for transparent huge pages for the 2 MiB-aligned part of a fresh array of `bytes` at p, before
   its pages are first touched (a no-op when the kernel has them off, and for arrays under 4 MiB).
   Why: a product streams the values and columns once; with 4 KiB pages it takes a TLB miss every
   4 KiB and the hardware prefetchers stop at each page boundary. On a Zen 4 core (Linux THP mode
   madvise, the Debian default) the 48^3 stencil's products ran 10-34% faster with 2 MiB pages. */
static void HugePages(void *p, size_t bytes)
{
#if defined(MADV_HUGEPAGE)
  constexpr uintptr_t huge = (uintptr_t)2 << 20;
  if (bytes < 2 * huge) return;
  const uintptr_t b = ((uintptr_t)p + huge - 1) & ~(huge - 1), e = ((uintptr_t)p + bytes) & ~(huge - 1);
  if (e > b) (void)madvise((void *)b, e - b, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

void *MatSeqBinBCSRMapHuge(size_t bytes, void **base, size_t *length)
{
#if defined(MADV_HUGEPAGE)
  constexpr size_t huge = (size_t)2 << 20;
  if (bytes >= 2 * huge) {
    const size_t map = (bytes + huge - 1) / huge * huge + huge; /* room to align the start */
    void        *m   = mmap(nullptr, map, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m != MAP_FAILED) {
      char *start = (char *)(((uintptr_t)m + huge - 1) & ~(uintptr_t)(huge - 1));
      (void)madvise(start, map - (size_t)(start - (char *)m), MADV_HUGEPAGE);
      *base   = m;
      *length = map;
      return start;
    }
  }
#endif
  (void)bytes;
  *base   = nullptr;
  *length = 0;
  return nullptr;
}

void MatSeqBinBCSRUnmapHuge(void *base, size_t length)
{
  if (base) (void)munmap(base, length);
}

/* The value arrays (binbcsr.h: 64-byte aligned inside val_mem). Of 4 MiB and more they get a mapping
   of their own (val_map bytes), 2 MiB-aligned and marked for huge pages before any page is touched:
   from malloc they often reused heap pages a freed matrix had faulted in with 4 KiB pages, which the
   hint cannot change, and then the same layout ran 1.2-1.45x slower than a copy made later in the
   program (the 32^3 stencil, symmetric storage, after other matrices were freed). */
PetscErrorCode MatSeqBinBCSRReleaseValues_Private(void *mem, size_t map)
{
  PetscFunctionBegin;
#if defined(MADV_HUGEPAGE)
  if (map) {
    PetscCheck(munmap(mem, map) == 0, PETSC_COMM_SELF, PETSC_ERR_SYS, "munmap of the value array failed");
    PetscFunctionReturn(0);
  }
#endif
  (void)map;
  PetscCall(PetscFree(mem));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRFreeValues_Private(Mat_SeqBinBCSR *a)
{
  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRReleaseValues_Private(a->val_mem, a->val_map));
  a->val_mem = nullptr;
  a->val_map = 0;
  a->val     = nullptr;
  a->valf    = nullptr;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRAllocValues_Private(Mat_SeqBinBCSR *a, MatBinBCSRPrecision p, size_t nv,
                                                PetscBool zero)
{
  constexpr size_t line  = 64;
  const size_t     bytes = nv * (p == MAT_BINBCSR_PRECISION_SINGLE ? sizeof(float) : sizeof(MatScalar));
  char            *mem = nullptr, *v = nullptr;

  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRFreeValues_Private(a));
  {
    void  *base;
    size_t length;
    v = (char *)MatSeqBinBCSRMapHuge(bytes, &base, &length);
    if (v) { /* else malloc below */
      mem        = (char *)base;
      a->val_map = length;
      zero       = PETSC_FALSE; /* a fresh mapping reads as zero */
    }
  }
  if (!mem) {
    PetscCall(PetscMalloc1(bytes + line, &mem));
    v = mem + (line - (size_t)((uintptr_t)mem % line)) % line;
  }
  if (zero) PetscCall(PetscMemzero(v, bytes));
  a->val_mem = mem;
  if (p == MAT_BINBCSR_PRECISION_SINGLE) a->valf = (float *)v;
  else a->val = (MatScalar *)v;
  PetscFunctionReturn(0);
}

/* The symmetric-storage part of MatSeqBinBCSRBuildLayout: bins ordered by the colouring. */
static PetscErrorCode MatSeqBinBCSRBuildLayoutSym(Mat A, const PetscInt bi[], const PetscInt bj[])
{
  Mat_SeqBinBCSR       *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt        bw = a->bw, mbs = a->mbs, nbins = a->nbins;
  std::vector<PetscInt> slot_col, entry_k, colid(a->nbs, -1), allcol;

  PetscFunctionBegin;
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Symmetric storage needs a square matrix, this one is %" PetscInt_FMT " x %" PetscInt_FMT,
             A->rmap->n, A->cmap->n);
  PetscCall(CheckPattern(a, bi, bj));
  PetscCall(PetscMalloc1(mbs + 1, &a->row_off));
  a->row_off[0] = 0;
  for (PetscInt r = 0; r < mbs; r++) {
    PetscInt n = 0;
    for (PetscInt p = bi[r]; p < bi[r + 1]; p++) n += bj[p] >= r;
    a->row_nz[r]      = n;
    a->row_off[r + 1] = a->row_off[r] + n;
    a->max_row_nz     = PetscMax(a->max_row_nz, n);
  }
  a->nz = a->row_off[mbs];
  PetscCall(PetscMalloc1(a->nz, &a->real_slot));
  for (PetscInt b = 0; b < nbins; b++) {
    const PetscInt r0 = b * bw;
    entry_k.clear();
    const PetscInt len = MatSeqBinBCSRColourBin(bw, r0, mbs, bi, bj, slot_col, entry_k, colid);
    PetscCheck((PetscInt64)a->bin_start[b] + (PetscInt64)len * bw <= PETSC_MAX_INT / PetscMax(a->bs2, 1),
               PETSC_COMM_SELF, PETSC_ERR_SUP, "Matrix too large for 32-bit slot indices");
    a->bin_start[b + 1] = a->bin_start[b] + len * bw;
    allcol.insert(allcol.end(), slot_col.begin(), slot_col.end());
    size_t e = 0;
    for (PetscInt r = r0; r < PetscMin(mbs, r0 + bw); r++) {
      a->diag_slot[r] = -1;
      for (PetscInt k = 0; k < a->row_nz[r]; k++, e++) {
        const PetscInt s                = a->bin_start[b] + entry_k[e] * bw + (r - r0);
        a->real_slot[a->row_off[r] + k] = s;
        if (allcol[s] == r) a->diag_slot[r] = s;
      }
    }
  }
  a->nslots = a->bin_start[nbins];
  PetscCall(PetscMalloc1(a->nslots, &a->col));
  HugePages(a->col, (size_t)a->nslots * sizeof(PetscInt));
  std::copy(allcol.begin(), allcol.end(), a->col);
  PetscCall(MatSeqBinBCSRAllocValues_Private(a, a->precision, (size_t)a->nslots * a->bs2, PETSC_TRUE));
  PetscCall(PetscMalloc2((size_t)PetscMax(a->nbs, 1) * a->bs, &a->rowbuf_cols,
                         (size_t)PetscMax(a->nbs, 1) * a->bs,
                         &a->rowbuf_vals)); /* a full row, both triangles */
  a->built        = PETSC_TRUE;
  A->preallocated = PETSC_TRUE;
  A->nonzerostate++;
  PetscCall(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRBuildLowerIndex(Mat_SeqBinBCSR *a)
{
  PetscInt *fill;

  PetscFunctionBegin;
  if (a->lower_off) PetscFunctionReturn(0);
  PetscCall(PetscCalloc1(a->mbs + 1, &a->lower_off));
  for (PetscInt r = 0; r < a->mbs; r++)
    for (PetscInt k = 0; k < a->row_nz[r]; k++) {
      const PetscInt c = a->col[BinBCSRSlot(a, r, k)];
      if (c != r) a->lower_off[c + 1]++;
    }
  for (PetscInt r = 0; r < a->mbs; r++) a->lower_off[r + 1] += a->lower_off[r];
  PetscCall(PetscMalloc1(2 * PetscMax(a->lower_off[a->mbs], 1), &a->lower_slot));
  PetscCall(PetscMalloc1(a->mbs, &fill));
  for (PetscInt r = 0; r < a->mbs; r++) fill[r] = a->lower_off[r];
  for (PetscInt r = 0; r < a->mbs; r++) /* rows ascending: each lower list comes out in ascending c */
    for (PetscInt k = 0; k < a->row_nz[r]; k++) {
      const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
      if (c != r) {
        a->lower_slot[2 * fill[c]]     = s;
        a->lower_slot[2 * fill[c] + 1] = r;
        fill[c]++;
      }
    }
  PetscCall(PetscFree(fill));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRBuildLayout(Mat A, const PetscInt bi[], const PetscInt bj[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        bw, mbs, nbins;

  PetscFunctionBegin;
  PetscCall(MatSeqBinBCSRResetLayout(A));
  if (!a->bw_set) a->bw = BinBCSRDefaultBinWidth(a->bs);
  if (!a->streams_set) a->streams = BINBCSR_DEFAULT_STREAMS;
  if (!a->prefetch_set) a->prefetch = BINBCSR_DEFAULT_PREFETCH;
  PetscCall(MatSeqBinBCSRTune(A, bi, bj)); /* outside the build's log event: it has its own */
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_BuildLayout, A, 0, 0, 0));
  bw       = a->bw;
  mbs      = a->mbs;
  nbins    = (mbs + bw - 1) / bw;
  a->nbins = nbins;
  PetscCall(PetscMalloc1(nbins + 1, &a->bin_start));
  PetscCall(PetscMalloc1(mbs, &a->row_nz));
  PetscCall(PetscMalloc1(mbs, &a->diag_slot));
  a->bin_start[0] = 0;
  a->nz           = 0;
  a->max_row_nz   = 0;
  if (a->sym) {
    PetscCall(MatSeqBinBCSRBuildLayoutSym(A, bi, bj));
    PetscCall(PetscLogEventEnd(MAT_BinBCSR_BuildLayout, A, 0, 0, 0));
    PetscFunctionReturn(0);
  }
  PetscCall(CheckPattern(a, bi, bj));
  for (PetscInt r = 0; r < mbs; r++) {
    const PetscInt n = bi[r + 1] - bi[r];
    a->row_nz[r]     = n;
    a->nz += n;
    a->max_row_nz = PetscMax(a->max_row_nz, n);
  }
  {
    const long nslots = binbcsr::bin_starts<PetscInt>(bi, mbs, bw, a->bin_start);
    PetscCheck(nslots <= PETSC_MAX_INT / PetscMax(a->bs2, 1), PETSC_COMM_SELF, PETSC_ERR_SUP,
               "Matrix too large for 32-bit slot indices");
    a->nslots = (PetscInt)nslots;
  }
  PetscCall(PetscMalloc1(a->nslots, &a->col));
  HugePages(a->col, (size_t)a->nslots * sizeof(PetscInt));
  PetscCall(MatSeqBinBCSRAllocValues_Private(a, a->precision, (size_t)a->nslots * a->bs2, PETSC_TRUE));
  binbcsr::bin_columns<PetscInt>(bi, bj, mbs, bw, a->bin_start, a->col, a->diag_slot);
  PetscCall(PetscMalloc2((size_t)a->max_row_nz * a->bs, &a->rowbuf_cols, (size_t)a->max_row_nz * a->bs,
                         &a->rowbuf_vals));
  a->built        = PETSC_TRUE;
  A->preallocated = PETSC_TRUE; /* a layout is an allocation, however it was built (convert, load, ...) */
  A->nonzerostate++;
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_BuildLayout, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRCreateWithPattern(Mat A, PetscBool transposed, const PetscInt bi[],
                                              const PetscInt bj[], Mat *B)
{
  const Mat_SeqBinBCSR *a    = (const Mat_SeqBinBCSR *)A->data;
  PetscLayout           rmap = transposed ? A->cmap : A->rmap, cmap = transposed ? A->rmap : A->cmap;

  PetscFunctionBegin;
  PetscCall(MatCreate(PetscObjectComm((PetscObject)A), B));
  PetscCall(MatSetSizes(*B, rmap->n, cmap->n, rmap->N, cmap->N));
  PetscCall(MatSetBlockSizes(*B, PetscAbs(rmap->bs), PetscAbs(cmap->bs)));
  PetscCall(MatSetType(*B, MATSEQBINBCSR));
  PetscCall(MatBinBCSRSetBinWidth(*B, a->bw));
  PetscCall(MatBinBCSRSetPrecision(*B, a->precision));
  PetscCall(MatBinBCSRSetSymmetricStorage(*B, a->sym));
  PetscCall(PetscLayoutSetUp((*B)->rmap));
  PetscCall(PetscLayoutSetUp((*B)->cmap));
  PetscCall(MatSeqBinBCSRBuildLayout(*B, bi, bj));
  (*B)->preallocated = PETSC_TRUE;
  PetscFunctionReturn(0);
}
