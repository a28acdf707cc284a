/* The device library's merged CG on the executor under test, against a plain CSR PCG (Jacobi) and
   against the reference executor. */
#include "device_test.h"
#include "fixtures.h"

#include <algorithm>

using namespace dt;

namespace {
/* Hestenes-Stiefel PCG with Jacobi on the CSR matrix; stops when ||D^-1 r|| <= rtol ||D^-1 b|| or after
   max_its; returns the iterations. */
int csr_pcg(const BlockCSR &A, const std::vector<double> &b, std::vector<double> &x, double rtol, int max_its)
{
  const std::vector<double> d = inverse_diagonal(A);
  const size_t              n = b.size();
  std::vector<double>       r = b, z(n), p(n), q;
  x.assign(n, 0.0);
  double rz = 0, zz = 0;
  for (size_t i = 0; i < n; i++) z[i] = d[i] * r[i], rz += r[i] * z[i], zz += z[i] * z[i];
  const double z0 = std::sqrt(zz);
  p               = z;
  int k           = 0;
  while (k < max_its && std::sqrt(zz) > rtol * z0) {
    csr_mult(A, p, q);
    double pq = 0;
    for (size_t i = 0; i < n; i++) pq += p[i] * q[i];
    const double a   = rz / pq;
    double       rz1 = 0;
    zz               = 0;
    for (size_t i = 0; i < n; i++)
      x[i] += a * p[i], r[i] -= a * q[i], z[i] = d[i] * r[i], rz1 += r[i] * z[i], zz += z[i] * z[i];
    for (size_t i = 0; i < n; i++) p[i] = z[i] + rz1 / rz * p[i];
    rz = rz1;
    k++;
  }
  return k;
}
double rel_diff(const std::vector<double> &a, const std::vector<double> &b)
{
  double num = 0, den = 0;
  for (size_t i = 0; i < a.size(); i++) num += (a[i] - b[i]) * (a[i] - b[i]), den += b[i] * b[i];
  return std::sqrt(num / (den + 1e-300));
}
struct Problem {
  BlockCSR            A;
  HostBins            B;
  std::vector<double> b, dinv, xtrue;
};
Problem problem(int bs, int bw, int mbs, bool sym, double shift = 1.0)
{
  Problem P;
  P.A     = random_spd(bs, mbs, 41 + mbs, shift);
  P.B     = bins_from_bcsr(bs, mbs, P.A.ptr.data(), P.A.col.data(), P.A.val.data(), bw, sym);
  P.xtrue = random_vector((long)mbs * bs, 77);
  csr_mult(P.A, P.xtrue, P.b);
  P.dinv = inverse_diagonal(P.A);
  return P;
}
SolveResult run(Executor &E, const Problem &P, const SolveSettings &st, std::vector<double> &x,
                Precision prec = Precision::double_values, const std::vector<double> *b = nullptr,
                const std::vector<double> *dinv = nullptr)
{
  auto M = E.matrix(P.B.layout(), prec);
  M->set_values(P.B.val.data());
  auto D = upload(E, dinv ? *dinv : P.dinv), Bv = upload(E, b ? *b : P.b);
  if (x.size() != P.b.size()) x.assign(P.b.size(), 0.0);
  auto        X = upload(E, x);
  SolveResult r = M->solve(*D, *Bv, *X, st);
  x             = download(*X);
  return r;
}
} // namespace

TEST_CASE("device merged CG converges as a plain PCG and as the reference executor", "[device]")
{
  auto E = tested(), R = reference();
  for (const Shape &sh : shapes())
    for (int sym = 0; sym < 2; sym++) {
      if (sh.mbs < 5) continue;
      const Problem P = problem(sh.bs, sh.bw, sh.mbs, sym);
      SolveSettings st;
      st.rtol = 1e-10;
      std::vector<double> x, xr, xc;
      const SolveResult   res = run(*E, P, st, x), ref = run(*R, P, st, xr);
      const int           its = csr_pcg(P.A, P.b, xc, 1e-10, 10000);
      CHECK(res.reason == converged_rtol);
      CHECK(std::abs(res.its - its) <= 1);
      CHECK(rel_diff(x, P.xtrue) <= 1e-8);
      CHECK((int)res.history.size() == res.its + 1);
      CHECK(res.history.back() <= 1e-10 * res.history[0]);
      CHECK(res.host_syncs <= 2 + (res.its + st.check_every - 1) / st.check_every + 2 * res.true_checks);
      /* the executor under test against the reference executor: the same iterations and reason, the
         same norms up to the order of the reductions */
      CHECK(res.its == ref.its);
      CHECK(res.reason == ref.reason);
      for (size_t k = 0; k < std::min(res.history.size(), ref.history.size()); k++)
        CHECK(std::fabs(res.history[k] - ref.history[k]) <= 1e-8 * ref.history[0]);
      CHECK(rel_diff(x, xr) <= 1e-9);
    }
}

TEST_CASE("device merged CG: fixed iterations, no test, one copy to the host", "[device]")
{
  auto          E = tested();
  const Problem P = problem(3, 8, 60, false);
  SolveSettings st;
  st.fixed_its = 7;
  std::vector<double> x, xc;
  const SolveResult   res = run(*E, P, st, x);
  csr_pcg(P.A, P.b, xc, 0.0, 7);
  CHECK(res.its == 7);
  CHECK(res.reason == converged_its);
  CHECK(res.host_syncs == 1);
  CHECK((int)res.history.size() == 8);
  CHECK(rel_diff(x, xc) <= 1e-10);
  /* again, replaying the captured iterations */
  std::vector<double> x2;
  const SolveResult   again = run(*E, P, st, x2);
  CHECK(again.its == 7);
  CHECK(rel_diff(x2, x) <= 1e-15);
}

TEST_CASE("device merged CG: initial guess, norm types, tolerances", "[device]")
{
  auto          E = tested(), R = reference();
  const Problem P = problem(3, 8, 50, false);
  for (Norm nt : {Norm::preconditioned, Norm::unpreconditioned, Norm::natural}) {
    SolveSettings st;
    st.norm               = nt;
    st.rtol               = 1e-9;
    st.guess_zero         = false;
    std::vector<double> x = P.xtrue, xr;
    for (double &v : x) v *= 0.9; /* close to the solution */
    xr                    = x;
    const SolveResult res = run(*E, P, st, x), ref = run(*R, P, st, xr);
    CHECK(res.reason > 0);
    CHECK(res.its == ref.its);
    CHECK(rel_diff(x, P.xtrue) <= 1e-7);
    /* the initial norm is that of r = b - A x0, not of b */
    SolveSettings zero_guess;
    zero_guess.norm = nt;
    CHECK(res.history[0] < 0.5 * run(*R, P, zero_guess, xr).history[0]);
  }
  /* at_start decides the tolerance (PETSc's KSPConvergedDefault) */
  SolveSettings st;
  double        seen = -1;
  st.at_start        = [&](double dp0, double &ttol, double &div) {
    seen = dp0;
    ttol = 1e-3 * dp0;
    div  = 1e30;
  };
  std::vector<double> x;
  const SolveResult   res = run(*E, P, st, x);
  CHECK(seen > 0);
  CHECK(res.history.back() <= 1e-3 * seen);
  CHECK(res.history[res.its - 1] > 1e-3 * seen);
  /* the iteration limit */
  SolveSettings lim;
  lim.max_its = 3;
  lim.rtol    = 1e-14;
  CHECK(run(*E, P, lim, x).reason == diverged_its);
  CHECK(run(*E, P, lim, x).its == 3);
}

TEST_CASE("device merged CG: breakdowns and bad input are reasons, not crashes", "[device]")
{
  auto                E = tested();
  const Problem       P = problem(3, 8, 20, false);
  std::vector<double> x;
  /* zero right-hand side: converged at iteration 0 */
  const std::vector<double> zero(P.b.size(), 0.0);
  SolveResult               res = run(*E, P, SolveSettings{}, x, Precision::double_values, &zero);
  CHECK(res.reason == converged_atol);
  CHECK(res.its == 0);
  /* NaN in b */
  std::vector<double> bad = P.b;
  bad[3]                  = NAN;
  CHECK(run(*E, P, SolveSettings{}, x, Precision::double_values, &bad).reason == diverged_nanorinf);
  /* a negative preconditioner: r.M^-1 r < 0 */
  std::vector<double> neg = P.dinv;
  for (double &v : neg) v = -v;
  CHECK(run(*E, P, SolveSettings{}, x, Precision::double_values, nullptr, &neg).reason ==
        diverged_indefinite_pc);
  /* a negative definite matrix without a preconditioner: p.Ap < 0 */
  const Problem N = problem(3, 8, 20, false, -1.0);
  SolveSettings nj;
  nj.jacobi = false;
  CHECK(run(*E, N, nj, x).reason == diverged_indefinite_mat);
}

TEST_CASE("device merged CG: single storage stops at the precision floor or converges honestly", "[device]")
{
  auto          E = tested(), R = reference();
  const Problem P = problem(3, 8, 80, true);
  SolveSettings st;
  st.rtol     = 1e-12;
  st.roundoff = 5.9604644775390625e-08;
  std::vector<double> x, xr;
  const SolveResult   res = run(*E, P, st, x, Precision::single_values),
                    ref   = run(*R, P, st, xr, Precision::single_values);
  CHECK((res.reason == diverged_breakdown || res.reason > 0));
  CHECK(res.reason == ref.reason);
  CHECK(std::abs(res.its - ref.its) <= 1);
  CHECK(rel_diff(x, P.xtrue) <= 1e-4);
  /* a tolerance the rounding allows is met */
  st.rtol = 1e-5;
  CHECK(run(*E, P, st, x, Precision::single_values).reason == converged_rtol);
}

TEST_CASE("device merged CG: the true-residual check confirms a claim near the rounding drift", "[device]")
{
  auto          E = tested();
  const Problem P = problem(3, 8, 40, false);
  SolveSettings st;
  st.rtol = 1e-15; /* at the drift: the claim, if made, is checked on b - A x */
  std::vector<double> x;
  const SolveResult   res = run(*E, P, st, x);
  CHECK((res.reason > 0 || res.reason == diverged_breakdown || res.reason == diverged_its));
  if (res.reason > 0 && res.true_checks > 0) CHECK(res.rnorm == res.true_rnorm);
  CHECK(rel_diff(x, P.xtrue) <= 1e-10);
}
