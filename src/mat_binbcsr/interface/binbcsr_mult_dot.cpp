/* MatMultDotLocal, the fused y = A x with the local x.y that KSPMCG reduces with its other dots, and
   the small vector helpers the types' products share. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

/*@
   MatMultDotLocal - Computes y = A x and the local part of the dot product x^T y in one pass over A

   Neighbor-wise Collective

   Input Parameters:
+  A - the matrix
-  x - the vector to multiply

   Output Parameters:
+  y     - the product A x
-  xdoty - this process's part of x^T y (its rows only, not reduced across processes)

   Level: developer

   Notes:
   One pass when the matrix type provides it (the composed "MatMultDotLocal_C": `MATBINBCSR` does),
   otherwise `MatMult()` and a local dot. The caller reduces the dot across processes, typically
   together with other dots: `KSPMCG` does so once per iteration.

.seealso: `MATBINBCSR`, `KSPMCG`, `MatMult()`
@*/
PetscErrorCode MatMultDotLocal(Mat A, Vec x, Vec y, PetscScalar *xdoty)
{
  PetscErrorCode (*fused)(Mat, Vec, Vec, PetscScalar *) = nullptr;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidHeaderSpecific(x, VEC_CLASSID, 2);
  PetscValidHeaderSpecific(y, VEC_CLASSID, 3);
  PetscAssertPointer(xdoty, 4);
  PetscCall(PetscObjectQueryFunction((PetscObject)A, "MatMultDotLocal_C", &fused));
  if (fused) {
    PetscCall(fused(A, x, y, xdoty));
  } else {
    PetscCall(MatMult(A, x, y));
    PetscCall(MatBinBCSRVecDotLocal_Private(x, y, xdoty));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRVecDotLocal_Private(Vec x, Vec y, PetscScalar *xdoty)
{
  const PetscScalar *xa, *ya;
  PetscInt           n;
  PetscScalar        sum = 0;

  PetscFunctionBegin;
  PetscCall(VecGetLocalSize(x, &n));
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayRead(y, &ya));
  for (PetscInt i = 0; i < n; i++) sum += xa[i] * ya[i];
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(VecRestoreArrayRead(y, &ya));
  PetscCall(PetscLogFlops(2.0 * n));
  *xdoty = sum;
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRCheckVecLocalSize(Vec v, PetscInt n, const char *what)
{
  PetscInt nv;

  PetscFunctionBegin;
  PetscCall(VecGetLocalSize(v, &nv));
  PetscCheck(nv == n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "%s has %" PetscInt_FMT " local entries, the matrix needs %" PetscInt_FMT, what, nv, n);
  PetscFunctionReturn(0);
}
