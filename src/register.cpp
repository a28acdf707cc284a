#include "binbcsr_impl.h"

PetscLogEvent MAT_BinBCSR_BuildLayout  = 0;
PetscLogEvent MAT_BinBCSR_SetValuesCOO = 0;
PetscLogEvent MAT_BinBCSR_MultDot      = 0;
PetscLogEvent MAT_BinBCSR_Tune         = 0;
PetscLogEvent KSP_MCG_FusedUpdate      = 0;
PetscLogEvent KSP_MCG_Reduction        = 0;
PetscLogEvent MAT_BinBCSR_DeviceMult   = 0;
PetscLogEvent MAT_BinBCSR_DeviceUpload = 0;
PetscLogEvent KSP_MCG_DeviceSolve      = 0;

const char *const MatBinBCSRPrecisions[] = {"double", "single", "MatBinBCSRPrecision", "MAT_BINBCSR_PRECISION_", nullptr};
const char *const MatBinBCSRDevices[]    = {"none", "reference", "cuda", "MatBinBCSRDevice", "MAT_BINBCSR_DEVICE_", nullptr};
const char *const MatBinBCSRTunes[]      = {"off", "auto", "MatBinBCSRTune", "MAT_BINBCSR_TUNE_", nullptr};

static PetscBool registered = PETSC_FALSE;

/*@C
   PetscBinBCSRRegisterAll - Registers `MATBINBCSR`, `MATSEQBINBCSR`, `MATMPIBINBCSR`, `KSPMCG`, the
   factorisations of `MATSEQBINBCSR` and the -log_view events of the plug-in

   Not Collective

   Level: beginner

   Notes:
   A program linked against libpetscbinbcsr calls it once after `PetscInitialize()`; a stock PETSc
   program gets the same from -dll_append libpetscbinbcsr.so, through
   `PetscDLLibraryRegister_petscbinbcsr()`. Calling it again does nothing.

.seealso: `MATBINBCSR`, `KSPMCG`, `PetscDLLibraryRegister_petscbinbcsr()`
@*/
PetscErrorCode PetscBinBCSRRegisterAll(void)
{
  PetscFunctionBegin;
  if (registered) PetscFunctionReturn(0);
  registered = PETSC_TRUE;
  PetscCall(MatRegister(MATSEQBINBCSR, MatCreate_SeqBinBCSR));
  PetscCall(MatRegister(MATMPIBINBCSR, MatCreate_MPIBinBCSR));
  PetscCall(MatRegisterRootName(MATBINBCSR, MATSEQBINBCSR, MATMPIBINBCSR));
  PetscCall(KSPRegister(KSPMCG, KSPCreate_MCG));
  for (MatFactorType ft : {MAT_FACTOR_ICC, MAT_FACTOR_CHOLESKY, MAT_FACTOR_ILU, MAT_FACTOR_LU}) PetscCall(MatSolverTypeRegister(MATSOLVERPETSC, MATSEQBINBCSR, ft, MatGetFactor_SeqBinBCSR_Petsc));
  PetscCall(MatBinBCSRRegisterExternalFactors());
  PetscCall(PetscLogEventRegister("BinBCSRBuildLay", MAT_CLASSID, &MAT_BinBCSR_BuildLayout));
  PetscCall(PetscLogEventRegister("BinBCSRSetCOO", MAT_CLASSID, &MAT_BinBCSR_SetValuesCOO));
  PetscCall(PetscLogEventRegister("BinBCSRMultDot", MAT_CLASSID, &MAT_BinBCSR_MultDot));
  PetscCall(PetscLogEventRegister("BinBCSRTune", MAT_CLASSID, &MAT_BinBCSR_Tune));
  PetscCall(PetscLogEventRegister("MCGFusedUpdate", KSP_CLASSID, &KSP_MCG_FusedUpdate));
  PetscCall(PetscLogEventRegister("MCGReduction", KSP_CLASSID, &KSP_MCG_Reduction));
  PetscCall(PetscLogEventRegister("BinBCSRDevMult", MAT_CLASSID, &MAT_BinBCSR_DeviceMult));
  PetscCall(PetscLogEventRegister("BinBCSRDevUp", MAT_CLASSID, &MAT_BinBCSR_DeviceUpload));
  PetscCall(PetscLogEventRegister("MCGDeviceSolve", KSP_CLASSID, &KSP_MCG_DeviceSolve));
  PetscFunctionReturn(0);
}

/*@C
   PetscDLLibraryRegister_petscbinbcsr - The entry point PETSc's dynamic library loader calls for
   -dll_append or -dll_prepend libpetscbinbcsr.so: registers everything, as `PetscBinBCSRRegisterAll()`

   Not Collective

   Level: developer

.seealso: `PetscBinBCSRRegisterAll()`, `PetscDLLibraryAppend()`
@*/
PetscErrorCode PetscDLLibraryRegister_petscbinbcsr(void)
{
  PetscFunctionBegin;
  PetscCall(PetscBinBCSRRegisterAll());
  PetscFunctionReturn(0);
}
