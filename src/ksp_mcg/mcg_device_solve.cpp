/* KSPMCG on a matrix with a device copy (MatBinBCSRSetDevice): the whole solve runs on the device
   library's executor (src/device/mcg_driver.h: the iteration of mcg_solve.cpp, its reasons and
   checks, one reduction per iteration), with b and the initial guess uploaded and x downloaded.
   PETSc's convergence test decides the tolerances at iteration 0 (KSPConvergedDefault, called on the
   host with the initial norm), the device applies them afterwards. Monitors and the residual history
   are called after the solve from the norms the device recorded. Anything the device solve does not
   do (another PC or convergence test, a transpose solve, a null space) runs on the host path, which
   then multiplies through the device copy's MatMult or the host kernels (PetscInfo says why). */
#include "mcg_device_solve.h"
#include "mat_binbcsr/seq/binbcsr_device.h"

namespace {
/* Why the device solve cannot run this solve, or nullptr. */
const char *DeviceRefusal(KSP ksp, Mat Amat, Mat Pmat)
{
  KSP_MCG *mcg = (KSP_MCG *)ksp->data;
  if (mcg->how == MCG_PC_GENERIC)
    return mcg->why_generic[0] ? mcg->why_generic : "the preconditioner is not applied in the fused pass";
  if (ksp->transpose_solve) return "transpose solve";
  if (mcg->how == MCG_PC_JACOBI && Pmat != Amat) return "the preconditioning matrix is not the operator";
  if (mcg->fixed_its <= 0 && ksp->converged != KSPConvergedDefault)
    return "a convergence test other than KSPConvergedDefault";
  if (mcg->fixed_its <= 0 && ksp->normtype == KSP_NORM_NONE) return "norm type none without fixed iterations";
  if (mcg->fixed_its <= 0 && ksp->chknorm >= 0) return "-ksp_check_norm_iteration";
  return nullptr;
}
} // namespace

PetscErrorCode KSPSolve_MCG_Device(KSP ksp, Mat Amat, Mat Pmat, PetscBool *done)
{
  KSP_MCG                     *mcg = (KSP_MCG *)ksp->data;
  binbcsr::device::Executor   *E;
  binbcsr::device::Matrix     *M;
  binbcsr::device::Vector     *dinv = nullptr, *b = nullptr;
  binbcsr::device::SolveResult res;

  PetscFunctionBegin;
  *done = PETSC_FALSE;
  PetscCall(MatSeqBinBCSRGetDeviceMatrix(Amat, &E, &M));
  if (!M) PetscFunctionReturn(0);
  if (const char *why = DeviceRefusal(ksp, Amat, Pmat)) {
    PetscCall(PetscInfo(ksp, "KSPMCG on a device matrix solves on the host: %s\n", why));
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(KSP_MCG_DeviceSolve, ksp, 0, 0, 0));
  binbcsr::device::SolveSettings st;
  st.jacobi     = mcg->how == MCG_PC_JACOBI;
  st.norm       = ksp->normtype == KSP_NORM_PRECONDITIONED     ? binbcsr::device::Norm::preconditioned
                  : ksp->normtype == KSP_NORM_UNPRECONDITIONED ? binbcsr::device::Norm::unpreconditioned
                  : ksp->normtype == KSP_NORM_NATURAL          ? binbcsr::device::Norm::natural
                                                               : binbcsr::device::Norm::none;
  st.max_its    = (int)ksp->max_it;
  st.fixed_its  = (int)mcg->fixed_its;
  st.guess_zero = ksp->guess_zero ? true : false;
  st.atol       = ksp->abstol;
  st.verify     = mcg->verify ? true : false;
  st.stagnation = mcg->stagnation;
  st.roundoff   = mcg->roundoff;
  PetscErrorCode at_start_err = 0;
  st.at_start                 = [&](double dp0, double &ttol, double &divergence) {
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    ksp->rnorm                = dp0;
    at_start_err              = (*ksp->converged)(ksp, 0, dp0, &reason, ksp->cnvP);
    ttol                      = ksp->ttol;
    divergence                = ksp->divtol * ksp->rnorm0;
  };
  /* b and dinv are cached on the matrix: uploaded again only when they change */
  PetscCall(MatSeqBinBCSRDeviceCachedVector(Amat, 0, ksp->vec_rhs, &b));
  if (st.jacobi) PetscCall(MatSeqBinBCSRDeviceCachedVector(Amat, 1, mcg->dinv, &dinv));
  else dinv = b; /* unused */
  {
    PetscScalar             *xa;
    binbcsr::device::Vector *x;
    PetscCall(MatSeqBinBCSRDeviceCachedVector(Amat, 2, nullptr, &x));
    PetscCall(VecGetArray(ksp->vec_sol, &xa));
    BinBCSRDeviceTry(if (!st.guess_zero) x->upload(xa); res = M->solve(*dinv, *b, *x, st); x->download(xa));
    PetscCall(VecRestoreArray(ksp->vec_sol, &xa));
  }
  PetscCall(at_start_err);
  ksp->its         = res.its;
  ksp->reason      = (KSPConvergedReason)res.reason;
  ksp->rnorm       = res.rnorm;
  mcg->restarts    = res.restarts;
  mcg->true_checks = res.true_checks;
  mcg->true_rnorm  = res.true_rnorm;
  for (size_t k = 0; k < res.history.size(); k++) {
    PetscCall(KSPLogResidualHistory(ksp, res.history[k]));
    PetscCall(KSPMonitor(ksp, (PetscInt)k, res.history[k]));
  }
  PetscCall(PetscInfo(ksp,
                      "KSPMCG solved on the %s executor: %d iterations, %d copies of the state to the host\n",
                      E->name(), res.its, res.host_syncs));
  PetscCall(PetscLogEventEnd(KSP_MCG_DeviceSolve, ksp, 0, 0, 0));
  *done = PETSC_TRUE;
  PetscFunctionReturn(0);
}
