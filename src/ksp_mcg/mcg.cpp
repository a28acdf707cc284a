/* KSPMCG (placeholder until implemented). */
#include "binbcsr_impl.h"

PetscErrorCode KSPCreate_MCG(KSP ksp)
{
  PetscFunctionBegin;
  SETERRQ(PetscObjectComm((PetscObject)ksp), PETSC_ERR_SUP, "KSPMCG is not implemented yet");
  PetscFunctionReturn(0);
}

PetscErrorCode KSPMCGSetFixedIterations(KSP ksp, PetscInt n)
{
  PetscFunctionBegin;
  PetscTryMethod(ksp, "KSPMCGSetFixedIterations_C", (KSP, PetscInt), (ksp, n));
  PetscFunctionReturn(0);
}

PetscErrorCode KSPMCGGetFixedIterations(KSP ksp, PetscInt *n)
{
  PetscFunctionBegin;
  *n = 0;
  PetscTryMethod(ksp, "KSPMCGGetFixedIterations_C", (KSP, PetscInt *), (ksp, n));
  PetscFunctionReturn(0);
}
