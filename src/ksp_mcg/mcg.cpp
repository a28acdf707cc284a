/* KSPMCG ("mcg"): merged preconditioned conjugate gradient with one global reduction per iteration
   (Chronopoulos-Gear formulation; the iteration is in mcg_solve.cpp). This file holds the object:
   creation, options, view and setup (the settings' functions are in mcg_settings.cpp). */
#include "mcg_impl.h"

static PetscErrorCode KSPSetUp_MCG(KSP ksp)
{
  PetscFunctionBegin;
  /* r, u = M^-1 r, w = A u, p, s = A p */
  PetscCall(KSPSetWorkVecs(ksp, 5));
  PetscFunctionReturn(0);
}

static PetscErrorCode KSPReset_MCG(KSP ksp)
{
  KSP_MCG *mcg = (KSP_MCG *)ksp->data;

  PetscFunctionBegin;
  PetscCall(VecDestroy(&mcg->dinv));
  mcg->dinv_id    = 0;
  mcg->dinv_state = 0;
  PetscCall(PetscFree(mcg->binv));
  mcg->binv_n     = 0;
  mcg->binv_id    = 0;
  mcg->binv_state = 0;
  PetscFunctionReturn(0);
}

static PetscErrorCode KSPDestroy_MCG(KSP ksp)
{
  PetscFunctionBegin;
  PetscCall(KSPReset_MCG(ksp));
  PetscCall(KSPDestroyDefault(ksp));
  PetscCall(PetscObjectComposeFunction((PetscObject)ksp, "KSPMCGGetPrecisionFloor_C", nullptr));
  PetscCall(KSPMCGComposeSettings(ksp, PETSC_FALSE));
  PetscFunctionReturn(0);
}

static PetscErrorCode KSPView_MCG(KSP ksp, PetscViewer viewer)
{
  KSP_MCG  *mcg = (KSP_MCG *)ksp->data;
  PetscBool iascii;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &iascii));
  if (!iascii) PetscFunctionReturn(0);
  PetscCall(
    PetscViewerASCIIPrintf(viewer, "  merged CG (Chronopoulos-Gear): one global reduction per iteration\n"));
  if (mcg->fixed_its > 0)
    PetscCall(PetscViewerASCIIPrintf(
      viewer, "  fixed iterations: %" PetscInt_FMT " per solve, no convergence test (tolerances ignored)\n",
      mcg->fixed_its));
  else
    PetscCall(PetscViewerASCIIPrintf(
      viewer,
      "  fixed iterations: off (tolerances decide); true-residual check before claiming convergence: %s\n",
      mcg->verify ? "on" : "off"));
  if (ksp->setupstage == KSP_SETUP_NEW && !mcg->dinv && !mcg->why_generic[0]) {
    PetscCall(PetscViewerASCIIPrintf(
      viewer,
      "  fused preconditioner (jacobi/pbjacobi/none in the vector pass): %s; decided at the first solve\n",
      mcg->allow_fused ? "allowed" : "off"));
  } else {
    switch (mcg->how) {
    case MCG_PC_JACOBI:
      PetscCall(PetscViewerASCIIPrintf(
        viewer, "  fast path: on, Jacobi fused into the vector pass (own D^-1 from MatGetDiagonal%s)\n",
        mcg->dinv_zeros ? ", zero diagonal entries replaced as PCJACOBI does" : ""));
      break;
    case MCG_PC_PBJACOBI:
      PetscCall(PetscViewerASCIIPrintf(
        viewer,
        "  fast path: on, point-block Jacobi fused into the vector pass (own 3x3 block inverses from MatInvertBlockDiagonal)\n"));
      break;
    case MCG_PC_NONE:
      PetscCall(
        PetscViewerASCIIPrintf(viewer, "  fast path: on, no preconditioner, one fused vector pass\n"));
      break;
    default:
      PetscCall(PetscViewerASCIIPrintf(
        viewer, "  fast path: off (%s): PCApply between two fused vector passes\n", mcg->why_generic));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "  matrix product fused with u.Au: %s\n",
                                     mcg->mat_fused ? "yes (matrix type provides MatMultDotLocal)"
                                                    : "no (MatMult, then a local dot)"));
  }
  if (mcg->fixed_its <= 0) {
    if (mcg->floor_set == 0)
      PetscCall(PetscViewerASCIIPrintf(viewer, "  precision floor: off (-ksp_mcg_precision_floor 0)\n"));
    else if (mcg->floor_set > 0 || mcg->roundoff > 0)
      PetscCall(PetscViewerASCIIPrintf(
        viewer,
        "  precision floor: operator products rounded at u = %g (%s); no tolerance is claimed below u ||A|| ||x||, the solve stops there with DIVERGED_BREAKDOWN\n",
        (double)(mcg->floor_set > 0 ? mcg->floor_set : mcg->roundoff),
        mcg->floor_set > 0 ? "-ksp_mcg_precision_floor" : "values stored in single precision"));
    else if (ksp->setupstage == KSP_SETUP_NEW)
      PetscCall(PetscViewerASCIIPrintf(
        viewer,
        "  precision floor: decided from the matrix at the first solve (single-precision storage: u = %g)\n",
        MCG_SINGLE_ROUNDOFF));
    else
      PetscCall(
        PetscViewerASCIIPrintf(viewer, "  precision floor: none (operator products in double precision)\n"));
  }
  if (mcg->floor > 0)
    PetscCall(PetscViewerASCIIPrintf(
      viewer, "  last solve: precision floor u ||A|| ||x|| = %g (||A|| >= %g, ||x|| = %g)%s\n",
      (double)mcg->floor, (double)mcg->floor_anorm, (double)mcg->floor_xnorm,
      mcg->floor_hit && ksp->reason == KSP_DIVERGED_BREAKDOWN
        ? ": REACHED before the tolerance, stopped there (DIVERGED_BREAKDOWN; the residual against the assembled values is about the floor)"
      : mcg->floor_hit ? ": reached"
                       : ", not reached"));
  if (mcg->drift > 0)
    PetscCall(PetscViewerASCIIPrintf(
      viewer,
      "  last solve: estimated rounding drift of the recursive residual %g (claims %g times above it are not re-checked)\n",
      (double)mcg->drift, MCG_DRIFT_MARGIN));
  if (mcg->true_checks)
    PetscCall(PetscViewerASCIIPrintf(viewer,
                                     "  last solve: %" PetscInt_FMT " true-residual checks, %" PetscInt_FMT
                                     " restarts, true residual norm %g\n",
                                     mcg->true_checks, mcg->restarts, (double)mcg->true_rnorm));
  PetscFunctionReturn(0);
}

static PetscErrorCode KSPMCGGetPrecisionFloor_MCG(KSP ksp, PetscReal *floor, PetscBool *stopped)
{
  const KSP_MCG *mcg = (const KSP_MCG *)ksp->data;

  PetscFunctionBegin;
  if (floor) *floor = mcg->floor;
  if (stopped) *stopped = mcg->floor_hit && ksp->reason == KSP_DIVERGED_BREAKDOWN ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

static PetscErrorCode KSPSetFromOptions_MCG(KSP ksp, PetscOptionItems *PetscOptionsObject)
{
  KSP_MCG  *mcg = (KSP_MCG *)ksp->data;
  PetscInt  n   = mcg->fixed_its;
  PetscBool flg;

  PetscFunctionBegin;
  PetscOptionsHeadBegin(PetscOptionsObject, "KSP MCG (merged CG) options");
  PetscCall(PetscOptionsInt("-ksp_mcg_fixed_iterations",
                            "Run exactly this many iterations per solve, no convergence test (0: off)",
                            "KSPMCGSetFixedIterations", n, &n, &flg));
  if (flg) PetscCall(KSPMCGSetFixedIterations(ksp, n));
  PetscBool fused = mcg->allow_fused, verify = mcg->verify, set;
  PetscCall(PetscOptionsBool("-ksp_mcg_fused_pc",
                             "Apply PCJACOBI/PCPBJACOBI/PCNONE inside the fused vector pass",
                             "KSPMCGSetFusedPC", fused, &fused, &set));
  if (set) PetscCall(KSPMCGSetFusedPC(ksp, fused));
  PetscCall(PetscOptionsBool("-ksp_mcg_verify_residual",
                             "Confirm convergence on the true residual b - A x, restarting if it fails",
                             "KSPMCGSetVerifyResidual", verify, &verify, &set));
  if (set) PetscCall(KSPMCGSetVerifyResidual(ksp, verify));
  /* the setters check the values: a refused one never reaches the KSP */
  PetscReal stagnation = mcg->stagnation, floor_set = mcg->floor_set;
  PetscCall(PetscOptionsReal("-ksp_mcg_stagnation",
                             "Each restart must shrink the true residual by this factor",
                             "KSPMCGSetStagnation", stagnation, &stagnation, &set));
  if (set) PetscCall(KSPMCGSetStagnation(ksp, stagnation));
  PetscCall(PetscOptionsReal(
    "-ksp_mcg_precision_floor",
    "Relative rounding u of the operator's products: stop at u ||A|| ||x|| instead of claiming a tolerance below it (-1: from the matrix, 0: off)",
    "KSPMCGSetPrecisionFloorRounding", floor_set, &floor_set, &set));
  if (set) PetscCall(KSPMCGSetPrecisionFloorRounding(ksp, floor_set));
  PetscOptionsHeadEnd();
  PetscFunctionReturn(0);
}

/* -ksp_converged_reason: before PETSc's line (PETSc calls registered views first), say that a DIVERGED_BREAKDOWN was the precision floor.
   Registered once per KSP with KSPConvergedReasonViewSet (PETSc calls those views after every solve),
   it prints only when -ksp_converged_reason is given and the KSP is still KSPMCG. */
static PetscErrorCode KSPConvergedReasonView_MCGFloor(KSP ksp, void *)
{
  PetscBool         ismcg, flg, iascii;
  PetscViewer       viewer;
  PetscViewerFormat format;
  KSP_MCG          *mcg;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPMCG, &ismcg));
  if (!ismcg) PetscFunctionReturn(0);
  mcg = (KSP_MCG *)ksp->data;
  if (!mcg->floor_hit || ksp->reason != KSP_DIVERGED_BREAKDOWN) PetscFunctionReturn(0);
  PetscCall(PetscOptionsCreateViewer(PetscObjectComm((PetscObject)ksp), ((PetscObject)ksp)->options,
                                     ((PetscObject)ksp)->prefix, "-ksp_converged_reason", &viewer, &format,
                                     &flg));
  if (!flg) PetscFunctionReturn(0);
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &iascii));
  if (iascii) {
    PetscCall(PetscViewerASCIIAddTab(viewer, ((PetscObject)ksp)->tablevel));
    PetscCall(PetscViewerASCIIPrintf(
      viewer,
      "KSPMCG reached the precision floor of its operator: ||b - A x|| ~ u ||A|| ||x|| = %g (u = %g%s) before the tolerance; the solve stopped there\n",
      (double)mcg->floor, (double)mcg->roundoff,
      mcg->single_storage ? ", values stored in single precision" : ""));
    PetscCall(PetscViewerASCIISubtractTab(viewer, ((PetscObject)ksp)->tablevel));
  }
  PetscCall(PetscViewerDestroy(&viewer));
  PetscFunctionReturn(0);
}

/*MC
   KSPMCG - "mcg": merged preconditioned conjugate gradient for symmetric positive definite systems,
   with one global reduction per iteration whatever the norm type

   Options Database Keys:
+  -ksp_mcg_fixed_iterations <n>   - exactly n iterations per solve, no convergence test (0: off), see `KSPMCGSetFixedIterations()`
.  -ksp_mcg_fused_pc <bool>        - apply `PCJACOBI`, `PCPBJACOBI` (block size 3) or `PCNONE` inside the fused vector pass (default true), see `KSPMCGSetFusedPC()`
.  -ksp_mcg_verify_residual <bool> - confirm convergence on the true residual b - A x, restarting if it fails (default true), see `KSPMCGSetVerifyResidual()`
.  -ksp_mcg_stagnation <f>         - each restart from the true residual must shrink it by f (default 0.5), see `KSPMCGSetStagnation()`
-  -ksp_mcg_precision_floor <u>    - relative rounding of the operator's products: the solve stops with
                                     `KSP_DIVERGED_BREAKDOWN` at u ||A|| ||x|| instead of claiming a tolerance
                                     below it (default -1: from the matrix, 2^-24 for `MATBINBCSR` single
                                     storage and none otherwise; 0: off), see `KSPMCGSetPrecisionFloorRounding()`

   Level: intermediate

   Notes:
   The Chronopoulos-Gear formulation of CG. With u = M^-1 r, w = A u, gamma = r.u and delta = u.w,
   each iteration is
.vb
   beta  = gamma_k / gamma_{k-1}                (0 at the start and after a restart)
   pAp   = delta_k - beta^2 pAp_{k-1}
   alpha = gamma_k / pAp
   pass 1 (vectors): p = u + beta p; s = w + beta s; x += alpha p; r -= alpha s; u = M^-1 r;
                     local r.u, r.r, u.u
   pass 2 (matrix):  w = A u and the local u.w  (MatMultDotLocal())
   reduction:        {r.u, u.w, r.r, u.u} in one MPI_Allreduce
.ve
   It is CG in exact arithmetic (s = A p is carried by a recurrence instead of a second product), so
   iterates and iteration counts match `KSPCG` up to rounding; the residual norm of iteration k is
   known at the end of iteration k, as in `KSPCG`. With `PCJACOBI`, `PCPBJACOBI` (block size 3: its own
   inverses of the 3x3 diagonal blocks, rebuilt on a refill) or `PCNONE` pass 1 is one fused loop; other preconditioners go through `PCApply()`. On a `MATBINBCSR` matrix pass 2 is one sweep
   over the bins. docs/ksp_mcg.md has the derivation, the restarts and the measurements.

.seealso: `KSPCG`, `KSPCreate()`, `KSPSetType()`, `KSPMCGSetFixedIterations()`, `MatMultDotLocal()`, `MATBINBCSR`
M*/
PetscErrorCode KSPCreate_MCG(KSP ksp)
{
  KSP_MCG *mcg;

  PetscFunctionBegin;
  PetscCall(PetscNew(&mcg));
  mcg->allow_fused = PETSC_TRUE;
  mcg->verify      = PETSC_TRUE;
  mcg->stagnation  = 0.5;
  mcg->true_rnorm  = -1.0;
  mcg->floor_set   = MCG_FLOOR_AUTO;
  ksp->data        = (void *)mcg;
  PetscCall(KSPSetSupportedNorm(ksp, KSP_NORM_PRECONDITIONED, PC_LEFT, 3));
  PetscCall(KSPSetSupportedNorm(ksp, KSP_NORM_UNPRECONDITIONED, PC_LEFT, 2));
  PetscCall(KSPSetSupportedNorm(ksp, KSP_NORM_NATURAL, PC_LEFT, 2));
  PetscCall(KSPSetSupportedNorm(ksp, KSP_NORM_NONE, PC_LEFT, 1));
  ksp->ops->setup          = KSPSetUp_MCG;
  ksp->ops->solve          = KSPSolve_MCG;
  ksp->ops->reset          = KSPReset_MCG;
  ksp->ops->destroy        = KSPDestroy_MCG;
  ksp->ops->view           = KSPView_MCG;
  ksp->ops->setfromoptions = KSPSetFromOptions_MCG;
  ksp->ops->buildsolution  = KSPBuildSolutionDefault;
  ksp->ops->buildresidual  = KSPBuildResidualDefault;
  PetscCall(
    PetscObjectComposeFunction((PetscObject)ksp, "KSPMCGGetPrecisionFloor_C", KSPMCGGetPrecisionFloor_MCG));
  PetscCall(KSPMCGComposeSettings(ksp, PETSC_TRUE));
  {
    PetscBool registered = PETSC_FALSE;
    for (PetscInt k = 0; k < ksp->numberreasonviews; k++)
      if (ksp->reasonview[k] == KSPConvergedReasonView_MCGFloor) registered = PETSC_TRUE;
    if (!registered)
      PetscCall(KSPConvergedReasonViewSet(ksp, KSPConvergedReasonView_MCGFloor, nullptr, nullptr));
  }
  PetscFunctionReturn(0);
}

/*@
   KSPMCGGetPrecisionFloor - Gets the precision floor of the last `KSPMCG` solve and whether the solve
   stopped at it

   Not Collective

   Input Parameter:
.  ksp - the solver

   Output Parameters:
+  floor   - u ||A|| ||x||, the 2-norm of b - A x below which the operator's rounded products (single
             precision storage, or `-ksp_mcg_precision_floor`) cannot resolve the residual; 0 when there
             is none (pass NULL if not wanted)
-  stopped - `PETSC_TRUE` when the solve reached the floor before its tolerance and stopped there with
             `KSP_DIVERGED_BREAKDOWN` (pass NULL if not wanted)

   Level: intermediate

   Note:
   Tells a caller why a solve ended in `KSP_DIVERGED_BREAKDOWN`: a tolerance below what single storage
   resolves, not a breakdown of the iteration; a looser tolerance or double storage
   (`MatBinBCSRSetPrecision()`) converges. 0 and `PETSC_FALSE` on solvers of other types.

.seealso: `KSPMCG`, `MatBinBCSRSetPrecision()`, `KSPGetConvergedReason()`
@*/
PetscErrorCode KSPMCGGetPrecisionFloor(KSP ksp, PetscReal *floor, PetscBool *stopped)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(ksp, KSP_CLASSID, 1);
  if (floor) *floor = 0;
  if (stopped) *stopped = PETSC_FALSE;
  PetscTryMethod(ksp, "KSPMCGGetPrecisionFloor_C", (KSP, PetscReal *, PetscBool *), (ksp, floor, stopped));
  PetscFunctionReturn(0);
}
