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

  /* block rows of the valid entries; negative indices drop the entry, out-of-range ones are errors */
  PetscCall(PetscCalloc1(mbs + 1, &rowptr));
  for (PetscCount k = 0; k < n; k++) {
    const PetscInt i = ci[k], j = cj[k];
    if (i < 0 || j < 0) continue;
    PetscCheck(i < A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "COO entry %" PetscCount_FMT ": row %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", k, i, A->rmap->n);
    PetscCheck(j < A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "COO entry %" PetscCount_FMT ": column %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", k, j, A->cmap->n);
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

  /* value index of every COO entry (-1: dropped) */
  PetscCall(PetscMalloc1(n, &vk));
  for (PetscCount k = 0; k < n; k++) vk[k] = -1;
  for (PetscInt r = 0; r < mbs; r++) {
    PetscInt kk = -1, prev = -1;
    for (PetscInt p = rowptr[r]; p < rowptr[r + 1]; p++) {
      const PetscInt c = (PetscInt)(key[p] >> 32), k = (PetscInt)(key[p] & 0xffffffffu);
      if (c != prev) {
        kk++;
        prev = c;
      }
      const PetscInt s = BinBCSRSlot(a, r, kk), e = (ci[k] % bs) * bs + cj[k] % bs;
      vk[k]            = BinBCSRValueIndex(s, e, a->bw, a->bs2);
    }
  }
  PetscCall(PetscFree(key));
  PetscCall(PetscFree(rowptr));
  PetscCall(PetscFree(bi));
  PetscCall(PetscFree(bj));

  /* jmap: CSR over value indices; perm filled in COO order, so each value reads ascending entries */
  {
    const PetscInt nv = a->nslots * a->bs2;
    PetscCall(PetscCalloc1(nv + 1, &a->coo_jmap));
    PetscCall(PetscMalloc1(nvalid, &a->coo_perm));
    for (PetscCount k = 0; k < n; k++)
      if (vk[k] >= 0) a->coo_jmap[vk[k] + 1]++;
    for (PetscInt v = 0; v < nv; v++) a->coo_jmap[v + 1] += a->coo_jmap[v];
    PetscCall(PetscMalloc1(nv, &fill));
    for (PetscInt v = 0; v < nv; v++) fill[v] = a->coo_jmap[v];
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
template <typename V>
void coo_refill(V *val, PetscInt nv, const PetscInt *jmap, const PetscInt *perm, const PetscScalar *v, InsertMode imode)
{
  if (imode == INSERT_VALUES) {
    for (PetscInt i = 0; i < nv; i++) val[i] = (V)binbcsr::coo_gather<PetscInt>(v, jmap, perm, i);
  } else {
    for (PetscInt i = 0; i < nv; i++) val[i] = (V)((double)val[i] + binbcsr::coo_gather<PetscInt>(v, jmap, perm, i));
  }
}
} // namespace

PetscErrorCode MatSetValuesCOO_SeqBinBCSR(Mat A, const PetscScalar v[], InsertMode imode)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  nv = a->nslots * a->bs2;

  PetscFunctionBegin;
  PetscCheck(a->built && a->coo_jmap, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MatSetValuesCOO needs MatSetPreallocationCOO first");
  PetscCheck(imode == INSERT_VALUES || imode == ADD_VALUES, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "MatSetValuesCOO supports INSERT_VALUES and ADD_VALUES only");
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_SetValuesCOO, A, 0, 0, 0));
  if (!v) { /* no values: zeros */
    if (imode == INSERT_VALUES) {
      if (a->val) PetscCall(PetscArrayzero(a->val, nv));
      else PetscCall(PetscArrayzero(a->valf, nv));
    }
  } else if (a->val) coo_refill<double>(a->val, nv, a->coo_jmap, a->coo_perm, v, imode);
  else coo_refill<float>(a->valf, nv, a->coo_jmap, a->coo_perm, v, imode);
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_SetValuesCOO, A, 0, 0, 0));
  PetscFunctionReturn(0);
}
