/* MATMPIBINBCSR (placeholder until implemented). */
#include "binbcsr_impl.h"

PetscErrorCode MatCreate_MPIBinBCSR(Mat A)
{
  PetscFunctionBegin;
  SETERRQ(PetscObjectComm((PetscObject)A), PETSC_ERR_SUP, "MATMPIBINBCSR is not implemented yet");
  PetscFunctionReturn(0);
}
