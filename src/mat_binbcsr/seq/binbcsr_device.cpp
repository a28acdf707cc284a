/*
   The device copy of a MATSEQBINBCSR: MatBinBCSRSetDevice() puts the bins on an executor of the device
   library (src/device/), and three of the matrix's operations are wrapped:
     - assembly end: the values are uploaded (unless a COO refill already made them on the device);
     - MatSetValuesCOO: the host refill as before (every host operation keeps working), and the COO
       values uploaded and gathered on the device: no host gather plus full upload;
     - MatMult: x copied to the device, y = A x there, y copied back (slow; event BinBCSRDevMult).
   Any other change of the values (MatScale, MatZeroRows, ...) is caught by the object state: the next
   device use uploads the values again. The device state lives in a PetscContainer composed on the
   matrix, so it goes with the matrix.
*/
#include "binbcsr_device.h"

#include <vector>

namespace {
using namespace binbcsr::device;

struct DeviceCopy {
  MatBinBCSRDevice          kind = MAT_BINBCSR_DEVICE_NONE;
  std::unique_ptr<Executor> exec;
  std::unique_ptr<Matrix>   M;
  std::unique_ptr<Vector>   x, y;
  PetscObjectState          state     = -1; /* of the values on the device */
  PetscObjectState          nzstate   = -1; /* of the layout M was made for */
  MatBinBCSRPrecision       precision = MAT_BINBCSR_PRECISION_DOUBLE;
  const PetscInt           *gather_of = nullptr;     /* the coo_jmap the device refill map was made from */
  PetscBool                 coo_fresh = PETSC_FALSE; /* a COO refill made the device values */
  std::vector<std::unique_ptr<Vector>>                    cached;
  std::vector<std::pair<PetscObjectId, PetscObjectState>> cached_of;
  PetscErrorCode (*assemblyend)(Mat, MatAssemblyType)         = nullptr;
  PetscErrorCode (*mult)(Mat, Vec, Vec)                       = nullptr;
  PetscErrorCode (*coo)(Mat, const PetscScalar[], InsertMode) = nullptr;
};

PetscErrorCode DestroyDeviceCopy(void *p)
{
  delete (DeviceCopy *)p;
  return 0;
}

PetscErrorCode GetCopy(Mat A, DeviceCopy **dc)
{
  PetscContainer c = nullptr;

  PetscFunctionBegin;
  *dc = nullptr;
  PetscCall(PetscObjectQuery((PetscObject)A, "MatBinBCSRDevice_ctx", (PetscObject *)&c));
  if (c) PetscCall(PetscContainerGetPointer(c, (void **)dc));
  PetscFunctionReturn(0);
}

/* (Re)makes the device matrix when the layout or the precision changed, then uploads the values if
   they changed since the last upload. */
PetscErrorCode Refresh(Mat A, DeviceCopy *dc)
{
  Mat_SeqBinBCSR  *a = (Mat_SeqBinBCSR *)A->data;
  PetscObjectState st;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR device copy: the matrix has no layout yet (assemble it first)");
  PetscCall(PetscObjectStateGet((PetscObject)A, &st));
  if (dc->M && dc->nzstate == A->nonzerostate && dc->precision == a->precision && dc->state == st)
    PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_DeviceUpload, A, 0, 0, 0));
  if (!dc->M || dc->nzstate != A->nonzerostate || dc->precision != a->precision) {
    std::vector<int> bin_start(a->bin_start, a->bin_start + a->nbins + 1), col(a->col, a->col + a->nslots);
    Layout           L;
    L.bs        = (int)a->bs;
    L.bw        = (int)a->bw;
    L.mbs       = (int)a->mbs;
    L.symmetric = a->sym ? true : false;
    L.bin_start = bin_start.data();
    L.col       = col.data();
    BinBCSRDeviceTry(dc->M = dc->exec->matrix(L, a->precision == MAT_BINBCSR_PRECISION_SINGLE
                                                   ? Precision::single_values
                                                   : Precision::double_values));
    BinBCSRDeviceTry(dc->x = dc->exec->vector(L.n()));
    BinBCSRDeviceTry(dc->y = dc->exec->vector(L.n()));
    dc->nzstate   = A->nonzerostate;
    dc->precision = a->precision;
    dc->gather_of = nullptr;
  }
  const long nv = (long)a->nslots * a->bs2;
  if (a->val) BinBCSRDeviceTry(dc->M->set_values(a->val));
  else {
    std::vector<double> v(a->valf, a->valf + nv);
    BinBCSRDeviceTry(dc->M->set_values(v.data()));
  }
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_DeviceUpload, A, 0, 0, 0));
  dc->state = st;
  PetscFunctionReturn(0);
}

PetscErrorCode MatAssemblyEnd_Device(Mat A, MatAssemblyType t)
{
  DeviceCopy *dc;

  PetscFunctionBegin;
  PetscCall(GetCopy(A, &dc));
  PetscCall((*dc->assemblyend)(A, t));
  if (t != MAT_FINAL_ASSEMBLY) PetscFunctionReturn(0);
  if (dc->coo_fresh) { /* MatSetValuesCOO's own assembly: the device already has these values */
    dc->coo_fresh = PETSC_FALSE;
    PetscCall(PetscObjectStateGet((PetscObject)A, &dc->state));
    PetscFunctionReturn(0);
  }
  PetscCall(Refresh(A, dc));
  PetscFunctionReturn(0);
}

/* The device refill map from the host's: value q of the host's row order (binbcsr.h, COO assembly)
   is the value index of its slot and entry. */
PetscErrorCode MakeGatherMap(Mat A, DeviceCopy *dc)
{
  Mat_SeqBinBCSR   *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt    bs = a->bs, bs2 = a->bs2, bw = a->bw;
  const long        nv = (long)a->nslots * bs2;
  std::vector<int>  jmap(nv + 1, 0), perm;
  std::vector<long> vof((size_t)a->nz * bs2);

  PetscFunctionBegin;
  PetscInt q = 0;
  for (PetscInt r = 0; r < a->mbs; r++)
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt k = 0; k < a->row_nz[r]; k++)
        for (PetscInt j = 0; j < bs; j++, q++) {
          vof[q]           = BinBCSRValueIndex(BinBCSRSlot(a, r, k), i * bs + j, bw, bs2);
          jmap[vof[q] + 1] = a->coo_jmap[q + 1] - a->coo_jmap[q];
        }
  for (long v = 0; v < nv; v++) jmap[v + 1] += jmap[v];
  perm.resize(jmap[nv]);
  for (PetscInt t = 0; t < q; t++)
    for (PetscInt e = a->coo_jmap[t]; e < a->coo_jmap[t + 1]; e++)
      perm[jmap[vof[t]] + (e - a->coo_jmap[t])] = (int)a->coo_perm[e];
  GatherMap G;
  G.ncoo = (long)a->coo_n;
  G.jmap = jmap.data();
  G.perm = perm.data();
  BinBCSRDeviceTry(dc->M->set_gather_map(G));
  dc->gather_of = a->coo_jmap;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSetValuesCOO_Device(Mat A, const PetscScalar v[], InsertMode imode)
{
  Mat_SeqBinBCSR  *a = (Mat_SeqBinBCSR *)A->data;
  DeviceCopy      *dc;
  PetscObjectState st;

  PetscFunctionBegin;
  PetscCall(GetCopy(A, &dc));
  PetscCall(PetscObjectStateGet((PetscObject)A, &st));
  const PetscBool in_step =
    (PetscBool)(dc->M && dc->state == st && dc->nzstate == A->nonzerostate &&
                dc->precision == a->precision); /* device values = host values before the refill */
  PetscCall((*dc->coo)(A, v, imode));
  if (!v || (imode == ADD_VALUES && !in_step)) PetscFunctionReturn(0); /* the next use uploads */
  if (!dc->M || dc->nzstate != A->nonzerostate || dc->precision != a->precision) PetscCall(Refresh(A, dc));
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_DeviceUpload, A, 0, 0, 0));
  if (dc->gather_of != a->coo_jmap) PetscCall(MakeGatherMap(A, dc));
  BinBCSRDeviceTry(dc->M->refill(v, imode == ADD_VALUES));
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_DeviceUpload, A, 0, 0, 0));
  dc->coo_fresh = PETSC_TRUE;
  PetscCall(PetscObjectStateGet((PetscObject)A, &dc->state));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMult_Device(Mat A, Vec x, Vec y)
{
  DeviceCopy        *dc;
  const PetscScalar *xa;
  PetscScalar       *ya;
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;

  PetscFunctionBegin;
  PetscCall(GetCopy(A, &dc));
  PetscCall(Refresh(A, dc));
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_DeviceMult, A, x, y, 0));
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayWrite(y, &ya));
  BinBCSRDeviceTry(dc->x->upload(xa); dc->M->mult(*dc->x, *dc->y); dc->y->download(ya));
  PetscCall(VecRestoreArrayWrite(y, &ya));
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(PetscLogFlops(2.0 * (PetscLogDouble)a->nz * a->bs2));
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_DeviceMult, A, x, y, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRSetDevice(Mat A, MatBinBCSRDevice kind)
{
  DeviceCopy *dc;

  PetscFunctionBegin;
  PetscCall(GetCopy(A, &dc));
  if ((dc ? dc->kind : MAT_BINBCSR_DEVICE_NONE) == kind) PetscFunctionReturn(0);
  if (dc) { /* back to the host operations */
    A->ops->assemblyend = dc->assemblyend;
    A->ops->mult        = dc->mult;
    PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatSetValuesCOO_C", dc->coo));
    PetscCall(PetscObjectCompose((PetscObject)A, "MatBinBCSRDevice_ctx", nullptr));
  }
  if (kind == MAT_BINBCSR_DEVICE_NONE) PetscFunctionReturn(0);
  std::string               why;
  std::unique_ptr<Executor> E;
  BinBCSRDeviceTry(E = make_executor(kind == MAT_BINBCSR_DEVICE_CUDA ? "cuda" : "reference", &why));
  PetscCheck(E, PETSC_COMM_SELF, PETSC_ERR_SUP, "-mat_binbcsr_device %s: %s", MatBinBCSRDevices[kind],
             why.c_str());
  auto *n        = new DeviceCopy;
  n->kind        = kind;
  n->exec        = std::move(E);
  n->assemblyend = A->ops->assemblyend;
  n->mult        = A->ops->mult;
  PetscCall(PetscObjectQueryFunction((PetscObject)A, "MatSetValuesCOO_C", &n->coo));
  PetscContainer c;
  PetscCall(PetscContainerCreate(PETSC_COMM_SELF, &c));
  PetscCall(PetscContainerSetPointer(c, n));
  PetscCall(PetscContainerSetUserDestroy(c, DestroyDeviceCopy));
  PetscCall(PetscObjectCompose((PetscObject)A, "MatBinBCSRDevice_ctx", (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  A->ops->assemblyend = MatAssemblyEnd_Device;
  A->ops->mult        = MatMult_Device;
  if (n->coo)
    PetscCall(PetscObjectComposeFunction((PetscObject)A, "MatSetValuesCOO_C", MatSetValuesCOO_Device));
  if (((Mat_SeqBinBCSR *)A->data)->built && A->assembled) PetscCall(Refresh(A, n));
  PetscCall(PetscInfo(A, "device copy on the %s executor\n", n->exec->name()));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode MatSeqBinBCSRGetDeviceMatrix(Mat A, Executor **E, Matrix **M)
{
  DeviceCopy *dc;
  PetscBool   isseq;

  PetscFunctionBegin;
  *E = nullptr;
  *M = nullptr;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQBINBCSR, &isseq));
  if (!isseq) PetscFunctionReturn(0);
  PetscCall(GetCopy(A, &dc));
  if (!dc) PetscFunctionReturn(0);
  PetscCall(Refresh(A, dc));
  *E = dc->exec.get();
  *M = dc->M.get();
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRDeviceCachedVector(Mat A, int slot, Vec v, Vector **dv)
{
  DeviceCopy      *dc;
  PetscObjectId    id;
  PetscObjectState st;
  PetscInt         n;

  PetscFunctionBegin;
  PetscCall(GetCopy(A, &dc));
  PetscCheck(dc, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "the matrix has no device copy");
  if (v) {
    PetscCall(VecGetLocalSize(v, &n));
    PetscCall(PetscObjectGetId((PetscObject)v, &id));
    PetscCall(PetscObjectStateGet((PetscObject)v, &st));
  } else n = A->rmap->n; /* a work vector: allocated once, never uploaded here */
  if ((int)dc->cached.size() <= slot) {
    dc->cached.resize(slot + 1);
    dc->cached_of.resize(slot + 1, {-1, -1});
  }
  if (!dc->cached[slot] || dc->cached[slot]->size() != n) {
    BinBCSRDeviceTry(dc->cached[slot] = dc->exec->vector(n));
    dc->cached_of[slot] = {-1, -1};
  }
  if (v && dc->cached_of[slot] != std::make_pair(id, st)) {
    const PetscScalar *va;
    PetscCall(VecGetArrayRead(v, &va));
    BinBCSRDeviceTry(dc->cached[slot]->upload(va));
    PetscCall(VecRestoreArrayRead(v, &va));
    dc->cached_of[slot] = {id, st};
  }
  *dv = dc->cached[slot].get();
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRSetDevice - Keeps a device copy of a MATSEQBINBCSR on an executor of the device library

   Logically Collective

   Input Parameters:
+  A - the matrix
-  d - MAT_BINBCSR_DEVICE_NONE, MAT_BINBCSR_DEVICE_REFERENCE (host executor) or MAT_BINBCSR_DEVICE_CUDA

   Options Database Key:
.  -mat_binbcsr_device <none,reference,cuda> - the device

   Notes:
   After every final assembly and MatSetValuesCOO() the device copy is refreshed; MatMult() on host
   vectors copies in and out (slow); KSPMCG with PCJACOBI or PCNONE solves on the device. CUDA where
   the build has no cuda executor or the machine no GPU is an error saying why. MATMPIBINBCSR (more than
   one process) refuses any device. A no-op on matrices of other types.

   Level: intermediate

.seealso: `MatBinBCSRGetDevice()`, `KSPMCG`
@*/
PetscErrorCode MatBinBCSRSetDevice(Mat A, MatBinBCSRDevice d)
{
  PetscBool isseq, ismpi;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscCheck(d >= MAT_BINBCSR_DEVICE_NONE && d <= MAT_BINBCSR_DEVICE_CUDA, PetscObjectComm((PetscObject)A),
             PETSC_ERR_ARG_OUTOFRANGE, "unknown MatBinBCSRDevice %d", (int)d);
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQBINBCSR, &isseq));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &ismpi));
  if (ismpi) {
    PetscMPIInt size;
    PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)A), &size));
    PetscCheck(
      d == MAT_BINBCSR_DEVICE_NONE, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP,
      "-mat_binbcsr_device %s: MATMPIBINBCSR (%d processes) has no device copy; devices work on one process (MATSEQBINBCSR), see docs/gpu.md",
      MatBinBCSRDevices[d], (int)size);
  }
  if (isseq) PetscCall(MatSeqBinBCSRSetDevice(A, d));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRGetDevice - The device a MATSEQBINBCSR keeps a copy on

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  d - the device (MAT_BINBCSR_DEVICE_NONE for matrices of other types)

   Level: intermediate

.seealso: `MatBinBCSRSetDevice()`
@*/
PetscErrorCode MatBinBCSRGetDevice(Mat A, MatBinBCSRDevice *d)
{
  DeviceCopy *dc;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscCall(GetCopy(A, &dc));
  *d = dc ? dc->kind : MAT_BINBCSR_DEVICE_NONE;
  PetscFunctionReturn(0);
}
