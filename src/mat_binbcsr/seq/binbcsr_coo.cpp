/* MATSEQBINBCSR COO assembly. Preallocation builds the bin layout straight from the COO pattern and,
   for every stored value (slot, entry), the list of COO entries that sum into it (jmap/perm, as PETSc's
   seqaij does per nonzero). The refill then writes each value once, in storage order, by gathering:
   no atomics, no search, no sort per call.
   When the stored blocks are sums of whole COO blocks (a driver that lists 3x3 blocks), the refill
   goes by blocks instead (coo_slot_ptr/coo_slot_src, built at the first refill).
   With the COO mirror (MatBinBCSRSetCOOMirror) every entry (i, j) of an off-diagonal block also
   fills (j, i): the list is extended by those transposed entries at preallocation, and their
   places in coo_perm then name the entry they mirror, so the refill reads the caller's value twice
   and needs no copy. */
#include "binbcsr.h"
#include "../kernels/binbcsr_kernels.h"
#include <algorithm>
#include <cstdint>
#include <vector>

namespace {
PetscErrorCode BuildSlotMap(Mat A, const PetscInt *perm, long n);
}

/* Sorts each block row's keys ((block column << 32) | source, rows at rowptr) and lists its distinct
   block columns: the block CSR pattern bi, bj (bj as long as the keys). */
static void SortedPattern(PetscInt mbs, const PetscInt *rowptr, uint64_t *key, PetscInt *bi, PetscInt *bj)
{
  bi[0] = 0;
  for (PetscInt r = 0; r < mbs; r++) {
    std::sort(key + rowptr[r], key + rowptr[r + 1]);
    PetscInt nu = bi[r];
    for (PetscInt p = rowptr[r]; p < rowptr[r + 1]; p++) {
      const PetscInt c = (PetscInt)(key[p] >> 32);
      if (nu == bi[r] || bj[nu - 1] != c) bj[nu++] = c;
    }
    bi[r + 1] = nu;
  }
}

static PetscErrorCode PreallocateCOO(Mat A, PetscCount n, const PetscInt ci[], const PetscInt cj[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        bs, mbs, nvalid = 0, *rowptr, *bi, *bj, *vk, *fill;
  uint64_t       *key; /* (block column << 32) | coo index, sorted per block row */

  PetscFunctionBegin;
  PetscCheck(n <= PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_SUP,
             "%" PetscCount_FMT " COO entries overflow the 32-bit indices of MATSEQBINBCSR", n);
  PetscCall(MatSeqBinBCSRSetSizes(A));
  bs  = a->bs;
  mbs = a->mbs;

  /* negative indices drop the entry, out-of-range ones are errors (checked before any allocation) */
  for (PetscCount k = 0; k < n; k++) {
    const PetscInt i = ci[k], j = cj[k];
    if (i < 0 || j < 0) continue;
    PetscCheck(i < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "COO entry %" PetscCount_FMT ": row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", k,
               i, A->rmap->n);
    PetscCheck(j < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "COO entry %" PetscCount_FMT ": column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")",
               k, j, A->cmap->n);
  }
  /* block rows of the valid entries */
  PetscCall(PetscCalloc1(mbs + 1, &rowptr));
  for (PetscCount k = 0; k < n; k++) {
    const PetscInt i = ci[k], j = cj[k];
    if (i < 0 || j < 0) continue;
    rowptr[i / bs + 1]++;
    nvalid++;
  }
  for (PetscInt r = 0; r < mbs; r++) rowptr[r + 1] += rowptr[r];
  PetscCall(PetscMalloc1(nvalid, &key));
  PetscCall(PetscMalloc1(mbs, &fill));
  for (PetscInt r = 0; r < mbs; r++) fill[r] = rowptr[r];
  for (PetscCount k = 0; k < n; k++) {
    const PetscInt i = ci[k], j = cj[k];
    if (i < 0 || j < 0) continue;
    key[fill[i / bs]++] = ((uint64_t)(j / bs) << 32) | (uint64_t)k;
  }
  PetscCall(PetscFree(fill));

  /* the unique block columns of each row: the block CSR pattern */
  PetscCall(PetscMalloc1(mbs + 1, &bi));
  PetscCall(PetscMalloc1(nvalid, &bj));
  SortedPattern(mbs, rowptr, key, bi, bj);
  PetscCall(MatSeqBinBCSRBuildLayout(A, bi, bj)); /* sets a->bs, a->bw, ... and zero values */

  /* row-order value number q (see binbcsr.h) of every COO entry (-1: dropped) */
  PetscCall(PetscMalloc1(n, &vk));
  for (PetscCount k = 0; k < n; k++) vk[k] = -1;
  {
    PetscInt qbase = 0;
    for (PetscInt r = 0; r < mbs; r++) {
      const PetscInt nr = a->row_nz[r];
      PetscInt       kk = -1, prev = -1;
      for (PetscInt p = rowptr[r]; p < rowptr[r + 1]; p++) {
        const PetscInt c = (PetscInt)(key[p] >> 32), k = (PetscInt)(key[p] & 0xffffffffu);
        if (a->sym && c < r) continue; /* symmetric storage: the lower triangle maps to no slot */
        if (c != prev) {
          kk++;
          prev = c;
        }
        vk[k] = qbase + (ci[k] % bs) * nr * bs + kk * bs + cj[k] % bs;
      }
      qbase += nr * a->bs2;
    }
  }
  PetscCall(PetscFree(key));
  PetscCall(PetscFree(rowptr));
  PetscCall(PetscFree(bi));
  PetscCall(PetscFree(bj));

  /* jmap: CSR over the value numbers; perm filled in COO order, so each value reads ascending entries */
  {
    const PetscInt nq = a->nz * a->bs2;
    PetscCall(PetscCalloc1(nq + 1, &a->coo_jmap));
    PetscCall(PetscMalloc1(nvalid, &a->coo_perm));
    for (PetscCount k = 0; k < n; k++)
      if (vk[k] >= 0) a->coo_jmap[vk[k] + 1]++;
    for (PetscInt q = 0; q < nq; q++) a->coo_jmap[q + 1] += a->coo_jmap[q];
    PetscCall(PetscMalloc1(nq, &fill));
    for (PetscInt q = 0; q < nq; q++) fill[q] = a->coo_jmap[q];
    for (PetscCount k = 0; k < n; k++)
      if (vk[k] >= 0) a->coo_perm[fill[vk[k]]++] = (PetscInt)k;
    PetscCall(PetscFree(fill));
  }
  PetscCall(PetscFree(vk));
  a->coo_n = n;
  PetscFunctionReturn(0);
}

/* The preallocation of a list made of whole blocks (what the drivers give): entries t bs2 .. t bs2 +
   bs2 - 1 are block t, (I, J), in row-major order, every index in range. The sort and the temporaries
   go by blocks, a bs2-th of PreallocateCOO's (linear_38k_thesis: 0.84 M blocks against 7.5 M entries,
   15 M with the mirror, and 0.3 GB of temporaries), and the maps come out as PreallocateCOO makes them
   for the same list: each value's entries in ascending order, the mirrored ones after the others and
   named by the entry they mirror (tests/unit/mat_binbcsr/mat_core/coo_blocks.cpp). *done is false, and
   nothing is built, for any other list (negative or out-of-range indices included: PreallocateCOO
   drops or reports them). */
static PetscErrorCode PreallocateCOOBlocks(Mat A, PetscCount n, const PetscInt ci[], const PetscInt cj[],
                                           PetscBool *done)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  *done = PETSC_FALSE;
  PetscCall(MatSeqBinBCSRSetSizes(A));
  const PetscInt bs = a->bs, bs2 = a->bs2, mbs = a->mbs, nbs = a->nbs;
  if (bs < 2 || n <= 0 || n % bs2 || n > PETSC_MAX_INT) PetscFunctionReturn(0);
  const PetscInt nb = (PetscInt)(n / bs2);
  for (PetscInt t = 0; t < nb; t++) {
    const PetscInt *i = ci + (size_t)t * bs2, *j = cj + (size_t)t * bs2;
    if (i[0] < 0 || j[0] < 0 || i[0] % bs || j[0] % bs || i[0] / bs >= mbs || j[0] / bs >= nbs)
      PetscFunctionReturn(0);
    for (PetscInt e = 1; e < bs2; e++)
      if (i[e] != i[0] + e / bs || j[e] != j[0] + e % bs) PetscFunctionReturn(0);
  }
  /* sources: block t < nb as listed, nb + m the m-th mirrored block (mirror_of[m] its original) */
  std::vector<PetscInt> mirror_of;
  if (a->coo_mirror)
    for (PetscInt t = 0; t < nb; t++)
      if (ci[(size_t)t * bs2] != cj[(size_t)t * bs2]) mirror_of.push_back(t);
  const PetscInt        nsrc = nb + (PetscInt)mirror_of.size();
  std::vector<PetscInt> rowptr(mbs + 1, 0), fill;
  std::vector<uint64_t> key(nsrc); /* (block column << 32) | source, sorted per block row */
  const auto            row_of = [&](PetscInt s) {
    return s < nb ? ci[(size_t)s * bs2] / bs : cj[(size_t)mirror_of[s - nb] * bs2] / bs;
  };
  const auto col_of = [&](PetscInt s) {
    return s < nb ? cj[(size_t)s * bs2] / bs : ci[(size_t)mirror_of[s - nb] * bs2] / bs;
  };
  for (PetscInt s = 0; s < nsrc; s++) rowptr[row_of(s) + 1]++;
  for (PetscInt r = 0; r < mbs; r++) rowptr[r + 1] += rowptr[r];
  fill.assign(rowptr.begin(), rowptr.end() - 1);
  for (PetscInt s = 0; s < nsrc; s++) key[fill[row_of(s)]++] = ((uint64_t)col_of(s) << 32) | (uint64_t)s;
  PetscInt *bi, *bj;
  PetscCall(PetscMalloc1(mbs + 1, &bi));
  PetscCall(PetscMalloc1(PetscMax(nsrc, 1), &bj));
  SortedPattern(mbs, rowptr.data(), key.data(), bi, bj);
  PetscCall(MatSeqBinBCSRBuildLayout(A, bi, bj)); /* sets a->row_nz, a->nz, ... and zero values */
  PetscCall(PetscFree(bi));
  PetscCall(PetscFree(bj));

  /* jmap and perm in value order q (see binbcsr.h): row r, point row i, stored block kk, column j; the
     entry (i, j) of source s is s bs2 + i bs + j listed, t bs2 + j bs + i for a block mirrored from t */
  const PetscInt nq    = a->nz * bs2;
  PetscInt       nperm = 0;
  for (PetscInt r = 0; r < mbs; r++)
    for (PetscInt p = rowptr[r]; p < rowptr[r + 1]; p++) nperm += !(a->sym && (PetscInt)(key[p] >> 32) < r);
  PetscCall(PetscMalloc1(nq + 1, &a->coo_jmap));
  PetscCall(PetscMalloc1(PetscMax((PetscCount)nperm * bs2, (PetscCount)1), &a->coo_perm));
  PetscInt q = 0, w = 0;
  a->coo_jmap[0] = 0;
  for (PetscInt r = 0; r < mbs; r++) {
    PetscInt p0 = rowptr[r];
    if (a->sym) /* symmetric storage: the lower triangle maps to no value */
      while (p0 < rowptr[r + 1] && (PetscInt)(key[p0] >> 32) < r) p0++;
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt p = p0; p < rowptr[r + 1];) { /* the stored blocks of the row, in column order */
        PetscInt p1 = p + 1;
        while (p1 < rowptr[r + 1] && (key[p1] >> 32) == (key[p] >> 32)) p1++;
        for (PetscInt j = 0; j < bs; j++, q++) {
          for (PetscInt k = p; k < p1; k++) {
            const PetscInt src = (PetscInt)(key[k] & 0xffffffffu);
            a->coo_perm[w++]   = src < nb ? src * bs2 + i * bs + j : mirror_of[src - nb] * bs2 + j * bs + i;
          }
          a->coo_jmap[q + 1] = w;
        }
        p = p1;
      }
  }
  PetscCheck(q == nq, PETSC_COMM_SELF, PETSC_ERR_PLIB,
             "COO block map: %" PetscInt_FMT " values of %" PetscInt_FMT, q, nq);
  a->coo_n = n;
  *done    = PETSC_TRUE;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetPreallocationCOO_SeqBinBCSR(Mat A, PetscCount n, const PetscInt ci[],
                                                 const PetscInt cj[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        rbs, cbs;

  PetscFunctionBegin;
  if (a->coo_mirror) {
    PetscCall(PetscLayoutSetUp(A->rmap));
    PetscCall(PetscLayoutSetUp(A->cmap));
    PetscCall(MatGetBlockSizes(A, &rbs, &cbs));
    PetscCheck(A->rmap->n == A->cmap->n && rbs == cbs, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
               "The COO mirror needs a square matrix with equal block sizes, this one is %" PetscInt_FMT
               " x %" PetscInt_FMT,
               A->rmap->n, A->cmap->n);
  }
  {
    PetscBool blocks;
    PetscCall(PreallocateCOOBlocks(A, n, ci, cj, &blocks));
    if (blocks) {
      PetscCall(BuildSlotMap(A, a->coo_perm, (long)n));
      PetscFunctionReturn(0);
    }
  }
  if (!a->coo_mirror) {
    PetscCall(PreallocateCOO(A, n, ci, cj));
    PetscCall(BuildSlotMap(A, a->coo_perm, (long)n));
    PetscFunctionReturn(0);
  }
  /* entries n + t: the transposes of the off-diagonal-block entries mirror_of[t] (the original
     entries come first, so a bad index is reported by its own position) */
  std::vector<PetscInt> ei(ci, ci + n), ej(cj, cj + n), mirror_of;
  for (PetscCount k = 0; k < n; k++)
    if (ci[k] >= 0 && cj[k] >= 0 && ci[k] / rbs != cj[k] / rbs) {
      ei.push_back(cj[k]);
      ej.push_back(ci[k]);
      mirror_of.push_back((PetscInt)k);
    }
  PetscCall(PreallocateCOO(A, (PetscCount)ei.size(), ei.data(), ej.data()));
  const PetscInt nperm = a->coo_jmap[a->nz * a->bs2];
  for (PetscInt t = 0; t < nperm; t++)
    if (a->coo_perm[t] >= n) a->coo_perm[t] = mirror_of[a->coo_perm[t] - n];
  a->coo_n = n;
  PetscCall(BuildSlotMap(A, a->coo_perm, (long)n));
  PetscFunctionReturn(0);
}

namespace {
/* Refill in row order q (CSR order: gathers from the same elements follow each other); the writes
   stay inside one bin's tiles at a time. perm indices below n read v, the others recv (see
   binbcsr::coo_gather). */
template <int BS, bool ADD, typename V, typename S>
void coo_refill(const Mat_SeqBinBCSR *a, V *val, const PetscInt *perm, const S *v, long n,
                const PetscScalar *recv)
{
  const PetscInt  bs = BS ? BS : a->bs, bs2 = bs * bs, bw = a->bw;
  const PetscInt *jmap = a->coo_jmap;
  PetscInt        q    = 0;
  for (PetscInt r = 0; r < a->mbs; r++) {
    const PetscInt nr = a->row_nz[r];
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt k = 0; k < nr; k++) {
        V *blk =
          val + BinBCSRValueIndex(BinBCSRSlot(a, r, k), i * bs, bw, bs2); /* entry (i, j): blk[j * bw] */
        for (PetscInt j = 0; j < bs; j++, q++) {
          V           &dst = blk[(size_t)j * bw];
          const double s   = binbcsr::coo_gather<PetscInt>(v, n, recv, jmap, perm, q);
          dst              = (V)(ADD ? (double)dst + s : s);
        }
      }
  }
}

/* The block map (see coo_slot_ptr/coo_slot_src in binbcsr.h) from the value map; false if some
   stored block is not a sum of whole COO blocks, each in a single source (*why: which test failed,
   for -info). Each value lists its entries in COO order, and the entries of a COO block are
   consecutive in that order, so source block t of a stored block is entry t of each of its values. */
bool build_slot_map(const Mat_SeqBinBCSR *a, const PetscInt *perm, long n, PetscInt *slot_ptr,
                    std::vector<PetscInt> &slot_src, const char **why)
{
  const PetscInt        bs = a->bs, bs2 = a->bs2;
  const PetscInt       *jmap = a->coo_jmap;
  std::vector<PetscInt> count(a->nslots, 0),
    first(a->nslots, 0); /* per slot: sources, and where its (0, 0) value lists them */
  PetscInt qbase = 0;
  for (PetscInt r = 0; r < a->mbs; r++) {
    const PetscInt nr = a->row_nz[r];
    for (PetscInt k = 0; k < nr; k++) {
      const PetscInt q00 = qbase + k * bs, cnt = jmap[q00 + 1] - jmap[q00];
      *why = "a value with no COO entry";
      if (cnt == 0) return false;
      for (PetscInt t = 0; t < cnt; t++) {
        const long base = perm[jmap[q00] + t];
        *why            = "a block split between the two sources";
        if ((base < n) != (base + bs2 - 1 < n)) return false;
        bool plain = true, transposed = true;
        for (PetscInt i = 0; i < bs; i++)
          for (PetscInt j = 0; j < bs; j++) {
            const PetscInt q = qbase + i * nr * bs + k * bs + j;
            *why             = "values of one block with different numbers of COO entries";
            if (jmap[q + 1] - jmap[q] != cnt) return false;
            const long p = perm[jmap[q] + t];
            plain        = plain && p == base + i * bs + j;
            transposed   = transposed && p == base + j * bs + i;
          }
        *why = "a block whose entries are not whole blocks of the list";
        if (!plain && !transposed) return false;
      }
      const PetscInt slot = BinBCSRSlot(a, r, k);
      count[slot]         = cnt;
      first[slot]         = q00;
    }
    qbase += nr * bs2;
  }
  slot_ptr[0] = 0;
  for (PetscInt s = 0; s < a->nslots; s++) slot_ptr[s + 1] = slot_ptr[s] + count[s];
  slot_src.resize(slot_ptr[a->nslots]);
  for (PetscInt s = 0; s < a->nslots; s++)
    for (PetscInt t = 0; t < count[s]; t++) {
      const long base = perm[jmap[first[s]] + t];
      /* plain or transposed: the (0, 1) value tells (for bs 1 both are the same) */
      const bool transposed     = bs > 1 && perm[jmap[first[s] + 1] + t] != base + 1;
      slot_src[slot_ptr[s] + t] = transposed ? (PetscInt)(-1 - base) : (PetscInt)base;
    }
  return true;
}

/* sum += the BS x BS block at x (row-major), transposed if asked */
template <int BS, typename T> inline void add_block(double *sum, const T *x, bool transposed)
{
  if (!transposed)
    for (int e = 0; e < BS * BS; e++) sum[e] += (double)x[e];
  else
    for (int i = 0; i < BS; i++)
      for (int j = 0; j < BS; j++) sum[i * BS + j] += (double)x[j * BS + i];
}

/* The refill by blocks: slot by slot in storage order, so the values are written in sequence. v: the
   caller's values (double, or float for MatBinBCSRSetValuesCOOSingle), recv: received ones. */
template <int BS, bool ADD, typename V, typename S>
void coo_refill_blocks(const Mat_SeqBinBCSR *a, V *val, const PetscInt *slot_ptr, const PetscInt *slot_src,
                       const S *v, long n, const PetscScalar *recv)
{
  /* value e (plain order) of the source block at base, and its address (for the prefetch) */
  const auto address = [&](long base, PetscInt e) -> const void * {
    return base < n ? (const void *)(v + base + e) : (const void *)(recv + (base - n) + e);
  };
  const auto value = [&](long base, PetscInt e) -> double {
    return base < n ? (double)v[base + e] : recv[base - n + e];
  };
  constexpr int  MAXB2 = BS ? BS * BS : 1;
  const PetscInt bs = BS ? BS : a->bs, bs2 = bs * bs, bw = a->bw;
  for (PetscInt s0 = 0; s0 < a->nslots; s0 += bw) { /* one column of a bin: bw lanes */
    /* the sources of the slot column four ahead: the caller's blocks are read in its order, not in
       storage order, and each read waited for memory */
    if (s0 + 4 * bw < a->nslots)
      for (PetscInt l = 0; l < bw; l++) {
        const PetscInt p = slot_ptr[s0 + 4 * bw + l];
        if (p == slot_ptr[s0 + 4 * bw + l + 1]) continue;
        const long base = slot_src[p] >= 0 ? slot_src[p] : -1 - (long)slot_src[p];
        __builtin_prefetch(address(base, 0));
        __builtin_prefetch(address(base, bs2 - 1));
      }
    for (PetscInt l = 0; l < bw; l++) {
      const PetscInt p0 = slot_ptr[s0 + l], p1 = slot_ptr[s0 + l + 1];
      if (p0 == p1) continue; /* padding stays zero */
      V *dst = val + (size_t)s0 * bs2 + l;
      if (BS) {
        double sum[MAXB2] = {};
        for (PetscInt p = p0; p < p1; p++) {
          const PetscInt src  = slot_src[p];
          const long     base = src >= 0 ? src : -1 - (long)src;
          if (base < n) add_block<BS>(sum, v + base, src < 0);
          else add_block<BS>(sum, recv + (base - n), src < 0);
        }
        for (int e = 0; e < MAXB2; e++)
          dst[(size_t)e * bw] = (V)(ADD ? (double)dst[(size_t)e * bw] + sum[e] : sum[e]);
      } else { /* any block size: value by value */
        for (PetscInt i = 0; i < bs; i++)
          for (PetscInt j = 0; j < bs; j++) {
            double sum = 0;
            for (PetscInt p = p0; p < p1; p++) {
              const PetscInt src  = slot_src[p];
              const long     base = src >= 0 ? src : -1 - (long)src;
              sum += value(base, src >= 0 ? i * bs + j : j * bs + i);
            }
            V &d = dst[(size_t)(i * bs + j) * bw];
            d    = (V)(ADD ? (double)d + sum : sum);
          }
      }
    }
  }
}

template <int BS, typename V, typename S>
void coo_refill_mode(const Mat_SeqBinBCSR *a, V *val, const PetscInt *perm, const S *v, long n,
                     const PetscScalar *recv, InsertMode imode)
{
  if (imode == ADD_VALUES) coo_refill<BS, true, V>(a, val, perm, v, n, recv);
  else coo_refill<BS, false, V>(a, val, perm, v, n, recv);
}

template <typename V, typename S>
void coo_refill_any(const Mat_SeqBinBCSR *a, V *val, const PetscInt *perm, const S *v, long n,
                    const PetscScalar *recv, InsertMode imode)
{
  if (a->coo_slot_state == 1) {
    const bool      add = imode == ADD_VALUES;
    const PetscInt *ptr = a->coo_slot_ptr, *src = a->coo_slot_src;
    if (a->bs == 3)
      add ? coo_refill_blocks<3, true>(a, val, ptr, src, v, n, recv)
          : coo_refill_blocks<3, false>(a, val, ptr, src, v, n, recv);
    else if (a->bs == 1)
      add ? coo_refill_blocks<1, true>(a, val, ptr, src, v, n, recv)
          : coo_refill_blocks<1, false>(a, val, ptr, src, v, n, recv);
    else
      add ? coo_refill_blocks<0, true>(a, val, ptr, src, v, n, recv)
          : coo_refill_blocks<0, false>(a, val, ptr, src, v, n, recv);
    return;
  }
  if (a->bs == 3) coo_refill_mode<3>(a, val, perm, v, n, recv, imode);
  else if (a->bs == 1) coo_refill_mode<1>(a, val, perm, v, n, recv, imode);
  else coo_refill_mode<0>(a, val, perm, v, n, recv, imode);
}

/* The block map if the list allows it (else the refill goes value by value), for the split n between
   the two sources; built once, at preallocation. */
PetscErrorCode BuildSlotMap(Mat A, const PetscInt *perm, long n)
{
  Mat_SeqBinBCSR       *a = (Mat_SeqBinBCSR *)A->data;
  std::vector<PetscInt> src;
  const char           *why = "";

  PetscFunctionBegin;
  PetscCall(PetscFree(a->coo_slot_ptr));
  PetscCall(PetscFree(a->coo_slot_src));
  PetscCall(PetscMalloc1(a->nslots + 1, &a->coo_slot_ptr));
  a->coo_slot_state = build_slot_map(a, perm, n, a->coo_slot_ptr, src, &why) ? 1 : -1;
  a->coo_slot_n     = n;
  a->coo_slot_perm  = perm;
  if (a->coo_slot_state > 0) {
    PetscCall(PetscMalloc1(PetscMax(src.size(), (size_t)1), &a->coo_slot_src));
    std::copy(src.begin(), src.end(), a->coo_slot_src);
  } else PetscCall(PetscFree(a->coo_slot_ptr));
  PetscCall(PetscInfo(A, "COO refill %s%s\n", a->coo_slot_state > 0 ? "by whole blocks" : "by values: ",
                      a->coo_slot_state > 0 ? "" : why));
  PetscFunctionReturn(0);
}

/* The refill the entry points share; v == NULL means zeros. S: the caller's value type. */
template <typename S>
PetscErrorCode SetValuesCOO(Mat A, const PetscInt *perm, const S v[], long n, const PetscScalar recv[],
                            InsertMode imode)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  nv = a->nslots * a->bs2; /* padding included: it stays zero */

  PetscFunctionBegin;
  PetscCheck(imode == INSERT_VALUES || imode == ADD_VALUES, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "MatSetValuesCOO supports INSERT_VALUES and ADD_VALUES only");
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_SetValuesCOO, A, 0, 0, 0));
  /* Values come from v, and on an MPI part also from recv (the entries other ranks send). A rank with
     no entries of its own has v null (n = 0) and may still receive some: only with neither source are
     the values zeros. (Testing v alone zeroed such a rank's rows, received entries and all.) */
  const bool values = v || recv;
  /* the map is built at preallocation; again if this refill reads another map or split (a copy, a part refilled on its own) */
  if (values && (a->coo_slot_state == 0 ||
                 (a->coo_slot_state == 1 && (a->coo_slot_n != n || a->coo_slot_perm != perm))))
    PetscCall(BuildSlotMap(A, perm, n));
  if (!values) { /* no values: zeros */
    if (imode == INSERT_VALUES) {
      if (a->val) PetscCall(PetscArrayzero(a->val, nv));
      else PetscCall(PetscArrayzero(a->valf, nv));
    }
  } else if (a->val) coo_refill_any(a, a->val, perm, v, n, recv, imode);
  else coo_refill_any(a, a->valf, perm, v, n, recv, imode);
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_SetValuesCOO, A, 0, 0, 0));
  PetscFunctionReturn(0);
}
} // namespace

namespace {
/* The refill from the caller's values alone (v double or float; `name` for the error) */
template <typename S> PetscErrorCode SetValuesCOOOwn(Mat A, const S v[], InsertMode imode, const char *name)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_jmap, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "%s needs MatSetPreallocationCOO first", name);
  PetscCall(SetValuesCOO(A, a->coo_perm, v, (long)a->coo_n, nullptr, imode));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode MatSetValuesCOO_SeqBinBCSR(Mat A, const PetscScalar v[], InsertMode imode)
{
  return SetValuesCOOOwn(A, v, imode, "MatSetValuesCOO");
}

PetscErrorCode MatBinBCSRSetValuesCOOSingle_SeqBinBCSR(Mat A, const float v[], InsertMode imode)
{
  return SetValuesCOOOwn(A, v, imode, "MatBinBCSRSetValuesCOOSingle");
}

PetscErrorCode MatSeqBinBCSRComposeCOO(Mat A, const PetscCount from[], PetscCount n, PetscCount nsrc)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_jmap, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatSeqBinBCSRComposeCOO needs MatSetPreallocationCOO first");
  PetscCheck(nsrc <= PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_SUP,
             "%" PetscCount_FMT " COO sources overflow the 32-bit indices of MATSEQBINBCSR", nsrc);
  const PetscInt nperm = a->coo_jmap[a->nz * a->bs2];
  PetscCall(PetscFree(a->coo_perm_src));
  PetscCall(PetscMalloc1(nperm, &a->coo_perm_src));
  for (PetscInt t = 0; t < nperm; t++) a->coo_perm_src[t] = (PetscInt)from[a->coo_perm[t]];
  a->coo_composed = PETSC_TRUE; /* coo_perm_src is NULL when the part has no entries */
  PetscCall(BuildSlotMap(A, a->coo_perm_src, (long)n)); /* the block map follows the sources */
  PetscFunctionReturn(0);
}

template <typename S>
static PetscErrorCode SetValuesCOOTwoSources(Mat A, const S v[], PetscCount n, const PetscScalar recv[],
                                             InsertMode imode)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_composed, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MatSetValuesCOOTwoSources_SeqBinBCSR needs MatSeqBinBCSRComposeCOO first");
  PetscCall(SetValuesCOO(A, a->coo_perm_src, v, (long)n, recv, imode));
  /* not assembled here: the MPI matrix assembles its parts inside its own assembly, which
     MatSetValuesCOO() calls next (assembled here, outside it, a part printed itself under -mat_view) */
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetValuesCOOTwoSources_SeqBinBCSR(Mat A, const PetscScalar v[], PetscCount n,
                                                    const PetscScalar recv[], InsertMode imode)
{
  return SetValuesCOOTwoSources(A, v, n, recv, imode);
}

PetscErrorCode MatSetValuesCOOTwoSourcesSingle_SeqBinBCSR(Mat A, const float v[], PetscCount n,
                                                          const PetscScalar recv[], InsertMode imode)
{
  return SetValuesCOOTwoSources(A, v, n, recv, imode);
}
