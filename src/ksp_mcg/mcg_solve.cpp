/* KSPMCG iteration: preconditioned conjugate gradient in the Chronopoulos-Gear formulation
   (A.T. Chronopoulos, C.W. Gear, "s-step iterative methods for symmetric linear systems",
   J. Comput. Appl. Math. 25 (1989)), which needs ONE global reduction per iteration.

   With u = M^-1 r, w = A u, gamma = r.u, delta = u.w, iteration k does

     beta  = gamma_k / gamma_{k-1}                (0 at the first iteration or after a restart)
     pAp   = delta_k - beta^2 pAp_{k-1}           (= p.Ap by A-conjugacy; = delta at the start)
     alpha = gamma_k / pAp
     p = u + beta p;  s = w + beta s;  x += alpha p;  r -= alpha s;  u = M^-1 r      (one pass)
     w = A u  and the local u.w                                                        (one pass)
     reduce {r.u, u.w, r.r, u.u} together                                          (one reduction)

   which is CG (Hestenes-Stiefel) in exact arithmetic: s = A p is carried by recurrence instead of
   being a product. The norms r.r and u.u ride along in the same reduction, so every norm type costs
   the same. With PCJACOBI (diagonal), PCPBJACOBI (3x3 blocks) or PCNONE the preconditioner is applied inside the vector pass
   ("fused" path); any other PC is applied with PCApply between two vector passes ("generic" path),
   still with one reduction per iteration. The product uses MatMultDotLocal(), which runs the matrix
   type's fused product-and-dot kernel when the type composes one (binbcsr does). */
#include "mcg_impl.h"
#include "mcg_kernels.h"
#include "mcg_device_solve.h"

/* The norm the KSP's norm type asks for, from the reduced dots: free, no extra reduction. */
static PetscReal MCGNorm(KSP ksp, const PetscScalar *dots)
{
  switch (ksp->normtype) {
  case KSP_NORM_PRECONDITIONED:
    return PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_UU]));
  case KSP_NORM_UNPRECONDITIONED:
    return PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RR]));
  case KSP_NORM_NATURAL:
    return PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RU]));
  default:
    return 0.0;
  }
}

/* The residual norm to report when a reduced dot is NaN or Inf: the KSP's norm when that is
   nonfinite itself, else the nonfinite dot's magnitude (KSPCG reports its NaN norm the same way;
   the last finite norm would tell KSPGetResidualNorm() that a NaN solve was small). */
static PetscReal MCGNonfiniteNorm(KSP ksp, const PetscScalar *dots, int k)
{
  const PetscReal dp = MCGNorm(ksp, dots);
  return PetscIsInfOrNanReal(dp) ? dp : PetscAbsScalar(dots[k]);
}

/* NaN or Inf in any reduced dot: KSP_DIVERGED_NANORINF (or KSP_DIVERGED_PC_FAILED when the PC
   reports a failure), as KSPCG reports it, with the nonfinite norm as the residual norm. A macro
   because KSPCheckDot() returns from the solve. */
#define MCGCheckDots(ksp, dots)                                                            \
  do {                                                                                     \
    for (int k_ = 0; k_ < MCG_NDOTS; k_++) {                                               \
      if (PetscIsInfOrNanScalar((dots)[k_])) ksp->rnorm = MCGNonfiniteNorm(ksp, dots, k_); \
      KSPCheckDot(ksp, (dots)[k_]);                                                        \
    }                                                                                      \
  } while (0)

/* r = b - A x computed from scratch, u = M^-1 r, and the reduced r.u, r.r, u.u (no product yet). */
static PetscErrorCode MCGTrueResidual(KSP ksp, Mat Amat, Vec X, Vec B, Vec R, Vec U, PetscScalar *dots)
{
  PetscFunctionBegin;
  PetscCall(KSP_MatMult(ksp, Amat, X, R));
  PetscCall(VecAYPX(R, -1.0, B));
  PetscCall(MCGPrecondition(ksp, R, U, dots));
  dots[MCG_DOT_UW] = 0;
  dots[MCG_DOT_XX] = 0;
  PetscCall(MCGReduce(ksp, dots, MCG_NDOTS));
  PetscFunctionReturn(0);
}

/* ||A|| from below: the largest Rayleigh quotient u.Au / u.u seen. */
static void MCGTrackNorm(const PetscScalar *dots, PetscReal *anorm)
{
  const PetscReal uu = PetscAbsScalar(dots[MCG_DOT_UU]);
  if (uu > 0) *anorm = PetscMax(*anorm, PetscAbsScalar(dots[MCG_DOT_UW]) / uu);
}

/* Accumulates the terms of the rounding-drift estimate from the reduced dots of one iteration. */
static void MCGTrackDrift(const PetscScalar *dots, PetscReal *anorm, PetscReal *sum_x, PetscReal *sum_r,
                          PetscReal *xnorm)
{
  MCGTrackNorm(dots, anorm);
  if (dots[MCG_DOT_XX] != (PetscScalar)0.0) *xnorm = PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_XX]));
  *sum_x += *xnorm;
  *sum_r += PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RR]));
}

static PetscBool MCGIsToleranceClaim(KSPConvergedReason reason)
{
  return (reason == KSP_CONVERGED_RTOL || reason == KSP_CONVERGED_ATOL ||
          reason == KSP_CONVERGED_RTOL_NORMAL || reason == KSP_CONVERGED_ATOL_NORMAL)
           ? PETSC_TRUE
           : PETSC_FALSE;
}

PetscErrorCode KSPSolve_MCG(KSP ksp)
{
  KSP_MCG    *mcg = (KSP_MCG *)ksp->data;
  Mat         Amat, Pmat;
  Vec         X, B, R, U, W, P, S;
  PetscBool   diagonalscale;
  PetscScalar dots[MCG_NDOTS];
  PetscScalar gamma, gamma_old = 1.0, delta, pAp = 0.0, alpha, beta;
  PetscReal   dp, last_true = PETSC_MAX_REAL;
  PetscReal   anorm = 0, sum_x = 0, sum_r = 0, xnorm = 0; /* for the rounding-drift estimate */
  PetscReal   norm_ratio = 0;                             /* KSP norm / 2-norm of the latest nonzero r */
  PetscBool   fresh      = PETSC_TRUE; /* p and s start from zero: first iteration or after a restart */
  PetscInt    i, max_its;
  PetscBool   defer_product; /* one process, convergence tested: the next w = A u after the test */

  PetscFunctionBegin;
  PetscCall(PCGetDiagonalScale(ksp->pc, &diagonalscale));
  PetscCheck(!diagonalscale, PetscObjectComm((PetscObject)ksp), PETSC_ERR_SUP,
             "Krylov method %s does not support diagonal scaling", ((PetscObject)ksp)->type_name);
  /* -ksp_rtol and friends reach ksp->rtol without KSPSetTolerances' checks: a NaN compared false in
     every test below, and the solve ran to its maximum and reported the matrix indefinite */
  PetscCheck(
    !PetscIsNanReal(ksp->rtol) && !PetscIsNanReal(ksp->abstol) && !PetscIsNanReal(ksp->divtol),
    PetscObjectComm((PetscObject)ksp), PETSC_ERR_ARG_OUTOFRANGE,
    "KSPMCG: tolerances rtol %g, abstol %g, divtol %g: NaN is not a tolerance (-ksp_rtol, -ksp_atol, "
    "-ksp_divtol)",
    (double)ksp->rtol, (double)ksp->abstol, (double)ksp->divtol);
  X = ksp->vec_sol;
  B = ksp->vec_rhs;
  R = ksp->work[0];
  U = ksp->work[1];
  W = ksp->work[2];
  P = ksp->work[3];
  S = ksp->work[4];
  PetscCall(PCGetOperators(ksp->pc, &Amat, &Pmat));
  PetscCall(MCGChoosePath(ksp, Amat));
  {
    /* MatBinBCSRGetPrecision answers double for every other matrix type (aij, shell, ...) */
    MatBinBCSRPrecision precision;
    PetscCall(MatBinBCSRGetPrecision(Amat, &precision));
    mcg->single_storage = precision == MAT_BINBCSR_PRECISION_SINGLE ? PETSC_TRUE : PETSC_FALSE;
    mcg->roundoff =
      mcg->floor_set != MCG_FLOOR_AUTO ? mcg->floor_set : (mcg->single_storage ? MCG_SINGLE_ROUNDOFF : 0.0);
    if (mcg->fixed_its > 0 || ksp->normtype == KSP_NORM_NONE)
      mcg->roundoff = 0.0; /* no tolerance is claimed */
    if (mcg->roundoff > 0)
      PetscCall(
        PetscInfo(ksp, "operator products rounded at u = %g%s: no tolerance is claimed below u ||A|| ||x||\n",
                  (double)mcg->roundoff, mcg->single_storage ? " (single-precision storage)" : ""));
  }
  if (mcg->how == MCG_PC_JACOBI) PetscCall(MCGUpdateDiagonal(ksp));
  if (mcg->how == MCG_PC_PBJACOBI) PetscCall(MCGUpdateBlockDiagonal(ksp));
  {
    PetscBool on_device; /* a matrix with a device copy (MatBinBCSRSetDevice): the whole solve there */
    PetscCall(KSPSolve_MCG_Device(ksp, Amat, Pmat, &on_device));
    if (on_device) PetscFunctionReturn(0);
  }
  max_its          = mcg->fixed_its > 0 ? mcg->fixed_its : ksp->max_it;
  mcg->restarts    = 0;
  mcg->true_checks = 0;
  mcg->true_rnorm  = -1.0;
  mcg->drift       = 0.0;
  mcg->floor       = 0.0;
  mcg->floor_hit   = PETSC_FALSE;
  ksp->its         = 0;

  /* r = b - A x, u = M^-1 r, w = A u, and the first reduction */
  if (!ksp->guess_zero) {
    PetscCall(KSP_MatMult(ksp, Amat, X, R));
    PetscCall(VecAYPX(R, -1.0, B));
  } else {
    PetscCall(VecCopy(B, R));
  }
  /* the PC may have failed in KSPSetUp on some ranks only: make every rank see it in the dots */
  if (ksp->reason == KSP_DIVERGED_PC_FAILED) PetscCall(BinBCSRVecSetInf(R));
  PetscCall(MCGPrecondition(ksp, R, U, dots));
  dots[MCG_DOT_XX] = 0; /* the x0 term of the drift estimate is left out: x1 stands for it */
  PetscCall(MCGMatMultDot(ksp, Amat, U, W, &dots[MCG_DOT_UW]));
  PetscCall(MCGReduce(ksp, dots, MCG_NDOTS));
  MCGCheckDots(ksp, dots);
  gamma = dots[MCG_DOT_RU];
  delta = dots[MCG_DOT_UW];
  MCGTrackDrift(dots, &anorm, &sum_x, &sum_r, &xnorm);

  dp = MCGNorm(ksp, dots);
  if (PetscRealPart(dots[MCG_DOT_RR]) > 0) norm_ratio = dp / PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RR]));
  PetscCall(KSPLogResidualHistory(ksp, dp));
  PetscCall(KSPMonitor(ksp, 0, dp));
  ksp->rnorm = dp;
  if (mcg->fixed_its <= 0) {
    PetscCall((*ksp->converged)(ksp, 0, dp, &ksp->reason, ksp->cnvP));
    if (ksp->reason) PetscFunctionReturn(0);
  }

  {
    PetscMPIInt size;
    PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)ksp), &size));
    defer_product = (PetscBool)(size == 1 && mcg->fixed_its <= 0);
  }
  i = 0;
  while (PETSC_TRUE) {
    if (i >= max_its) {
      ksp->reason = mcg->fixed_its > 0 ? KSP_CONVERGED_ITS : KSP_DIVERGED_ITS;
      break;
    }
    /* Without a tolerance (fixed iterations, norm none) the iteration goes on after the residual
       has converged: the recursive residual keeps shrinking geometrically until r.M^-1 r or p.Ap
       underflow or lose their sign to rounding. Once it is below the rounding drift it no longer
       measures anything (b - A x is at its attainable accuracy), so a breakdown there is the end of
       a converged solve, reported as KSPCG reports r.z = 0: KSP_CONVERGED_ATOL. */
    if (mcg->fixed_its > 0 || ksp->normtype == KSP_NORM_NONE) {
      const PetscReal drift = PETSC_MACHINE_EPSILON * (anorm * sum_x + sum_r);
      const PetscReal r_un  = PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RR]));
      if (i > 0 && r_un <= drift &&
          (!(PetscRealPart(gamma) > 0.0) || !(PetscRealPart(delta) > 0.0) ||
           !(PetscRealPart(delta - (gamma / gamma_old) * (gamma / gamma_old) * pAp) > 0.0))) {
        ksp->reason = KSP_CONVERGED_ATOL;
        PetscCall(
          PetscInfo(ksp,
                    "Converged: recursive residual %g below its rounding drift %g at iteration %" PetscInt_FMT
                    " (r.M^-1 r or p.Ap lost to rounding)\n",
                    (double)r_un, (double)drift, i));
        break;
      }
    }
    /* breakdowns are reported, never divided by */
    if (gamma == (PetscScalar)0.0) {
      if (dots[MCG_DOT_RR] == (PetscScalar)0.0) {
        ksp->reason = KSP_CONVERGED_ATOL;
        PetscCall(PetscInfo(ksp, "Converged: the residual is exactly zero\n"));
      } else {
        PetscCheck(!ksp->errorifnotconverged, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED,
                   "KSPMCG breakdown: r.M^-1 r = 0 with r != 0 (singular preconditioner)");
        ksp->reason = KSP_DIVERGED_BREAKDOWN;
        PetscCall(PetscInfo(ksp, "Breakdown: r.M^-1 r = 0 with r != 0 (singular preconditioner)\n"));
      }
      break;
    }
    if (PetscRealPart(gamma) < 0.0) {
      PetscCheck(!ksp->errorifnotconverged, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED,
                 "Diverged due to indefinite preconditioner, r.M^-1 r = %g", (double)PetscRealPart(gamma));
      ksp->reason = KSP_DIVERGED_INDEFINITE_PC;
      PetscCall(PetscInfo(ksp, "Diverging due to indefinite preconditioner, r.M^-1 r = %g\n",
                          (double)PetscRealPart(gamma)));
      break;
    }
    beta = fresh ? 0.0 : gamma / gamma_old;
    pAp  = fresh ? delta : delta - beta * beta * pAp;
    if (!(PetscRealPart(pAp) > 0.0)) { /* also catches NaN */
      PetscCheck(!ksp->errorifnotconverged, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED,
                 "Diverged due to indefinite matrix, p.Ap = %g", (double)PetscRealPart(pAp));
      ksp->reason = KSP_DIVERGED_INDEFINITE_MAT;
      PetscCall(PetscInfo(ksp, "Diverging due to indefinite or negative definite matrix, p.Ap = %g\n",
                          (double)PetscRealPart(pAp)));
      break;
    }
    alpha = gamma / pAp;
    if (fresh) {
      PetscCall(VecSet(P, 0.0));
      PetscCall(VecSet(S, 0.0));
    }

    ksp->its = i + 1;
    PetscCall(MCGUpdate(ksp, alpha, beta, X, R, U, W, P, S, dots));
    /* w = A u only feeds the next iteration: none follows the last allowed one (fixed-iteration mode
       saves a product per solve this way; a restart recomputes w itself). On one process the
       reduction costs nothing, so the product waits for the convergence test (defer_product) and a
       converged solve makes no product that nothing uses, as KSPCG: one product per iteration. */
    dots[MCG_DOT_UW] = 0;
    if (i + 1 < max_its && !defer_product) PetscCall(MCGMatMultDot(ksp, Amat, U, W, &dots[MCG_DOT_UW]));
    PetscCall(MCGReduce(ksp, dots, MCG_NDOTS));
    MCGCheckDots(ksp, dots);
    gamma_old = gamma;
    gamma     = dots[MCG_DOT_RU];
    delta     = dots[MCG_DOT_UW];
    fresh     = PETSC_FALSE;
    i++;
    MCGTrackDrift(dots, &anorm, &sum_x, &sum_r, &xnorm);

    dp         = MCGNorm(ksp, dots);
    ksp->rnorm = dp;
    PetscCall(KSPLogResidualHistory(ksp, dp));
    PetscCall(KSPMonitor(ksp, i, dp));
    if (mcg->fixed_its > 0) continue;
    PetscCall((*ksp->converged)(ksp, i, dp, &ksp->reason, ksp->cnvP));

    /* Precision floor. When the operator's products are rounded at relative u (single-precision
       storage), b - A x against the values the user assembled differs from the residual MCG
       iterates on by up to about u ||A|| ||x|| (||A|| from the largest Rayleigh quotient seen,
       ||x|| from the reduced x.x: both free). A claim whose residual is below that floor, against a tolerance that is not above it
       (mcg_floor_below_tolerance), cannot be made honestly, so it is withheld; the iteration goes on until the residual of the
       rounded system is MCG_FLOOR_DEPTH below the floor (the solution is then as good as the
       rounded operator allows: the estimate is a bound, the actual plateau is usually a few times
       lower) and stops with KSP_DIVERGED_BREAKDOWN, reporting the floor as the residual norm. */
    if (mcg->roundoff > 0 && (ksp->reason == KSP_CONVERGED_ITERATING || MCGIsToleranceClaim(ksp->reason))) {
      const PetscReal r_un = PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RR]));
      mcg->floor           = mcg->roundoff * anorm * xnorm;
      mcg->floor_anorm     = anorm;
      mcg->floor_xnorm     = xnorm;
      if (r_un > 0) norm_ratio = dp / r_un;
      if (r_un <= mcg->floor &&
          !mcg_floor_below_tolerance(mcg->floor, norm_ratio,
                                     ksp->converged == KSPConvergedDefault ? ksp->ttol : 0)) {
        if (ksp->reason) {
          if (!mcg->floor_hit)
            PetscCall(PetscInfo(
              ksp,
              "Tolerance met at residual norm %g, at or below the precision floor u ||A|| ||x|| = %g (u %g, ||A|| >= %g, ||x|| %g): claim withheld\n",
              (double)r_un, (double)mcg->floor, (double)mcg->roundoff, (double)anorm, (double)xnorm));
          ksp->reason = KSP_CONVERGED_ITERATING;
        }
        mcg->floor_hit = PETSC_TRUE;
      }
      if (mcg->floor_hit && r_un <= MCG_FLOOR_DEPTH * mcg->floor) {
        PetscCheck(
          !ksp->errorifnotconverged, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED,
          "KSPMCG: the tolerance is below the precision floor u ||A|| ||x|| = %g of the operator (u = %g)",
          (double)mcg->floor, (double)mcg->roundoff);
        PetscCall(PetscInfo(
          ksp,
          "Precision floor u ||A|| ||x|| = %g (u %g, ||A|| >= %g, ||x|| %g) reached at iteration %" PetscInt_FMT
          " before the tolerance: stopping\n",
          (double)mcg->floor, (double)mcg->roundoff, (double)anorm, (double)xnorm, i));
        ksp->reason = KSP_DIVERGED_BREAKDOWN;
        /* the floor in the KSP's norm: scaled by the ratio of the KSP's norm to the 2-norm of r */
        ksp->rnorm = r_un > 0 ? dp * (mcg->floor / r_un) : mcg->floor;
        break;
      }
    }

    /* The recursively updated r drifts from b - A x by rounding, by at most about
       eps * sum_k (|A| |x_k| + |r_k|) (Greenbaum 1997; |A| estimated from below by the largest
       Rayleigh quotient u.Au/u.u seen, all norms from the reduction, so the estimate is free).
       A claim made far above that drift stands. Closer to it, check b - A x (one product); if the
       tolerance is not met there, restart from the true residual, and stop with a breakdown when
       restarts no longer make progress (the attainable accuracy is reached). */
    if (mcg->verify && MCGIsToleranceClaim(ksp->reason)) {
      mcg->drift = PETSC_MACHINE_EPSILON * (anorm * sum_x + sum_r);
      if (PetscSqrtReal(PetscAbsScalar(dots[MCG_DOT_RR])) > MCG_DRIFT_MARGIN * mcg->drift) break;
    }
    if (mcg->verify && MCGIsToleranceClaim(ksp->reason)) {
      KSPConvergedReason claim = ksp->reason, check = KSP_CONVERGED_ITERATING;
      PetscReal          true_dp;

      PetscCall(MCGTrueResidual(ksp, Amat, X, B, R, U, dots));
      MCGCheckDots(ksp, dots);
      mcg->true_checks++;
      true_dp         = MCGNorm(ksp, dots);
      mcg->true_rnorm = true_dp;
      PetscCall((*ksp->converged)(ksp, i, true_dp, &check, ksp->cnvP));
      if (check > 0) {
        ksp->reason = claim;
        ksp->rnorm  = true_dp;
        break;
      }
      if (!(true_dp < mcg->stagnation * last_true)) {
        PetscCheck(
          !ksp->errorifnotconverged, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED,
          "KSPMCG: true residual norm %g stagnates above the tolerance (attainable accuracy reached)",
          (double)true_dp);
        ksp->reason = KSP_DIVERGED_BREAKDOWN;
        ksp->rnorm  = true_dp;
        PetscCall(PetscInfo(ksp,
                            "True residual norm %g stagnates above the tolerance after %" PetscInt_FMT
                            " restarts: attainable accuracy reached\n",
                            (double)true_dp, mcg->restarts));
        break;
      }
      PetscCall(PetscInfo(
        ksp,
        "Recursive residual %g met the tolerance but the true residual is %g: restarting from the true residual\n",
        (double)dp, (double)true_dp));
      last_true   = true_dp;
      ksp->reason = KSP_CONVERGED_ITERATING;
      ksp->rnorm  = true_dp;
      mcg->restarts++;
      dots[MCG_DOT_UW] = 0;
      PetscCall(MCGMatMultDot(ksp, Amat, U, W, &dots[MCG_DOT_UW]));
      PetscCall(MCGReduce(ksp, &dots[MCG_DOT_UW], 1));
      MCGCheckDots(ksp, dots);
      gamma = dots[MCG_DOT_RU];
      delta = dots[MCG_DOT_UW];
      fresh = PETSC_TRUE;
      /* the drift starts again from the recomputed residual */
      sum_r = 0;
      sum_x = xnorm;
      MCGTrackDrift(dots, &anorm, &sum_x, &sum_r, &xnorm);
    }
    if (ksp->reason) break;
    if (defer_product && !fresh && i < max_its) {
      PetscCall(MCGMatMultDot(ksp, Amat, U, W, &dots[MCG_DOT_UW]));
      if (PetscIsInfOrNanScalar(dots[MCG_DOT_UW])) ksp->rnorm = PetscAbsScalar(dots[MCG_DOT_UW]);
      KSPCheckDot(ksp, dots[MCG_DOT_UW]);
      delta = dots[MCG_DOT_UW];
      MCGTrackNorm(dots, &anorm);
    }
  }
  PetscFunctionReturn(0);
}
