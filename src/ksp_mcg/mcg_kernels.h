/* Per-index kernels of KSPMCG's fused vector passes.

   Plain functions of one index on raw arrays: no PETSc, no STL, no allocation, so that a CUDA backend
   can call the same code from a kernel (one thread per index, dots reduced in shared memory) and the
   host loop below stays one loop over contiguous memory that the compiler vectorises.

   The local dot products are accumulated into scalars; the caller reduces them across ranks in the
   one global reduction of the iteration. */
#ifndef BINBCSR_MCG_KERNELS_H
#define BINBCSR_MCG_KERNELS_H

#include "../binbcsr_hd.h"

/* Order matters: it is the layout of the buffer handed to the global reduction. */
enum {
  MCG_DOT_RU = 0,
  MCG_DOT_UW = 1,
  MCG_DOT_RR = 2,
  MCG_DOT_UU = 3,
  MCG_DOT_XX = 4,
  MCG_NDOTS  = 5
};

/* Chronopoulos-Gear update of one index, fused with Jacobi and the local dots:
     p = u + beta p        s = w + beta s   (s tracks A p without a product)
     x = x + alpha p       r = r - alpha s
     u = dinv * r          (Jacobi == false: no preconditioner, u = r, dinv unused)
   and adds r.u, r.r, u.u of the new r, u and x.x of the new x to ru, rr, uu, xx (scalars, so that a
   host loop can declare them as an OpenMP simd reduction and a device kernel can reduce them in
   shared memory). x.x feeds the estimate of the rounding drift of r (see mcg_solve.cpp).
   u is read (old value) before it is written (new value), so it is updated in place. */
template <bool Jacobi, typename Scalar>
BINBCSR_HD void mcg_update_index(long i, Scalar alpha, Scalar beta, Scalar *u, const Scalar *w, Scalar *p,
                                 Scalar *s, Scalar *x, Scalar *r, const Scalar *dinv, Scalar &ru, Scalar &rr,
                                 Scalar &uu, Scalar &xx)
{
  const Scalar pi = u[i] + beta * p[i];
  const Scalar si = w[i] + beta * s[i];
  const Scalar ri = r[i] - alpha * si;
  const Scalar ui = Jacobi ? dinv[i] * ri : ri;
  const Scalar xi = x[i] + alpha * pi;
  p[i]            = pi;
  s[i]            = si;
  x[i]            = xi;
  r[i]            = ri;
  u[i]            = ui;
  ru += ri * ui;
  rr += ri * ri;
  uu += ui * ui;
  xx += xi * xi;
}

/* y = B x for one 3x3 block B stored column-major (the order of MatInvertBlockDiagonal()). */
template <typename Scalar>
BINBCSR_HD void mcg_block3_apply(const Scalar *B, Scalar x0, Scalar x1, Scalar x2, Scalar &y0, Scalar &y1,
                                 Scalar &y2)
{
  y0 = B[0] * x0 + B[3] * x1 + B[6] * x2;
  y1 = B[1] * x0 + B[4] * x1 + B[7] * x2;
  y2 = B[2] * x0 + B[5] * x1 + B[8] * x2;
}

/* The update of mcg_update_index for the three indices of block row b, with point-block Jacobi:
   u_b = binv_b r_b, binv_b the inverse of the 3x3 diagonal block of block row b (column-major, 9
   scalars per block row). */
template <typename Scalar>
BINBCSR_HD void mcg_update_block3(long b, Scalar alpha, Scalar beta, Scalar *u, const Scalar *w, Scalar *p,
                                  Scalar *s, Scalar *x, Scalar *r, const Scalar *binv, Scalar &ru, Scalar &rr,
                                  Scalar &uu, Scalar &xx)
{
  Scalar rb[3];
  for (int c = 0; c < 3; c++) {
    const long   i  = 3 * b + c;
    const Scalar pi = u[i] + beta * p[i];
    const Scalar si = w[i] + beta * s[i];
    const Scalar xi = x[i] + alpha * pi;
    rb[c]           = r[i] - alpha * si;
    p[i]            = pi;
    s[i]            = si;
    x[i]            = xi;
    r[i]            = rb[c];
    rr += rb[c] * rb[c];
    xx += xi * xi;
  }
  Scalar u0, u1, u2;
  mcg_block3_apply(binv + 9 * b, rb[0], rb[1], rb[2], u0, u1, u2);
  u[3 * b]     = u0;
  u[3 * b + 1] = u1;
  u[3 * b + 2] = u2;
  ru += rb[0] * u0 + rb[1] * u1 + rb[2] * u2;
  uu += u0 * u0 + u1 * u1 + u2 * u2;
}

/* u_b = binv_b r_b and the local dots of r and u for block row b: start of a solve with point-block Jacobi. */
template <typename Scalar>
BINBCSR_HD void mcg_precondition_block3(long b, const Scalar *r, const Scalar *binv, Scalar *u, Scalar &ru,
                                        Scalar &rr, Scalar &uu)
{
  const Scalar r0 = r[3 * b], r1 = r[3 * b + 1], r2 = r[3 * b + 2];
  Scalar       u0, u1, u2;
  mcg_block3_apply(binv + 9 * b, r0, r1, r2, u0, u1, u2);
  u[3 * b]     = u0;
  u[3 * b + 1] = u1;
  u[3 * b + 2] = u2;
  ru += r0 * u0 + r1 * u1 + r2 * u2;
  rr += r0 * r0 + r1 * r1 + r2 * r2;
  uu += u0 * u0 + u1 * u1 + u2 * u2;
}

/* Same update without the preconditioner (generic path: the PC is applied afterwards by PCApply);
   adds x.x of the new x to xx. */
template <typename Scalar>
BINBCSR_HD void mcg_update_index_nopc(long i, Scalar alpha, Scalar beta, const Scalar *u, const Scalar *w,
                                      Scalar *p, Scalar *s, Scalar *x, Scalar *r, Scalar &xx)
{
  const Scalar pi = u[i] + beta * p[i];
  const Scalar si = w[i] + beta * s[i];
  const Scalar xi = x[i] + alpha * pi;
  p[i]            = pi;
  s[i]            = si;
  x[i]            = xi;
  r[i] -= alpha * si;
  xx += xi * xi;
}

/* u = dinv * r (or u = r) and the local dots of r and u: the start of a solve or a restart. */
template <bool Jacobi, typename Scalar>
BINBCSR_HD void mcg_precondition_index(long i, const Scalar *r, const Scalar *dinv, Scalar *u, Scalar &ru,
                                       Scalar &rr, Scalar &uu)
{
  const Scalar ri = r[i];
  const Scalar ui = Jacobi ? dinv[i] * ri : ri;
  u[i]            = ui;
  ru += ri * ui;
  rr += ri * ri;
  uu += ui * ui;
}

/* Local dots of r and u only (generic path, after PCApply). */
template <typename Scalar>
BINBCSR_HD void mcg_dots_index(long i, const Scalar *r, const Scalar *u, Scalar &ru, Scalar &rr, Scalar &uu)
{
  const Scalar ri = r[i], ui = u[i];
  ru += ri * ui;
  rr += ri * ri;
  uu += ui * ui;
}

/* Precision floor (single-precision storage): b - A x for the assembled double values differs from
   the residual of the rounded operator by up to floor = u ||A|| ||x|| (2-norm). A tolerance claim
   with the recursive 2-norm residual at or below the floor is still honest when the floor, carried
   into the KSP's norm by ratio (KSP norm / 2-norm of the latest nonzero residual), lies below the
   tolerance ttol the claim was made against; otherwise it is withheld. ttol <= 0 (a convergence test
   that does not say) or no ratio yet (0) withholds. */
BINBCSR_HD bool mcg_floor_below_tolerance(double floor, double ratio, double ttol)
{
  return ttol > 0 && ratio > 0 && floor * ratio < ttol;
}

#endif
