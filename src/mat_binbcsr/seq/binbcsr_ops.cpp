/* MATSEQBINBCSR: the value operations (scale, shift, zero rows, norms, I/O ...). (placeholder) */
#include "binbcsr.h"

PetscErrorCode MatSeqBinBCSRSetOps_Ops(Mat A)
{
  PetscFunctionBegin;
  (void)A;
  PetscFunctionReturn(0);
}
