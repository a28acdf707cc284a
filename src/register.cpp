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

const char *const MatBinBCSRPrecisions[] = {"double", "single", "MatBinBCSRPrecision",
                                            "MAT_BINBCSR_PRECISION_", nullptr};
const char *const MatBinBCSRDevices[]    = {
     "none", "reference", "cuda", "MatBinBCSRDevice", "MAT_BINBCSR_DEVICE_", nullptr};
const char *const MatBinBCSRTunes[] = {"off", "auto", "MatBinBCSRTune", "MAT_BINBCSR_TUNE_", nullptr};

static PetscBool registered = PETSC_FALSE;

/* The method's source, printed by -citations in any program that loads the plug-in. */
static const char binbcsr_citation[] =
  "@article{WeberBenderSchnoesStorkFellner2013,\n"
  "  author  = {Daniel Weber and Jan Bender and Markus Schnoes and Andr{\\'e} Stork and Dieter Fellner},\n"
  "  title   = {Efficient {GPU} Data Structures and Methods to Solve Sparse Linear Systems in Dynamics Applications},\n"
  "  journal = {Computer Graphics Forum},\n"
  "  volume  = {32},\n"
  "  number  = {1},\n"
  "  pages   = {16--26},\n"
  "  year    = {2013},\n"
  "  doi     = {10.1111/j.1467-8659.2012.03227.x}\n"
  "}\n"
  "@phdthesis{Weber2016,\n"
  "  author  = {Daniel Weber},\n"
  "  title   = {Interactive Physically Based Simulation: Efficient Higher-Order Elements, Multigrid Approaches and Massively Parallel Data Structures},\n"
  "  school  = {Technische Universit{\\\"a}t Darmstadt},\n"
  "  year    = {2016},\n"
  "  note    = {Section 2.5: {BIN-BCSR} and the merged {CG} method}\n"
  "}\n";
static PetscBool binbcsr_cited = PETSC_FALSE;

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
  PetscCall(PetscCitationsRegister(binbcsr_citation, &binbcsr_cited));
  PetscCall(MatRegister(MATSEQBINBCSR, MatCreate_SeqBinBCSR));
  PetscCall(MatRegister(MATMPIBINBCSR, MatCreate_MPIBinBCSR));
  PetscCall(MatRegisterRootName(MATBINBCSR, MATSEQBINBCSR, MATMPIBINBCSR));
  PetscCall(KSPRegister(KSPMCG, KSPCreate_MCG));
  for (MatFactorType ft : {MAT_FACTOR_ICC, MAT_FACTOR_CHOLESKY, MAT_FACTOR_ILU, MAT_FACTOR_LU})
    PetscCall(MatSolverTypeRegister(MATSOLVERPETSC, MATSEQBINBCSR, ft, MatGetFactor_SeqBinBCSR_Petsc));
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
