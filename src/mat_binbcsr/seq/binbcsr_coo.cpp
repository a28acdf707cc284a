/* MATSEQBINBCSR COO assembly. Preallocation builds the bin layout straight from the COO pattern and,
   for every stored value (slot, entry), the list of COO entries that sum into it (jmap/perm, as PETSc's
   seqaij does per nonzero). The refill then writes each value once, in storage order, by gathering:
   no atomics, no search, no sort per call. */
#include "binbcsr.h"
#include "../binbcsr_kernels.h"
#include <algorithm>
#include <cstdint>

PetscErrorCode MatSetPreallocationCOO_SeqBinBCSR(Mat A, PetscCount n, const PetscInt ci[], const PetscInt cj[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        rbs, cbs, bs, mbs, nvalid = 0, *rowptr, *bi, *bj, *vk, *fill;
  uint64_t       *key; /* (block column << 32) | coo index, sorted per block row */

  PetscFunctionBegin;
  PetscCheck(n <= PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_SUP, "%" PetscCount_FMT " COO entries overflow the 32-bit indices of MATSEQBINBCSR", n);
  PetscCall(PetscLayoutSetUp(A->rmap));
  PetscCall(PetscLayoutSetUp(A->cmap));
  PetscCall(MatGetBlockSizes(A, &rbs, &cbs));
  PetscCheck(rbs == cbs, PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "MATSEQBINBCSR needs equal row and column block sizes, got %" PetscInt_FMT " and %" PetscInt_FMT, rbs, cbs);
  bs  = rbs;
  mbs = A->rmap->n / bs;

  /* negative indices drop the entry, out-of-range ones are errors (checked before any allocation) */
  for (PetscCount k = 0; k < n; k++) {
    const PetscInt i = ci[k], j = cj[k];
    if (i < 0 || j < 0) continue;
    PetscCheck(i < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "COO entry %" PetscCount_FMT ": row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", k, i, A->rmap->n);
    PetscCheck(j < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "COO entry %" PetscCount_FMT ": column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", k, j, A->cmap->n);
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

namespace
{
/* Refill in row order q (CSR order: gathers from the same elements follow each other); the writes
   stay inside one bin's tiles at a time. perm indices below n read v, the others recv (see
   binbcsr::coo_gather). */
template <int BS, bool ADD, typename V>
void coo_refill(const Mat_SeqBinBCSR *a, V *val, const PetscInt *perm, const PetscScalar *v, long n, const PetscScalar *recv)
{
  const PetscInt  bs = BS ? BS : a->bs, bs2 = bs * bs, bw = a->bw;
  const PetscInt *jmap = a->coo_jmap;
  PetscInt        q    = 0;
  for (PetscInt r = 0; r < a->mbs; r++) {
    const PetscInt nr = a->row_nz[r];
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt k = 0; k < nr; k++) {
        V *blk = val + BinBCSRValueIndex(BinBCSRSlot(a, r, k), i * bs, bw, bs2); /* entry (i, j): blk[j * bw] */
        for (PetscInt j = 0; j < bs; j++, q++) {
          V           &dst = blk[(size_t)j * bw];
          const double s   = binbcsr::coo_gather<PetscInt>(v, n, recv, jmap, perm, q);
          dst              = (V)(ADD ? (double)dst + s : s);
        }
      }
  }
}

template <int BS, typename V>
void coo_refill_mode(const Mat_SeqBinBCSR *a, V *val, const PetscInt *perm, const PetscScalar *v, long n, const PetscScalar *recv, InsertMode imode)
{
  if (imode == ADD_VALUES) coo_refill<BS, true, V>(a, val, perm, v, n, recv);
  else coo_refill<BS, false, V>(a, val, perm, v, n, recv);
}

template <typename V>
void coo_refill_any(const Mat_SeqBinBCSR *a, V *val, const PetscInt *perm, const PetscScalar *v, long n, const PetscScalar *recv, InsertMode imode)
{
  if (a->bs == 3) coo_refill_mode<3, V>(a, val, perm, v, n, recv, imode);
  else if (a->bs == 1) coo_refill_mode<1, V>(a, val, perm, v, n, recv, imode);
  else coo_refill_mode<0, V>(a, val, perm, v, n, recv, imode);
}

/* The refill both entry points share; v == NULL means zeros. */
PetscErrorCode SetValuesCOO(Mat A, const PetscInt *perm, const PetscScalar v[], long n, const PetscScalar recv[], InsertMode imode)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  nv = a->nslots * a->bs2; /* padding included: it stays zero */

  PetscFunctionBegin;
  PetscCheck(imode == INSERT_VALUES || imode == ADD_VALUES, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "MatSetValuesCOO supports INSERT_VALUES and ADD_VALUES only");
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_SetValuesCOO, A, 0, 0, 0));
  if (!v) { /* no values: zeros */
    if (imode == INSERT_VALUES) {
      if (a->val) PetscCall(PetscArrayzero(a->val, nv));
      else PetscCall(PetscArrayzero(a->valf, nv));
    }
  } else if (a->val) coo_refill_any<double>(a, a->val, perm, v, n, recv, imode);
  else coo_refill_any<float>(a, a->valf, perm, v, n, recv, imode);
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_SetValuesCOO, A, 0, 0, 0));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode MatSetValuesCOO_SeqBinBCSR(Mat A, const PetscScalar v[], InsertMode imode)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_jmap, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatSetValuesCOO needs MatSetPreallocationCOO first");
  PetscCall(SetValuesCOO(A, a->coo_perm, v, (long)a->coo_n, nullptr, imode));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRComposeCOO(Mat A, const PetscCount from[], PetscCount nsrc)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_jmap, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatSeqBinBCSRComposeCOO needs MatSetPreallocationCOO first");
  PetscCheck(nsrc <= PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_SUP, "%" PetscCount_FMT " COO sources overflow the 32-bit indices of MATSEQBINBCSR", nsrc);
  const PetscInt nperm = a->coo_jmap[a->nz * a->bs2];
  PetscCall(PetscFree(a->coo_perm_src));
  PetscCall(PetscMalloc1(nperm, &a->coo_perm_src));
  for (PetscInt t = 0; t < nperm; t++) a->coo_perm_src[t] = (PetscInt)from[a->coo_perm[t]];
  a->coo_composed = PETSC_TRUE; /* coo_perm_src is NULL when the part has no entries */
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetValuesCOOTwoSources_SeqBinBCSR(Mat A, const PetscScalar v[], PetscCount n, const PetscScalar recv[], InsertMode imode)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_composed, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatSetValuesCOOTwoSources_SeqBinBCSR needs MatSeqBinBCSRComposeCOO first");
  PetscCall(SetValuesCOO(A, a->coo_perm_src, v, (long)n, recv, imode));
  /* as MatSetValuesCOO() does after the type's refill */
  PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}
