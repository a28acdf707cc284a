/*
   Bodies both executors of the device library run (BINBCSR_HD: __host__ __device__ under nvcc):
   the refill of one lane, and the scalar step of the merged CG. The products call the lane bodies of
   binbcsr_kernels.h and the vector passes the index bodies of mcg_kernels.h directly; what is here is
   what those headers do not have. No PETSc, no STL.
*/
#ifndef BINBCSR_DEVICE_BODIES_H
#define BINBCSR_DEVICE_BODIES_H

#include "mat_binbcsr/kernels/binbcsr_kernels.h"
#include "ksp_mcg/mcg_kernels.h"
#include <math.h>

namespace binbcsr {
namespace device {

/* Refill of lane `lane` of bin b (the seed's Listing 2.9, one thread per lane): every stored value of
   the lane's len slot groups is the sum of its COO entries (padding: none, so zero). The lanes of a
   bin write neighbouring addresses (coalesced), no value is written twice, so no atomics. */
template <typename V, bool ADD>
BINBCSR_HD void lane_refill(V *val, const int *bin_start, int b, int lane, int bw, int bs2, const int *jmap,
                            const int *perm, const double *coo, long ncoo)
{
  const int s0 = bin_start[b], len = (bin_start[b + 1] - s0) / bw;
  for (int k = 0; k < len; k++)
    for (int e = 0; e < bs2; e++) {
      const long v =
        ((long)s0 + (long)k * bw) * bs2 + (long)e * bw + lane; /* value_index of slot s0 + k bw + lane */
      const double s = coo_gather<int>(coo, ncoo, nullptr, jmap, perm, v);
      val[v]         = (V)(ADD ? (double)val[v] + s : s);
    }
}

/* The merged CG's scalars and its decisions, KSPMCG's (src/ksp_mcg/mcg_solve.cpp) step for step, so
   that a device solve stops at the same iteration with the same reason. It lives on the device; each
   iteration's reduction is finished by one thread that calls mcg_step, and the host reads it every k
   iterations (or once, after a fixed-iteration solve). The dots are reduced in the order of
   mcg_kernels.h: MCG_DOT_RU, UW, RR, UU, XX. */
struct MCGState {
  /* settings */
  int    norm, max_its, fixed, verify; /* norm: device::Norm as int */
  double atol, ttol, divergence, roundoff, stagnation;
  /* iteration */
  int its, nhist, reason, fresh, done, want_verify, floor_hit, true_checks,
    restarts; /* nhist: norms in the history */
  double gamma, gamma_old, delta, pAp, alpha, beta, rnorm;
  double rr;                                 /* r.r of the last reduction (breakdown test) */
  double anorm, xnorm, sum_x, sum_r, floor_; /* rounding drift and precision floor estimates */
  double last_true, true_rnorm;
  double norm_ratio; /* KSP norm / 2-norm of the latest nonzero residual (precision floor test) */
};

constexpr double mcg_eps          = 2.220446049250313e-16; /* PETSC_MACHINE_EPSILON */
constexpr double mcg_drift_margin = 100.0;                 /* MCG_DRIFT_MARGIN */
constexpr double mcg_floor_depth  = 0.1;                   /* MCG_FLOOR_DEPTH */

BINBCSR_HD double mcg_abs(double a) { return a < 0 ? -a : a; }
BINBCSR_HD bool   mcg_finite(double a) { return a - a == 0.0; } /* false for NaN and Inf */

BINBCSR_HD double mcg_norm(const MCGState &s, const double *dots)
{
  switch (s.norm) {
  case 0:
    return sqrt(mcg_abs(dots[MCG_DOT_UU]));
  case 1:
    return sqrt(mcg_abs(dots[MCG_DOT_RR]));
  case 2:
    return sqrt(mcg_abs(dots[MCG_DOT_RU]));
  default:
    return 0.0;
  }
}

/* KSPConvergedDefault at an iteration > 0 (ttol and the divergence bound fixed at the start). */
BINBCSR_HD int mcg_test(const MCGState &s, double dp)
{
  if (!mcg_finite(dp)) return -9;
  if (dp <= s.ttol) return dp < s.atol ? 3 : 2;
  if (dp >= s.divergence) return -4;
  return 0;
}
BINBCSR_HD bool mcg_claim(int reason) { return reason == 2 || reason == 3; }

/* MCGCheckDots: NaN or Inf in a reduced dot stops the solve (KSP_DIVERGED_NANORINF). */
BINBCSR_HD bool mcg_dots_bad(MCGState &s, const double *dots, int ndots)
{
  for (int k = 0; k < ndots; k++)
    if (!mcg_finite(dots[k])) {
      s.reason = -9;
      s.done   = 1;
      return true;
    }
  return false;
}

BINBCSR_HD void mcg_track_norm(MCGState &s, double uw, double uu)
{
  uu = mcg_abs(uu);
  if (uu > 0 && mcg_abs(uw) / uu > s.anorm) s.anorm = mcg_abs(uw) / uu;
}

/* The top of an iteration: the iteration limit, the breakdowns, and alpha, beta of the next update. */
BINBCSR_HD void mcg_top(MCGState &s)
{
  if (s.done) return;
  if (s.its >= s.max_its) s.reason = s.fixed ? 4 : -3;
  else if (s.gamma == 0.0) s.reason = s.rr == 0.0 ? 3 : -5;
  else if (s.gamma < 0.0) s.reason = -8;
  else {
    s.beta = s.fresh ? 0.0 : s.gamma / s.gamma_old;
    s.pAp  = s.fresh ? s.delta : s.delta - s.beta * s.beta * s.pAp;
    if (!(s.pAp > 0.0)) s.reason = -10;
    else s.alpha = s.gamma / s.pAp;
  }
  if (s.reason) s.done = 1;
}

/* After the start's reduction (r, u = M^-1 r, w = A u): dp0; the host then sets ttol and divergence
   and calls mcg_start_test. hist: the norm of iteration 0 goes to hist[0]. */
BINBCSR_HD void mcg_start_step(MCGState &s, const double *dots, double *hist)
{
  if (mcg_dots_bad(s, dots, 5)) return;
  s.gamma = dots[MCG_DOT_RU];
  s.delta = dots[MCG_DOT_UW];
  s.rr    = dots[MCG_DOT_RR];
  s.fresh = 1;
  mcg_track_norm(s, dots[MCG_DOT_UW], dots[MCG_DOT_UU]);
  s.sum_x += s.xnorm;
  s.sum_r += sqrt(mcg_abs(dots[MCG_DOT_RR]));
  s.rnorm = mcg_norm(s, dots);
  if (dots[MCG_DOT_RR] > 0) s.norm_ratio = s.rnorm / sqrt(dots[MCG_DOT_RR]);
  if (hist) hist[0] = s.rnorm;
  s.nhist = 1;
}
BINBCSR_HD void mcg_start_test(MCGState &s)
{
  if (s.done) return;
  if (!s.fixed) {
    s.reason = mcg_test(s, s.rnorm);
    if (s.reason) {
      s.done = 1;
      return;
    }
  }
  mcg_top(s);
}

/* After an iteration's reduction (update pass and w = A u): the norm, the convergence test, the
   precision floor, the drift estimate that decides whether a claim is checked on b - A x
   (want_verify: the host runs that check), then the top of the next iteration. */
BINBCSR_HD void mcg_step(MCGState &s, const double *dots, double *hist)
{
  if (s.done || s.want_verify) return;
  s.its++; /* KSPMCG counts the iteration before its reduction is checked */
  if (mcg_dots_bad(s, dots, 5)) return;
  s.gamma_old = s.gamma;
  s.gamma     = dots[MCG_DOT_RU];
  s.delta     = dots[MCG_DOT_UW];
  s.rr        = dots[MCG_DOT_RR];
  s.fresh     = 0;
  /* KSPMCG defers this iteration's product past its tests on one process: the norm estimate takes
     u.Au only after them */
  if (dots[MCG_DOT_XX] != 0.0) s.xnorm = sqrt(mcg_abs(dots[MCG_DOT_XX]));
  s.sum_x += s.xnorm;
  s.sum_r += sqrt(mcg_abs(dots[MCG_DOT_RR]));
  const double dp = mcg_norm(s, dots);
  s.rnorm         = dp;
  if (hist) hist[s.its] = dp;
  s.nhist = s.its + 1;
  if (s.fixed) {
    mcg_track_norm(s, dots[MCG_DOT_UW], dots[MCG_DOT_UU]);
    mcg_top(s);
    return;
  }
  s.reason = mcg_test(s, dp);
  if (s.roundoff > 0 && (s.reason == 0 || mcg_claim(s.reason))) {
    const double r_un = sqrt(mcg_abs(dots[MCG_DOT_RR]));
    s.floor_          = s.roundoff * s.anorm * s.xnorm;
    if (r_un > 0) s.norm_ratio = dp / r_un;
    if (r_un <= s.floor_ && !mcg_floor_below_tolerance(s.floor_, s.norm_ratio, s.ttol)) {
      s.reason    = 0; /* the claim is withheld */
      s.floor_hit = 1;
    }
    if (s.floor_hit && r_un <= mcg_floor_depth * s.floor_) {
      s.reason = -5;
      s.rnorm  = r_un > 0 ? dp * (s.floor_ / r_un) : s.floor_;
      s.done   = 1;
      return;
    }
  }
  if (s.verify && mcg_claim(s.reason)) {
    const double drift = mcg_eps * (s.anorm * s.sum_x + s.sum_r);
    if (!(sqrt(mcg_abs(dots[MCG_DOT_RR])) > mcg_drift_margin * drift)) {
      s.want_verify = 1; /* the host checks b - A x (mcg_verify_step) */
      return;
    }
  }
  if (s.reason) {
    s.done = 1;
    return;
  }
  mcg_track_norm(s, dots[MCG_DOT_UW], dots[MCG_DOT_UU]);
  mcg_top(s);
}

/* After the true residual r = b - A x, u = M^-1 r and their reduced dots (RU, RR, UU; UW, XX zero):
   the claim stands, or the attainable accuracy is reached, or the CG restarts from r (returns true:
   the caller computes w = A u, zeroes p and s, and calls mcg_restart_step with u.w). */
BINBCSR_HD bool mcg_verify_step(MCGState &s, const double *dots)
{
  const int claim = s.reason;
  s.want_verify   = 0;
  if (mcg_dots_bad(s, dots, 5)) return false;
  s.true_checks++;
  const double true_dp = mcg_norm(s, dots);
  s.true_rnorm         = true_dp;
  if (mcg_test(s, true_dp) > 0) {
    s.reason = claim;
    s.rnorm  = true_dp;
    s.done   = 1;
    return false;
  }
  s.rnorm = true_dp;
  if (!(true_dp < s.stagnation * s.last_true)) {
    s.reason = -5;
    s.done   = 1;
    return false;
  }
  s.last_true = true_dp;
  s.reason    = 0;
  s.restarts++;
  s.gamma = dots[MCG_DOT_RU];
  s.rr    = dots[MCG_DOT_RR];
  s.fresh = 1;
  s.sum_r = 0;
  s.sum_x = s.xnorm;
  s.sum_x += s.xnorm;
  s.sum_r += sqrt(mcg_abs(dots[MCG_DOT_RR]));
  return true;
}
BINBCSR_HD void mcg_restart_step(MCGState &s, double uw, double uu)
{
  if (!mcg_finite(uw)) {
    s.reason = -9;
    s.done   = 1;
    return;
  }
  s.delta = uw;
  mcg_track_norm(s, uw, uu);
  mcg_top(s);
}

} // namespace device
} // namespace binbcsr

#endif
