/* KSPMCG's settings as functions (include/petscbinbcsr.h), one pair per option of KSPSetFromOptions_MCG:
   the fixed iteration count, the fused preconditioner, the true-residual check, its stagnation factor
   and the precision floor's rounding. The checks of a value live in the type's setter, so an option
   and a call refuse the same values with the same message. */
#include "mcg_impl.h"

namespace {

/* The getter of any setting, and the setter of one that takes every value of its type */
template <typename T, T KSP_MCG::*field> PetscErrorCode GetField(KSP ksp, T *v)
{
  PetscFunctionBegin;
  *v = ((KSP_MCG *)ksp->data)->*field;
  PetscFunctionReturn(0);
}

template <typename T, T KSP_MCG::*field> PetscErrorCode SetField(KSP ksp, T v)
{
  PetscFunctionBegin;
  ((KSP_MCG *)ksp->data)->*field = v;
  PetscFunctionReturn(0);
}

PetscErrorCode KSPMCGSetFixedIterations_MCG(KSP ksp, PetscInt n)
{
  PetscFunctionBegin;
  PetscCheck(n >= 0, PetscObjectComm((PetscObject)ksp), PETSC_ERR_ARG_OUTOFRANGE,
             "Fixed iteration count must be >= 0 (0 turns it off), not %" PetscInt_FMT, n);
  PetscCall(SetField<PetscInt, &KSP_MCG::fixed_its>(ksp, n));
  PetscFunctionReturn(0);
}

PetscErrorCode KSPMCGSetStagnation_MCG(KSP ksp, PetscReal factor)
{
  PetscFunctionBegin;
  /* 0 or NaN stopped at the first restart, above 1 let a restart grow the residual: neither is a factor */
  PetscCheck(factor > 0 && factor <= 1, PetscObjectComm((PetscObject)ksp), PETSC_ERR_ARG_OUTOFRANGE,
             "The stagnation factor (-ksp_mcg_stagnation) must be in (0, 1], not %g", (double)factor);
  PetscCall(SetField<PetscReal, &KSP_MCG::stagnation>(ksp, factor));
  PetscFunctionReturn(0);
}

PetscErrorCode KSPMCGSetPrecisionFloorRounding_MCG(KSP ksp, PetscReal u)
{
  PetscFunctionBegin;
  PetscCheck(
    u == MCG_FLOOR_AUTO || (u >= 0 && u < 1), PetscObjectComm((PetscObject)ksp), PETSC_ERR_ARG_OUTOFRANGE,
    "The precision floor's rounding (-ksp_mcg_precision_floor) must be -1 (from the matrix), 0 (off) or in (0, 1), not %g",
    (double)u);
  PetscCall(SetField<PetscReal, &KSP_MCG::floor_set>(ksp, u));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode KSPMCGComposeSettings(KSP ksp, PetscBool compose)
{
  PetscObject o = (PetscObject)ksp;
  const auto  f = [compose](auto fn) { return compose ? fn : nullptr; };

  PetscFunctionBegin;
  PetscCall(PetscObjectComposeFunction(o, "KSPMCGSetFixedIterations_C", f(KSPMCGSetFixedIterations_MCG)));
  PetscCall(
    PetscObjectComposeFunction(o, "KSPMCGGetFixedIterations_C", f(GetField<PetscInt, &KSP_MCG::fixed_its>)));
  PetscCall(
    PetscObjectComposeFunction(o, "KSPMCGSetFusedPC_C", f(SetField<PetscBool, &KSP_MCG::allow_fused>)));
  PetscCall(
    PetscObjectComposeFunction(o, "KSPMCGGetFusedPC_C", f(GetField<PetscBool, &KSP_MCG::allow_fused>)));
  PetscCall(
    PetscObjectComposeFunction(o, "KSPMCGSetVerifyResidual_C", f(SetField<PetscBool, &KSP_MCG::verify>)));
  PetscCall(
    PetscObjectComposeFunction(o, "KSPMCGGetVerifyResidual_C", f(GetField<PetscBool, &KSP_MCG::verify>)));
  PetscCall(PetscObjectComposeFunction(o, "KSPMCGSetStagnation_C", f(KSPMCGSetStagnation_MCG)));
  PetscCall(
    PetscObjectComposeFunction(o, "KSPMCGGetStagnation_C", f(GetField<PetscReal, &KSP_MCG::stagnation>)));
  PetscCall(PetscObjectComposeFunction(o, "KSPMCGSetPrecisionFloorRounding_C",
                                       f(KSPMCGSetPrecisionFloorRounding_MCG)));
  PetscCall(PetscObjectComposeFunction(o, "KSPMCGGetPrecisionFloorRounding_C",
                                       f(GetField<PetscReal, &KSP_MCG::floor_set>)));
  PetscFunctionReturn(0);
}

/*@
   KSPMCGSetFixedIterations - Makes `KSPMCG` run exactly n iterations per solve, with no convergence test

   Logically Collective

   Input Parameters:
+  ksp - the solver
-  n   - the number of iterations; 0 turns it off (the tolerances decide)

   Options Database Key:
.  -ksp_mcg_fixed_iterations <n> - sets the number of iterations

   Level: advanced

   Note:
   No residual norm is computed. A no-op on solvers of other types.

.seealso: `KSPMCG`, `KSPMCGGetFixedIterations()`
@*/
BINBCSR_TRY_SETTER(KSPMCGSetFixedIterations, KSP, KSP_CLASSID, PetscInt, PetscValidLogicalCollectiveInt)

/*@
   KSPMCGGetFixedIterations - Gets the fixed number of iterations per solve of `KSPMCG`

   Not Collective

   Input Parameter:
.  ksp - the solver

   Output Parameter:
.  n - the number of iterations; 0 when off and on solvers of other types

   Level: advanced

.seealso: `KSPMCG`, `KSPMCGSetFixedIterations()`
@*/
BINBCSR_TRY_GETTER(KSPMCGGetFixedIterations, KSP, KSP_CLASSID, PetscInt, PetscAssertPointer, 0)

/*@
   KSPMCGSetFusedPC - Sets whether `KSPMCG` applies `PCJACOBI`, `PCPBJACOBI` (block size 3) or `PCNONE`
   inside its fused vector pass

   Logically Collective

   Input Parameters:
+  ksp - the solver
-  flg - `PETSC_TRUE` (the default) to fuse those preconditioners; `PETSC_FALSE` to apply every
         preconditioner through `PCApply()`

   Options Database Key:
.  -ksp_mcg_fused_pc <bool> - sets it

   Level: advanced

   Note:
   The fused and the `PCApply()` paths give the same iterates up to rounding; the fused one reads and
   writes the vectors once per iteration. A no-op on solvers of other types.

.seealso: `KSPMCG`, `KSPMCGGetFusedPC()`
@*/
BINBCSR_TRY_SETTER(KSPMCGSetFusedPC, KSP, KSP_CLASSID, PetscBool, PetscValidLogicalCollectiveBool)

/*@
   KSPMCGGetFusedPC - Gets whether `KSPMCG` may apply its preconditioner inside the fused vector pass

   Not Collective

   Input Parameter:
.  ksp - the solver

   Output Parameter:
.  flg - the setting; `PETSC_FALSE` on solvers of other types

   Level: advanced

.seealso: `KSPMCG`, `KSPMCGSetFusedPC()`
@*/
BINBCSR_TRY_GETTER(KSPMCGGetFusedPC, KSP, KSP_CLASSID, PetscBool, PetscAssertPointer, PETSC_FALSE)

/*@
   KSPMCGSetVerifyResidual - Sets whether `KSPMCG` confirms convergence on the true residual b - A x
   before claiming it, restarting from the true residual when the check fails

   Logically Collective

   Input Parameters:
+  ksp - the solver
-  flg - `PETSC_TRUE` (the default) to check; `PETSC_FALSE` to trust the recursive residual

   Options Database Key:
.  -ksp_mcg_verify_residual <bool> - sets it

   Level: advanced

   Note:
   The check costs one product and one reduction per claimed convergence; without it a solve can claim
   a tolerance its rounded recurrences never reached. A no-op on solvers of other types.

.seealso: `KSPMCG`, `KSPMCGGetVerifyResidual()`, `KSPMCGSetStagnation()`
@*/
BINBCSR_TRY_SETTER(KSPMCGSetVerifyResidual, KSP, KSP_CLASSID, PetscBool, PetscValidLogicalCollectiveBool)

/*@
   KSPMCGGetVerifyResidual - Gets whether `KSPMCG` confirms convergence on the true residual

   Not Collective

   Input Parameter:
.  ksp - the solver

   Output Parameter:
.  flg - the setting; `PETSC_FALSE` on solvers of other types

   Level: advanced

.seealso: `KSPMCG`, `KSPMCGSetVerifyResidual()`
@*/
BINBCSR_TRY_GETTER(KSPMCGGetVerifyResidual, KSP, KSP_CLASSID, PetscBool, PetscAssertPointer, PETSC_FALSE)

/*@
   KSPMCGSetStagnation - Sets the factor by which each restart of `KSPMCG` from the true residual must
   shrink it; a restart that does not ends the solve with `KSP_DIVERGED_BREAKDOWN`

   Logically Collective

   Input Parameters:
+  ksp    - the solver
-  factor - in (0, 1]; the default is 0.5

   Options Database Key:
.  -ksp_mcg_stagnation <factor> - sets it

   Level: advanced

   Note:
   A no-op on solvers of other types.

.seealso: `KSPMCG`, `KSPMCGGetStagnation()`, `KSPMCGSetVerifyResidual()`
@*/
BINBCSR_TRY_SETTER(KSPMCGSetStagnation, KSP, KSP_CLASSID, PetscReal, PetscValidLogicalCollectiveReal)

/*@
   KSPMCGGetStagnation - Gets the factor by which each restart of `KSPMCG` must shrink the true residual

   Not Collective

   Input Parameter:
.  ksp - the solver

   Output Parameter:
.  factor - the factor; 0 on solvers of other types

   Level: advanced

.seealso: `KSPMCG`, `KSPMCGSetStagnation()`
@*/
BINBCSR_TRY_GETTER(KSPMCGGetStagnation, KSP, KSP_CLASSID, PetscReal, PetscAssertPointer, 0)

/*@
   KSPMCGSetPrecisionFloorRounding - Sets the relative rounding u of the operator's products, below
   whose floor u ||A|| ||x|| `KSPMCG` does not claim a tolerance

   Logically Collective

   Input Parameters:
+  ksp - the solver
-  u   - -1 (the default): from the matrix (2^-24 for `MATBINBCSR` single storage, none otherwise);
         0: no floor; a value in (0, 1): that rounding

   Options Database Key:
.  -ksp_mcg_precision_floor <u> - sets it

   Level: advanced

   Note:
   A solve that reaches the floor before its tolerance stops with `KSP_DIVERGED_BREAKDOWN`;
   `KSPMCGGetPrecisionFloor()` gives the floor of the last solve and whether it stopped there. A no-op on
   solvers of other types.

.seealso: `KSPMCG`, `KSPMCGGetPrecisionFloorRounding()`, `KSPMCGGetPrecisionFloor()`
@*/
BINBCSR_TRY_SETTER(KSPMCGSetPrecisionFloorRounding, KSP, KSP_CLASSID, PetscReal,
                   PetscValidLogicalCollectiveReal)

/*@
   KSPMCGGetPrecisionFloorRounding - Gets the relative rounding `KSPMCG` takes for its precision floor

   Not Collective

   Input Parameter:
.  ksp - the solver

   Output Parameter:
.  u - the setting (-1: from the matrix, 0: none); 0 on solvers of other types

   Level: advanced

.seealso: `KSPMCG`, `KSPMCGSetPrecisionFloorRounding()`, `KSPMCGGetPrecisionFloor()`
@*/
BINBCSR_TRY_GETTER(KSPMCGGetPrecisionFloorRounding, KSP, KSP_CLASSID, PetscReal, PetscAssertPointer, 0)
