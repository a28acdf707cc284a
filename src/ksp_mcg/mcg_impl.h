/* KSPMCG private data, shared by mcg.cpp (object, options, view) and mcg_solve.cpp (the iteration). */
#ifndef BINBCSR_MCG_IMPL_H
#define BINBCSR_MCG_IMPL_H

#include "binbcsr_impl.h"
#include <petsc/private/kspimpl.h>

/* How z = M^-1 r is applied. The fused kinds apply it inside the vector pass of the iteration. */
typedef enum {
  MCG_PC_GENERIC = 0, /* PCApply between two vector passes */
  MCG_PC_JACOBI  = 1, /* fused: z = D^-1 r with D^-1 built by KSPMCG exactly as PCJACOBI builds it */
  MCG_PC_NONE    = 2, /* fused: z = r */
  MCG_PC_PBJACOBI =
    3 /* fused: z_b = D_b^-1 r_b with the inverses of the 3x3 diagonal blocks (MatInvertBlockDiagonal) */
} MCGPreconditioning;

typedef struct {
  /* user settings */
  PetscInt  fixed_its;   /* > 0: exactly this many iterations, no convergence test */
  PetscBool allow_fused; /* -ksp_mcg_fused_pc: apply jacobi/none inside the vector pass */
  PetscBool verify;      /* -ksp_mcg_verify_residual: confirm convergence on b - A x */
  PetscReal stagnation;  /* a restart must shrink the true residual by this factor, else give up */
  PetscReal floor_set;   /* -ksp_mcg_precision_floor: relative rounding u of the operator's products;
                              MCG_FLOOR_AUTO: from the matrix (single storage: 2^-24, else none), 0: off */

  /* chosen at each solve */
  MCGPreconditioning how;
  char               why_generic[160]; /* why the fused path was not taken (for KSPView) */
  PetscBool          mat_fused;        /* Amat composes "MatMultDotLocal_C" */
  PetscBool          single_storage;   /* Amat stores its values in single precision */
  PetscReal          roundoff;         /* u used in this solve (0: no precision floor) */

  /* Jacobi diagonal owned by KSPMCG, rebuilt when the preconditioning matrix changes */
  Vec              dinv;
  PetscObjectId    dinv_id;
  PetscObjectState dinv_state;
  PetscInt         dinv_zeros; /* global number of zero diagonal entries found at the last build */

  /* point-block Jacobi: inverses of the 3x3 diagonal blocks (column-major), rebuilt likewise */
  PetscScalar     *binv;
  PetscInt         binv_n; /* number of local block rows binv holds */
  PetscObjectId    binv_id;
  PetscObjectState binv_state;

  /* what the last solve did (for KSPView and PetscInfo) */
  PetscInt  restarts;    /* residual replacements after a failed true-residual check */
  PetscReal true_rnorm;  /* norm of b - A x at the last check, -1 when none was made */
  PetscInt  true_checks; /* number of true-residual checks of the last solve */
  PetscReal drift;       /* estimated rounding drift of the recursive residual at the last claim */
  PetscReal floor;       /* precision floor u ||A|| ||x|| (2-norm of b - A x) at the end, 0 when none */
  PetscBool floor_hit;   /* the last solve's residual fell below the precision floor */
  PetscReal floor_anorm, floor_xnorm; /* the estimates of ||A|| and ||x|| the floor was made of */
} KSP_MCG;

/* A claim of convergence at least this far above the estimated rounding drift is not re-checked. */
#define MCG_DRIFT_MARGIN 100.0

/* -ksp_mcg_precision_floor default: take the operator's rounding from the matrix. */
#define MCG_FLOOR_AUTO -1.0
/* Relative rounding of values stored in single precision (round to nearest: 2^-24). */
#define MCG_SINGLE_ROUNDOFF 5.9604644775390625e-08
/* Below the precision floor, iterate until the residual of the rounded system is this fraction of it. */
#define MCG_FLOOR_DEPTH 0.1

PETSC_INTERN PetscErrorCode KSPSolve_MCG(KSP);
/* composes (or, compose false, removes) the settings' functions of mcg_settings.cpp */
PETSC_INTERN PetscErrorCode KSPMCGComposeSettings(KSP, PetscBool compose);
/* The passes of one iteration (mcg_passes.cpp). */
PETSC_INTERN PetscErrorCode MCGChoosePath(KSP, Mat);
PETSC_INTERN PetscErrorCode MCGUpdateDiagonal(KSP);
PETSC_INTERN PetscErrorCode MCGReduce(KSP, PetscScalar *dots, PetscMPIInt count);
PETSC_INTERN PetscErrorCode MCGMatMultDot(KSP, Mat A, Vec u, Vec w, PetscScalar *uw);
PETSC_INTERN PetscErrorCode MCGPrecondition(KSP, Vec R, Vec U, PetscScalar *dots);
PETSC_INTERN PetscErrorCode MCGUpdate(KSP, PetscScalar alpha, PetscScalar beta, Vec X, Vec R, Vec U, Vec W,
                                      Vec P, Vec S, PetscScalar *dots);
PETSC_INTERN PetscErrorCode MCGUpdateBlockDiagonal(KSP);
/* Whether KSPMCG's own preconditioner data (built from the Pmat with id/state built_id/built_state; built:
   it exists) must be rebuilt: the Pmat changed and the PC is not told to reuse its preconditioner. */
PETSC_INTERN PetscErrorCode MCGPreconditionerStale(KSP, PetscBool built, PetscObjectId built_id,
                                                   PetscObjectState built_state, Mat *Pmat, PetscObjectId *id,
                                                   PetscObjectState *state, PetscBool *stale);

#endif
