/* MATSEQBINBCSR: creation, layout, assembly and products. (placeholder until implemented) */
#include "binbcsr.h"

PetscErrorCode MatCreate_SeqBinBCSR(Mat A)
{
  PetscFunctionBegin;
  SETERRQ(PetscObjectComm((PetscObject)A), PETSC_ERR_SUP, "MATSEQBINBCSR is not implemented yet");
  PetscFunctionReturn(0);
}
