/* The reference executor: host memory, one thread, the bodies of binbcsr_kernels.h, mcg_kernels.h and
   device_bodies.h in plain loops over bins and lanes (the lanes one after another). Every result of the
   cuda executor is tested against this one. */
#include "reference.h"
#include "mcg_driver.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace binbcsr {
namespace device {
namespace {

class RefVector : public Vector {
public:
  explicit RefVector(long n) : v(n, 0.0) {}
  long size() const override { return (long)v.size(); }
  void upload(const double *h) override { std::memcpy(v.data(), h, v.size() * sizeof(double)); }
  void download(double *h) const override { std::memcpy(h, v.data(), v.size() * sizeof(double)); }
  std::vector<double> v;
};
const double *data(const Vector &x) { return static_cast<const RefVector &>(x).v.data(); }
double       *data(Vector &x) { return static_cast<RefVector &>(x).v.data(); }

template <int BS, typename V> void whole_mult(const Layout &L, const V *val, const double *x, double *y)
{
  const int bs = BS ? BS : L.bs, bs2 = bs * bs;
  for (int b = 0; b < L.nbins(); b++) {
    const int s0 = L.bin_start[b], len = (L.bin_start[b + 1] - s0) / L.bw;
    for (int lane = 0; lane < L.bw; lane++) {
      const long r = (long)b * L.bw + lane;
      if (r >= L.mbs) break;
      double acc[BS ? BS : 8] = {0};
      lane_mult<BS, V, int>(val + (long)s0 * bs2, L.col + s0, len, L.bw, bs, lane, x, acc);
      for (int i = 0; i < bs; i++) y[r * bs + i] = acc[i];
    }
  }
}

template <int BS, typename V> void sym_mult(const Layout &L, const V *val, const double *x, double *y)
{
  const int bs = BS ? BS : L.bs, bs2 = bs * bs;
  std::memset(y, 0, sizeof(double) * L.n());
  for (int b = 0; b < L.nbins(); b++) {
    const int s0 = L.bin_start[b], len = (L.bin_start[b + 1] - s0) / L.bw;
    for (int lane = 0; lane < L.bw; lane++) {
      const long r                = (long)b * L.bw + lane;
      const bool real             = r < L.mbs;
      double     acc[BS ? BS : 8] = {0}, xr[BS ? BS : 8] = {0};
      for (int i = 0; i < bs && real; i++) xr[i] = x[r * bs + i];
      const int own = real ? (int)r : L.mbs - 1;
      /* The device layout carries no diagonal-slot map: the diagonal block is the lane's first slot of
         column own (padding follows the real slots and also names own). A row without a diagonal
         block then multiplies one padding slot by x_own (zero unless x_own is not finite): the device
         products are not yet NaN-exact (docs/gpu.md). */
      int kd = -1;
      for (int k = 0; k < len && kd < 0; k++)
        if (L.col[s0 + (long)k * L.bw + lane] == own) kd = k;
      sym_lane_mult<BS, V, int>(val + (long)s0 * bs2, L.col + s0, len, L.bw, bs, lane, own, kd, x, xr, y,
                                acc);
      for (int i = 0; i < bs && real; i++) y[r * bs + i] += acc[i];
    }
  }
}

template <typename V> class RefMatrix : public Matrix {
public:
  RefMatrix(const Layout &L, Precision p) : prec(p)
  {
    if (L.bs < 1 || L.bs > 8 || L.bw < 1 || L.mbs < 1)
      throw std::invalid_argument("device: layout needs 1 <= bs <= 8, bw >= 1, mbs >= 1");
    bin_start.assign(L.bin_start, L.bin_start + L.nbins() + 1);
    col.assign(L.col, L.col + L.nslots());
    lay           = L;
    lay.bin_start = bin_start.data();
    lay.col       = col.data();
    val.assign(lay.nvalues(), (V)0);
  }
  const Layout &layout() const override { return lay; }
  Precision     precision() const override { return prec; }
  void          set_values(const double *v) override
  {
    for (long i = 0; i < lay.nvalues(); i++) val[i] = (V)v[i];
  }
  void get_values(double *v) const override
  {
    for (long i = 0; i < lay.nvalues(); i++) v[i] = (double)val[i];
  }
  void set_gather_map(const GatherMap &m) override
  {
    jmap.assign(m.jmap, m.jmap + lay.nvalues() + 1);
    perm.assign(m.perm, m.perm + jmap.back());
    ncoo = m.ncoo;
  }
  void refill(const double *coo, bool add) override
  {
    if (jmap.empty()) throw std::logic_error("device: refill before set_gather_map");
    coo_buf.assign(coo, coo + ncoo); /* the upload a device executor makes */
    for (int b = 0; b < lay.nbins(); b++)
      for (int lane = 0; lane < lay.bw; lane++) {
        if (add)
          lane_refill<V, true>(val.data(), bin_start.data(), b, lane, lay.bw, lay.bs * lay.bs, jmap.data(),
                               perm.data(), coo_buf.data(), ncoo);
        else
          lane_refill<V, false>(val.data(), bin_start.data(), b, lane, lay.bw, lay.bs * lay.bs, jmap.data(),
                                perm.data(), coo_buf.data(), ncoo);
      }
  }
  void mult_raw(const double *x, double *y) const
  {
    if (lay.symmetric) {
      if (lay.bs == 3) sym_mult<3, V>(lay, val.data(), x, y);
      else if (lay.bs == 1) sym_mult<1, V>(lay, val.data(), x, y);
      else sym_mult<0, V>(lay, val.data(), x, y);
    } else {
      if (lay.bs == 3) whole_mult<3, V>(lay, val.data(), x, y);
      else if (lay.bs == 1) whole_mult<1, V>(lay, val.data(), x, y);
      else whole_mult<0, V>(lay, val.data(), x, y);
    }
  }
  void   mult(const Vector &x, Vector &y) override { mult_raw(data(x), data(y)); }
  double mult_dot(const Vector &x, Vector &y) override
  {
    mult_raw(data(x), data(y));
    const double *xa = data(x), *ya = data(y);
    double        d = 0.0;
    for (long i = 0; i < lay.n(); i++) d += xa[i] * ya[i];
    return d;
  }
  SolveResult solve(const Vector &dinv, const Vector &b, Vector &x, const SolveSettings &st) override;

private:
  Layout              lay;
  Precision           prec;
  std::vector<int>    bin_start, col, jmap, perm;
  std::vector<V>      val;
  std::vector<double> coo_buf;
  long                ncoo = 0;
};

/* The merged CG on the host arrays, in the passes the cuda executor launches (each reduction a
   sequential sum here). */
template <typename V> struct RefOps {
  const RefMatrix<V> &A;
  const double       *dinv, *b;
  double             *x;
  bool                jacobi;
  long                n;
  std::vector<double> r, u, w, p, s, hist;
  MCGState            st;
  RefOps(const RefMatrix<V> &A_, const double *dinv_, const double *b_, double *x_, bool jac, int max_its)
      : A(A_), dinv(dinv_), b(b_), x(x_), jacobi(jac), n(A_.layout().n()), r(n), u(n), w(n), p(n, 0.0),
        s(n, 0.0), hist((size_t)max_its + 1)
  {
  }

  void precondition(double *dots)
  {
    double ru = 0, rr = 0, uu = 0;
    for (long i = 0; i < n; i++) {
      if (jacobi) mcg_precondition_index<true, double>(i, r.data(), dinv, u.data(), ru, rr, uu);
      else mcg_precondition_index<false, double>(i, r.data(), nullptr, u.data(), ru, rr, uu);
    }
    dots[MCG_DOT_RU] = ru;
    dots[MCG_DOT_RR] = rr;
    dots[MCG_DOT_UU] = uu;
    dots[MCG_DOT_UW] = dots[MCG_DOT_XX] = 0;
  }
  double product_dot()
  {
    A.mult_raw(u.data(), w.data());
    double d = 0;
    for (long i = 0; i < n; i++) d += u[i] * w[i];
    return d;
  }
  void true_residual(bool zero)
  {
    if (zero) {
      for (long i = 0; i < n; i++) x[i] = 0.0, r[i] = b[i];
      return;
    }
    A.mult_raw(x, r.data());
    for (long i = 0; i < n; i++) r[i] = b[i] - r[i];
  }
  void start(bool guess_zero, bool test_on_device)
  {
    double dots[MCG_NDOTS];
    true_residual(guess_zero);
    precondition(dots);
    dots[MCG_DOT_UW] = product_dot();
    mcg_start_step(st, dots, hist.data());
    if (test_on_device) mcg_start_test(st);
  }
  void iterations(int k)
  {
    for (int t = 0; t < k && !st.done && !st.want_verify; t++) {
      double ru = 0, rr = 0, uu = 0, xx = 0, dots[MCG_NDOTS];
      for (long i = 0; i < n; i++) {
        if (jacobi)
          mcg_update_index<true, double>(i, st.alpha, st.beta, u.data(), w.data(), p.data(), s.data(), x,
                                         r.data(), dinv, ru, rr, uu, xx);
        else
          mcg_update_index<false, double>(i, st.alpha, st.beta, u.data(), w.data(), p.data(), s.data(), x,
                                          r.data(), nullptr, ru, rr, uu, xx);
      }
      dots[MCG_DOT_RU] = ru;
      dots[MCG_DOT_RR] = rr;
      dots[MCG_DOT_UU] = uu;
      dots[MCG_DOT_XX] = xx;
      dots[MCG_DOT_UW] = st.its + 1 < st.max_its ? product_dot() : 0.0; /* none follows the last iteration */
      mcg_step(st, dots, hist.data());
    }
  }
  void verify()
  {
    double dots[MCG_NDOTS];
    true_residual(false);
    precondition(dots);
    if (!mcg_verify_step(st, dots)) return;
    std::fill(p.begin(), p.end(), 0.0);
    std::fill(s.begin(), s.end(), 0.0);
    mcg_restart_step(st, product_dot(), dots[MCG_DOT_UU]);
  }
  void get_state(MCGState &o) { o = st; }
  void put_state(const MCGState &o) { st = o; }
  void history(double *h, int count) { std::copy(hist.begin(), hist.begin() + count, h); }
};

template <typename V>
SolveResult RefMatrix<V>::solve(const Vector &dinv, const Vector &b, Vector &x, const SolveSettings &st)
{
  RefOps<V> ops(*this, data(dinv), data(b), data(x), st.jacobi, st.fixed_its > 0 ? st.fixed_its : st.max_its);
  return run_mcg(ops, st);
}

class RefExecutor : public Executor {
public:
  const char             *name() const override { return "reference"; }
  std::unique_ptr<Vector> vector(long n) override { return std::make_unique<RefVector>(n); }
  std::unique_ptr<Matrix> matrix(const Layout &L, Precision p) override
  {
    if (p == Precision::single_values) return std::make_unique<RefMatrix<float>>(L, p);
    return std::make_unique<RefMatrix<double>>(L, p);
  }
  void synchronize() override {}
};

} // namespace

std::unique_ptr<Executor> make_reference_executor() { return std::make_unique<RefExecutor>(); }

} // namespace device
} // namespace binbcsr
