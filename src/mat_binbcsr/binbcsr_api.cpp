/* Public setters and getters of MATBINBCSR: dispatch to the composed implementation of the actual
   type (seq or mpi), and do nothing on other types so user code can call them unconditionally. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

PetscErrorCode MatBinBCSRSetFromOptions(Mat A)
{
  PetscErrorCode (*is_binbcsr)(Mat, PetscInt) = nullptr;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscCall(PetscObjectQueryFunction((PetscObject)A, "MatBinBCSRSetBinWidth_C", &is_binbcsr));
  if (!is_binbcsr || !A->ops->setfromoptions) PetscFunctionReturn(0);
  PetscObjectOptionsBegin((PetscObject)A);
  PetscCall((*A->ops->setfromoptions)(A, PetscOptionsObject));
  PetscOptionsEnd();
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetBinWidth(Mat A, PetscInt bw)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveInt(A, bw, 2);
  PetscTryMethod(A, "MatBinBCSRSetBinWidth_C", (Mat, PetscInt), (A, bw));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetBinWidth(Mat A, PetscInt *bw)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidIntPointer(bw, 2);
  *bw = 0;
  PetscTryMethod(A, "MatBinBCSRGetBinWidth_C", (Mat, PetscInt *), (A, bw));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetPrecision(Mat A, MatBinBCSRPrecision p)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveEnum(A, p, 2);
  PetscTryMethod(A, "MatBinBCSRSetPrecision_C", (Mat, MatBinBCSRPrecision), (A, p));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetPrecision(Mat A, MatBinBCSRPrecision *p)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidPointer(p, 2);
  *p = MAT_BINBCSR_PRECISION_DOUBLE;
  PetscTryMethod(A, "MatBinBCSRGetPrecision_C", (Mat, MatBinBCSRPrecision *), (A, p));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetSymmetricStorage(Mat A, PetscBool flg)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveBool(A, flg, 2);
  PetscTryMethod(A, "MatBinBCSRSetSymmetricStorage_C", (Mat, PetscBool), (A, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetSymmetricStorage(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidBoolPointer(flg, 2);
  *flg = PETSC_FALSE;
  PetscTryMethod(A, "MatBinBCSRGetSymmetricStorage_C", (Mat, PetscBool *), (A, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetCOOMirror(Mat A, PetscBool flg)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveBool(A, flg, 2);
  PetscTryMethod(A, "MatBinBCSRSetCOOMirror_C", (Mat, PetscBool), (A, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetCOOMirror(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidBoolPointer(flg, 2);
  *flg = PETSC_FALSE;
  PetscTryMethod(A, "MatBinBCSRGetCOOMirror_C", (Mat, PetscBool *), (A, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRSetStreams(Mat A, PetscInt streams)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveInt(A, streams, 2);
  PetscCheck(streams == 1 || streams == 2 || streams == 4 || streams == 8, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_OUTOFRANGE, "Streams %" PetscInt_FMT ": must be 1, 2, 4 or 8", streams);
  PetscTryMethod(A, "MatBinBCSRSetStreams_C", (Mat, PetscInt), (A, streams));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetStreams(Mat A, PetscInt *streams)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidIntPointer(streams, 2);
  *streams = 1;
  PetscTryMethod(A, "MatBinBCSRGetStreams_C", (Mat, PetscInt *), (A, streams));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRSetTune - Whether the layout build times the candidate bin widths and stream counts on
   this machine and keeps the fastest (MAT_BINBCSR_TUNE_AUTO, the default) or takes the defaults
   (MAT_BINBCSR_TUNE_OFF). A bin width or stream count set explicitly is never changed.

   Logically collective; set before the layout is built. Option: -mat_binbcsr_tune auto|off
@*/
PetscErrorCode MatBinBCSRSetTune(Mat A, MatBinBCSRTune t)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveEnum(A, t, 2);
  PetscCheck(t == MAT_BINBCSR_TUNE_OFF || t == MAT_BINBCSR_TUNE_AUTO, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_OUTOFRANGE, "Unknown tuning mode %d: MAT_BINBCSR_TUNE_OFF or MAT_BINBCSR_TUNE_AUTO", (int)t);
  PetscTryMethod(A, "MatBinBCSRSetTune_C", (Mat, MatBinBCSRTune), (A, t));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetTune(Mat A, MatBinBCSRTune *t)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidPointer(t, 2);
  *t = MAT_BINBCSR_TUNE_OFF;
  PetscTryMethod(A, "MatBinBCSRGetTune_C", (Mat, MatBinBCSRTune *), (A, t));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRSetTuneCache - Whether the tuner reads and writes its cache file
   ($XDG_CACHE_HOME/petscbinbcsr/tune.txt, else ~/.cache/petscbinbcsr/tune.txt).

   Logically collective; set before the layout is built. Option: -mat_binbcsr_tune_cache <bool>
@*/
PetscErrorCode MatBinBCSRSetTuneCache(Mat A, PetscBool flg)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveBool(A, flg, 2);
  PetscTryMethod(A, "MatBinBCSRSetTuneCache_C", (Mat, PetscBool), (A, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRGetTuneCache(Mat A, PetscBool *flg)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidBoolPointer(flg, 2);
  *flg = PETSC_FALSE;
  PetscTryMethod(A, "MatBinBCSRGetTuneCache_C", (Mat, PetscBool *), (A, flg));
  PetscFunctionReturn(0);
}

PetscErrorCode MatMultDotLocal(Mat A, Vec x, Vec y, PetscScalar *xdoty)
{
  PetscErrorCode (*fused)(Mat, Vec, Vec, PetscScalar *) = nullptr;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidHeaderSpecific(x, VEC_CLASSID, 2);
  PetscValidHeaderSpecific(y, VEC_CLASSID, 3);
  PetscValidScalarPointer(xdoty, 4);
  PetscCall(PetscObjectQueryFunction((PetscObject)A, "MatMultDotLocal_C", &fused));
  if (fused) {
    PetscCall(fused(A, x, y, xdoty));
  } else {
    const PetscScalar *xa, *ya;
    PetscInt           n;
    PetscScalar        sum = 0;
    PetscCall(MatMult(A, x, y));
    PetscCall(VecGetLocalSize(x, &n));
    PetscCall(VecGetArrayRead(x, &xa));
    PetscCall(VecGetArrayRead(y, &ya));
    for (PetscInt i = 0; i < n; i++) sum += xa[i] * ya[i];
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(VecRestoreArrayRead(y, &ya));
    PetscCall(PetscLogFlops(2.0 * n));
    *xdoty = sum;
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRCheckVecLocalSize(Vec v, PetscInt n, const char *what)
{
  PetscInt nv;

  PetscFunctionBegin;
  PetscCall(VecGetLocalSize(v, &nv));
  PetscCheck(nv == n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "%s has %" PetscInt_FMT " local entries, the matrix needs %" PetscInt_FMT, what, nv, n);
  PetscFunctionReturn(0);
}
