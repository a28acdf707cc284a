/* KSPMCG's passes over the vectors and its product (mcg_solve.cpp runs the iteration): the path that
   applies the preconditioner, the Jacobi diagonal, the one reduction, the fused product and dot, the
   preconditioning pass and the fused update pass. */
#include "mcg_impl.h"
#include "mcg_kernels.h"

/* Decides how z = M^-1 r is applied in this solve, and why not fused when it is not. */
PetscErrorCode MCGChoosePath(KSP ksp, Mat Amat)
{
  KSP_MCG     *mcg = (KSP_MCG *)ksp->data;
  PC           pc  = ksp->pc;
  PetscBool    isjacobi, isnone, ispbjacobi;
  MatNullSpace nullsp                                   = nullptr;
  PetscErrorCode (*fused)(Mat, Vec, Vec, PetscScalar *) = nullptr;

  PetscFunctionBegin;
  PetscCall(PetscObjectQueryFunction((PetscObject)Amat, "MatMultDotLocal_C", &fused));
  mcg->mat_fused      = (fused && !ksp->transpose_solve) ? PETSC_TRUE : PETSC_FALSE;
  mcg->how            = MCG_PC_GENERIC;
  mcg->why_generic[0] = 0;
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCJACOBI, &isjacobi));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCNONE, &isnone));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCPBJACOBI, &ispbjacobi));
  PetscCall(MatGetNullSpace(Amat, &nullsp));
  if (!mcg->allow_fused) {
    PetscCall(PetscSNPrintf(mcg->why_generic, sizeof(mcg->why_generic), "turned off (-ksp_mcg_fused_pc 0)"));
  } else if (ksp->transpose_solve) {
    PetscCall(PetscSNPrintf(mcg->why_generic, sizeof(mcg->why_generic), "transpose solve"));
  } else if (nullsp) {
    /* KSP_PCApply() removes the operator's null space from z; keep that behaviour */
    PetscCall(PetscSNPrintf(mcg->why_generic, sizeof(mcg->why_generic), "the operator has a null space"));
  } else if (isnone) {
    mcg->how = MCG_PC_NONE;
  } else if (isjacobi) {
    PCJacobiType type;
    PetscCall(PCJacobiGetType(pc, &type));
    if (type == PC_JACOBI_DIAGONAL) mcg->how = MCG_PC_JACOBI;
    else
      PetscCall(PetscSNPrintf(mcg->why_generic, sizeof(mcg->why_generic),
                              "jacobi type %s is applied with PCApply", PCJacobiTypes[type]));
  } else if (ispbjacobi) {
    Mat      Pmat;
    PetscInt bs, n;
    PetscCall(PCGetOperators(pc, nullptr, &Pmat));
    PetscCall(MatGetBlockSize(Pmat, &bs));
    PetscCall(MatGetLocalSize(Pmat, &n, nullptr));
    if (bs == 3 && n % 3 == 0) mcg->how = MCG_PC_PBJACOBI;
    else
      PetscCall(PetscSNPrintf(
        mcg->why_generic, sizeof(mcg->why_generic),
        "pbjacobi is fused for block size 3, the matrix has %" PetscInt_FMT ": applied with PCApply", bs));
  } else {
    PetscCall(PetscSNPrintf(mcg->why_generic, sizeof(mcg->why_generic), "PC type %s is applied with PCApply",
                            ((PetscObject)pc)->type_name ? ((PetscObject)pc)->type_name : "(unset)"));
  }
  PetscFunctionReturn(0);
}

/* D^-1 built the way PCSetUp_Jacobi builds it (PETSc 3.18): reciprocal of the diagonal (zeros stay
   zero), absolute value if -pc_jacobi_abs, and zeros replaced by 1 when -pc_jacobi_fixdiagonal (the
   default) unless the matrix is known to be SPD. Rebuilt when the preconditioning matrix or its state
   changes, except when the PC is told to reuse its preconditioner. */
PetscErrorCode MCGPreconditionerStale(KSP ksp, PetscBool built, PetscObjectId built_id,
                                      PetscObjectState built_state, Mat *Pmat, PetscObjectId *id,
                                      PetscObjectState *state, PetscBool *stale)
{
  PetscBool reuse;

  PetscFunctionBegin;
  PetscCall(PCGetOperators(ksp->pc, nullptr, Pmat));
  PetscCall(PetscObjectGetId((PetscObject)*Pmat, id));
  PetscCall(PetscObjectStateGet((PetscObject)*Pmat, state));
  PetscCall(PCGetReusePreconditioner(ksp->pc, &reuse));
  *stale = (PetscBool) !(built && (reuse || (*id == built_id && *state == built_state)));
  PetscFunctionReturn(0);
}

PetscErrorCode MCGUpdateDiagonal(KSP ksp)
{
  KSP_MCG         *mcg = (KSP_MCG *)ksp->data;
  PC               pc  = ksp->pc;
  Mat              Pmat;
  PetscObjectId    id;
  PetscObjectState state;
  PetscBool        stale, useabs, fixdiag, isset = PETSC_FALSE,
                                    isspd = PETSC_FALSE; /* MatIsSPDKnown leaves isspd unset when unknown */
  PetscInt     n, zeros = 0;
  PetscScalar *d;

  PetscFunctionBegin;
  PetscCall(MCGPreconditionerStale(ksp, (PetscBool) !!mcg->dinv, mcg->dinv_id, mcg->dinv_state, &Pmat, &id,
                                   &state, &stale));
  if (!stale) PetscFunctionReturn(0);
  if (mcg->dinv) {
    PetscInt nd, nm;
    PetscCall(VecGetLocalSize(mcg->dinv, &nd));
    PetscCall(MatGetLocalSize(Pmat, &nm, nullptr));
    if (nd != nm) PetscCall(VecDestroy(&mcg->dinv));
  }
  if (!mcg->dinv) PetscCall(MatCreateVecs(Pmat, &mcg->dinv, nullptr));
  PetscCall(MatGetDiagonal(Pmat, mcg->dinv));
  PetscCall(VecReciprocal(mcg->dinv));
  PetscCall(PCJacobiGetUseAbs(pc, &useabs));
  if (useabs) PetscCall(VecAbs(mcg->dinv));
  PetscCall(PCJacobiGetFixDiagonal(pc, &fixdiag));
  PetscCall(MatIsSPDKnown(Pmat, &isset, &isspd));
  PetscCall(VecGetLocalSize(mcg->dinv, &n));
  PetscCall(VecGetArray(mcg->dinv, &d));
  for (PetscInt i = 0; i < n; i++) {
    if (d[i] == (PetscScalar)0.0) {
      zeros++;
      if (fixdiag && (!isset || !isspd)) d[i] = 1.0;
    }
  }
  PetscCall(VecRestoreArray(mcg->dinv, &d));
  PetscCall(
    MPIU_Allreduce(&zeros, &mcg->dinv_zeros, 1, MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)ksp)));
  if (mcg->dinv_zeros)
    PetscCall(PetscInfo(ksp,
                        "Zero detected in diagonal of matrix (%" PetscInt_FMT
                        " entries), using %s at those locations as PCJACOBI does\n",
                        mcg->dinv_zeros, fixdiag && (!isset || !isspd) ? "1" : "0"));
  mcg->dinv_id    = id;
  mcg->dinv_state = state;
  PetscFunctionReturn(0);
}

/* The one global reduction of an iteration: sums the local dots over the KSP's communicator. */
PetscErrorCode MCGReduce(KSP ksp, PetscScalar *dots, PetscMPIInt count)
{
  PetscFunctionBegin;
  PetscCall(PetscLogEventBegin(KSP_MCG_Reduction, ksp, 0, 0, 0));
  PetscCallMPI(
    MPI_Allreduce(MPI_IN_PLACE, dots, count, MPIU_SCALAR, MPIU_SUM, PetscObjectComm((PetscObject)ksp)));
  PetscCall(PetscLogEventEnd(KSP_MCG_Reduction, ksp, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* w = A u and the local u.w. */
PetscErrorCode MCGMatMultDot(KSP ksp, Mat A, Vec u, Vec w, PetscScalar *uw)
{
  PetscFunctionBegin;
  if (!ksp->transpose_solve) {
    PetscCall(MatMultDotLocal(A, u, w, uw));
  } else {
    PetscCall(KSP_MatMult(ksp, A, u, w));
    PetscCall(MatBinBCSRVecDotLocal_Private(u, w, uw));
  }
  PetscFunctionReturn(0);
}

/* u = M^-1 r and the local r.u, r.r, u.u (start of a solve, restart, true-residual check). */
PetscErrorCode MCGPrecondition(KSP ksp, Vec R, Vec U, PetscScalar *dots)
{
  KSP_MCG           *mcg = (KSP_MCG *)ksp->data;
  const PetscScalar *r;
  PetscScalar        ru = 0, rr = 0, uu = 0;
  PetscInt           n;

  PetscFunctionBegin;
  if (mcg->how == MCG_PC_GENERIC) PetscCall(KSP_PCApply(ksp, R, U));
  PetscCall(PetscLogEventBegin(KSP_MCG_FusedUpdate, ksp, 0, 0, 0));
  PetscCall(VecGetLocalSize(R, &n));
  PetscCall(VecGetArrayRead(R, &r));
  if (mcg->how == MCG_PC_GENERIC) {
    const PetscScalar *u;
    PetscCall(VecGetArrayRead(U, &u));
#pragma omp simd reduction(+ : ru, rr, uu)
    for (PetscInt i = 0; i < n; i++) mcg_dots_index<PetscScalar>(i, r, u, ru, rr, uu);
    PetscCall(VecRestoreArrayRead(U, &u));
  } else {
    PetscScalar *u;
    PetscCall(VecGetArrayWrite(U, &u));
    if (mcg->how == MCG_PC_JACOBI) {
      const PetscScalar *dinv;
      PetscCall(VecGetArrayRead(mcg->dinv, &dinv));
#pragma omp simd reduction(+ : ru, rr, uu)
      for (PetscInt i = 0; i < n; i++) mcg_precondition_index<true, PetscScalar>(i, r, dinv, u, ru, rr, uu);
      PetscCall(VecRestoreArrayRead(mcg->dinv, &dinv));
    } else if (mcg->how == MCG_PC_PBJACOBI) {
      const PetscScalar *binv = mcg->binv;
      for (PetscInt b = 0; b < n / 3; b++) mcg_precondition_block3<PetscScalar>(b, r, binv, u, ru, rr, uu);
    } else {
#pragma omp simd reduction(+ : ru, rr, uu)
      for (PetscInt i = 0; i < n; i++)
        mcg_precondition_index<false, PetscScalar>(i, r, nullptr, u, ru, rr, uu);
    }
    PetscCall(VecRestoreArrayWrite(U, &u));
  }
  PetscCall(VecRestoreArrayRead(R, &r));
  PetscCall(PetscLogFlops(7.0 * n));
  PetscCall(PetscLogEventEnd(KSP_MCG_FusedUpdate, ksp, 0, 0, 0));
  dots[MCG_DOT_RU] = ru;
  dots[MCG_DOT_RR] = rr;
  dots[MCG_DOT_UU] = uu;
  PetscFunctionReturn(0);
}

/* The vector pass of an iteration: p, s, x, r updated, u = M^-1 r, local r.u, r.r, u.u. */
PetscErrorCode MCGUpdate(KSP ksp, PetscScalar alpha, PetscScalar beta, Vec X, Vec R, Vec U, Vec W, Vec P,
                         Vec S, PetscScalar *dots)
{
  KSP_MCG           *mcg = (KSP_MCG *)ksp->data;
  const PetscScalar *w;
  PetscScalar       *x, *r, *u, *p, *s, ru = 0, rr = 0, uu = 0, xx = 0;
  PetscInt           n;

  PetscFunctionBegin;
  PetscCall(PetscLogEventBegin(KSP_MCG_FusedUpdate, ksp, 0, 0, 0));
  PetscCall(VecGetLocalSize(R, &n));
  PetscCall(VecGetArray(X, &x));
  PetscCall(VecGetArray(R, &r));
  PetscCall(VecGetArray(U, &u));
  PetscCall(VecGetArrayRead(W, &w));
  PetscCall(VecGetArray(P, &p));
  PetscCall(VecGetArray(S, &s));
  if (mcg->how == MCG_PC_GENERIC) {
#pragma omp simd reduction(+ : xx)
    for (PetscInt i = 0; i < n; i++) mcg_update_index_nopc<PetscScalar>(i, alpha, beta, u, w, p, s, x, r, xx);
  } else if (mcg->how == MCG_PC_JACOBI) {
    const PetscScalar *dinv;
    PetscCall(VecGetArrayRead(mcg->dinv, &dinv));
#pragma omp simd reduction(+ : ru, rr, uu, xx)
    for (PetscInt i = 0; i < n; i++)
      mcg_update_index<true, PetscScalar>(i, alpha, beta, u, w, p, s, x, r, dinv, ru, rr, uu, xx);
    PetscCall(VecRestoreArrayRead(mcg->dinv, &dinv));
  } else if (mcg->how == MCG_PC_PBJACOBI) {
    const PetscScalar *binv = mcg->binv;
    for (PetscInt b = 0; b < n / 3; b++)
      mcg_update_block3<PetscScalar>(b, alpha, beta, u, w, p, s, x, r, binv, ru, rr, uu, xx);
  } else {
#pragma omp simd reduction(+ : ru, rr, uu, xx)
    for (PetscInt i = 0; i < n; i++)
      mcg_update_index<false, PetscScalar>(i, alpha, beta, u, w, p, s, x, r, nullptr, ru, rr, uu, xx);
  }
  PetscCall(VecRestoreArray(S, &s));
  PetscCall(VecRestoreArray(P, &p));
  PetscCall(VecRestoreArrayRead(W, &w));
  PetscCall(VecRestoreArray(U, &u));
  PetscCall(VecRestoreArray(R, &r));
  PetscCall(VecRestoreArray(X, &x));
  PetscCall(PetscLogFlops((mcg->how == MCG_PC_GENERIC    ? 10.0
                           : mcg->how == MCG_PC_PBJACOBI ? 26.0
                                                         : 17.0) *
                          n));
  PetscCall(PetscLogEventEnd(KSP_MCG_FusedUpdate, ksp, 0, 0, 0));
  if (mcg->how == MCG_PC_GENERIC) {
    /* the PC is applied to the new r, then one more pass for the local dots */
    PetscCall(MCGPrecondition(ksp, R, U, dots));
  } else {
    dots[MCG_DOT_RU] = ru;
    dots[MCG_DOT_RR] = rr;
    dots[MCG_DOT_UU] = uu;
  }
  dots[MCG_DOT_XX] = xx;
  PetscFunctionReturn(0);
}
