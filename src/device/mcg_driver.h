/*
   The host side of a merged-CG solve, the same for every executor: it starts the solve, hands the
   device k iterations at a time (all of them at once for a fixed-iteration solve, which then has no
   host synchronisation before its end), reads the small state after each chunk, and runs the
   true-residual check when the state asks for one. What an executor provides (Ops):

     void start(bool guess_zero, bool test_on_device)  r, u = M^-1 r, w = A u, the reduction, mcg_start_step
                                                       (and mcg_start_test when test_on_device)
     void iterations(int k)                            k iterations (update pass, w = A u, reduction,
                                                       mcg_step), each a no-op once the state is done
     void verify()                                     r = b - A x, u = M^-1 r, reduction, mcg_verify_step,
                                                       and on a restart p = s = 0, w = A u, mcg_restart_step
     void get_state(MCGState &) / put_state(const MCGState &)
     void history(double *h, int count)                the norms of iterations 0 .. count - 1
*/
#ifndef BINBCSR_DEVICE_MCG_DRIVER_H
#define BINBCSR_DEVICE_MCG_DRIVER_H

#include "device.h"
#include "device_bodies.h"

namespace binbcsr {
namespace device {

inline MCGState mcg_initial_state(const SolveSettings &st)
{
  MCGState s{};
  s.norm       = (int)st.norm;
  s.fixed      = st.fixed_its > 0;
  s.max_its    = st.fixed_its > 0 ? st.fixed_its : st.max_its;
  s.verify     = st.verify && !s.fixed;
  s.atol       = st.atol;
  s.roundoff   = s.fixed ? 0.0 : st.roundoff;
  s.stagnation = st.stagnation;
  s.last_true  = 1.79769313486231570e+308;
  s.true_rnorm = -1.0;
  return s;
}

template <class Ops> SolveResult run_mcg(Ops &ops, const SolveSettings &st)
{
  SolveResult res;
  MCGState    s = mcg_initial_state(st);
  ops.put_state(s);
  ops.start(st.guess_zero, s.fixed);
  if (s.fixed) {
    ops.iterations(s.max_its);
    ops.get_state(s);
    res.host_syncs = 1;
  } else {
    ops.get_state(s);
    res.host_syncs = 1;
    if (!s.done) {
      if (st.at_start) st.at_start(s.rnorm, s.ttol, s.divergence);
      else {
        s.ttol       = st.rtol * s.rnorm > st.atol ? st.rtol * s.rnorm : st.atol;
        s.divergence = st.dtol * s.rnorm;
      }
      mcg_start_test(s);
      ops.put_state(s);
    }
    const int k = st.check_every > 0 ? st.check_every : 1;
    while (!s.done) {
      if (s.want_verify) ops.verify();
      else ops.iterations(k);
      ops.get_state(s);
      res.host_syncs++;
    }
  }
  res.its         = s.its;
  res.reason      = s.reason;
  res.rnorm       = s.rnorm;
  res.true_checks = s.true_checks;
  res.restarts    = s.restarts;
  res.true_rnorm  = s.true_rnorm;
  res.history.resize((size_t)s.nhist);
  if (s.nhist) ops.history(res.history.data(), s.nhist);
  return res;
}

} // namespace device
} // namespace binbcsr

#endif
