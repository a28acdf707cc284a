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
enum { MCG_DOT_RU = 0, MCG_DOT_UW = 1, MCG_DOT_RR = 2, MCG_DOT_UU = 3, MCG_DOT_XX = 4, MCG_NDOTS = 5 };

/* Chronopoulos-Gear update of one index, fused with Jacobi and the local dots:
     p = u + beta p        s = w + beta s   (s tracks A p without a product)
     x = x + alpha p       r = r - alpha s
     u = dinv * r          (Jacobi == false: no preconditioner, u = r, dinv unused)
   and adds r.u, r.r, u.u of the new r, u and x.x of the new x to ru, rr, uu, xx (scalars, so that a
   host loop can declare them as an OpenMP simd reduction and a device kernel can reduce them in
   shared memory). x.x feeds the estimate of the rounding drift of r (see mcg_solve.cpp).
   u is read (old value) before it is written (new value), so it is updated in place. */
template <bool Jacobi, typename Scalar>
BINBCSR_HD void mcg_update_index(long i, Scalar alpha, Scalar beta, Scalar *u, const Scalar *w, Scalar *p, Scalar *s, Scalar *x, Scalar *r, const Scalar *dinv, Scalar &ru, Scalar &rr, Scalar &uu, Scalar &xx)
{
  const Scalar pi = u[i] + beta * p[i];
  const Scalar si = w[i] + beta * s[i];
  const Scalar ri = r[i] - alpha * si;
  const Scalar ui = Jacobi ? dinv[i] * ri : ri;
  const Scalar xi = x[i] + alpha * pi;
  p[i] = pi;
  s[i] = si;
  x[i] = xi;
  r[i] = ri;
  u[i] = ui;
  ru += ri * ui;
  rr += ri * ri;
  uu += ui * ui;
  xx += xi * xi;
}

/* Same update without the preconditioner (generic path: the PC is applied afterwards by PCApply);
   adds x.x of the new x to xx. */
template <typename Scalar>
BINBCSR_HD void mcg_update_index_nopc(long i, Scalar alpha, Scalar beta, const Scalar *u, const Scalar *w, Scalar *p, Scalar *s, Scalar *x, Scalar *r, Scalar &xx)
{
  const Scalar pi = u[i] + beta * p[i];
  const Scalar si = w[i] + beta * s[i];
  const Scalar xi = x[i] + alpha * pi;
  p[i] = pi;
  s[i] = si;
  x[i] = xi;
  r[i] -= alpha * si;
  xx += xi * xi;
}

/* u = dinv * r (or u = r) and the local dots of r and u: the start of a solve or a restart. */
template <bool Jacobi, typename Scalar>
BINBCSR_HD void mcg_precondition_index(long i, const Scalar *r, const Scalar *dinv, Scalar *u, Scalar &ru, Scalar &rr, Scalar &uu)
{
  const Scalar ri = r[i];
  const Scalar ui = Jacobi ? dinv[i] * ri : ri;
  u[i] = ui;
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

#endif
