// Benchmark of the device library (src/device/) on one executor: y = A x (whole and symmetric
// storage, double and single values), the fused product + dot, the refill from a COO value array, and
// the merged CG (30 fixed iterations; and to rtol 1e-6 with a check every 8 iterations). Matrices:
// the 27-point block stencils and PETSc binary files of examples/gpu/bench_matrices.h. No PETSc.
//   device_bench [-executor cuda|reference] [-stencil 16,32] [-f A.bin]... [-reps 1]
// Each figure is the median of 5 batches; a batch runs the operation until 20 ms (at least once).
#include "../examples/gpu/bench_matrices.h"
#include "device/device.h"
#include "device/host_bins.h"

#include <algorithm>
#include <chrono>

using namespace binbcsr::device;

namespace {
double now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
template <class F> double median_time(Executor &E, F &&f, double batch_s)
{
  std::vector<double> t;
  for (int b = 0; b < 5; b++) {
    E.synchronize();
    const double t0 = now();
    int          k  = 0;
    do {
      f();
      k++;
      E.synchronize();
    } while (now() - t0 < batch_s);
    t.push_back((now() - t0) / k);
  }
  std::sort(t.begin(), t.end());
  return t[2];
}
void bench(Executor &E, const gpu_bench::BlockMatrix &A, double batch_s)
{
  const long n = A.n(), nnz = A.nblocks() * A.bs * A.bs;
  std::printf("\n%s: %ld rows, %.2f M nonzeros (executor %s)\n", A.name.c_str(), n, nnz * 1e-6, E.name());
  std::printf("  %-26s %10s %10s %s\n", "operation", "us", "GB/s", "check");
  std::vector<double> x(n), ref;
  for (long i = 0; i < n; i++) x[i] = 1.0 + 1e-3 * (double)(i % 97);
  {
    const gpu_bench::ScalarCSR S = gpu_bench::scalar_csr(A);
    ref.assign(n, 0.0);
    for (long r = 0; r < n; r++)
      for (int p = S.ptr[r]; p < S.ptr[r + 1]; p++) ref[r] += S.val[p] * x[S.col[p]];
  }
  auto X = E.vector(n), Y = E.vector(n);
  X->upload(x.data());
  for (int sym = 0; sym < 2; sym++)
    for (int single = 0; single < 2; single++) {
      const HostBins B = bins_from_bcsr(A.bs, A.mbs, A.ptr.data(), A.col.data(), A.val.data(), 8, sym);
      auto           M = E.matrix(B.layout(), single ? Precision::single_values : Precision::double_values);
      M->set_values(B.val.data());
      const double bytes = (double)B.val.size() * (single ? 4 : 8) + B.col.size() * 4.0 + 16.0 * n;
      const double t     = median_time(
            E, [&] { M->mult(*X, *Y); }, batch_s);
      std::vector<double> y(n);
      Y->download(y.data());
      double err = 0, sc = 0;
      for (long i = 0; i < n; i++)
        err = std::max(err, std::fabs(y[i] - ref[i])), sc = std::max(sc, std::fabs(ref[i]));
      char name[64];
      std::snprintf(name, sizeof name, "mult %s %s", sym ? "symmetric" : "whole",
                    single ? "single" : "double");
      std::printf("  %-26s %10.1f %10.0f %.1e\n", name, t * 1e6, bytes / t * 1e-9, err / sc);
      if (!sym && !single) {
        const double td = median_time(
          E, [&] { M->mult_dot(*X, *Y); }, batch_s);
        std::printf("  %-26s %10.1f %10.0f\n", "mult_dot whole double", td * 1e6, bytes / td * 1e-9);
        /* refill: one COO entry per stored scalar, in block CSR order (an assembly's element order
           would add duplicates; the gather reads each once) */
        std::vector<int>    ci, cj;
        std::vector<double> cv;
        for (int r = 0; r < A.mbs; r++)
          for (int p = A.ptr[r]; p < A.ptr[r + 1]; p++)
            for (int e = 0; e < A.bs * A.bs; e++)
              ci.push_back(r * A.bs + e / A.bs), cj.push_back(A.col[p] * A.bs + e % A.bs),
                cv.push_back(A.val[(size_t)p * A.bs * A.bs + e]);
        const HostGather G = gather_from_coo(B, (long)cv.size(), ci.data(), cj.data());
        M->set_gather_map(G.map());
        const double tr = median_time(
          E, [&] { M->refill(cv.data()); }, batch_s);
        std::printf("  %-26s %10.1f %10.0f (COO upload included)\n", "refill from COO", tr * 1e6,
                    (cv.size() * 16.0 + G.perm.size() * 4.0 + G.jmap.size() * 4.0 + B.val.size() * 8.0) / tr *
                      1e-9);
        /* the merged CG, Jacobi */
        std::vector<double> dinv(n, 1.0);
        for (int r = 0; r < A.mbs; r++)
          for (int p = A.ptr[r]; p < A.ptr[r + 1]; p++)
            if (A.col[p] == r)
              for (int i = 0; i < A.bs; i++)
                dinv[(size_t)r * A.bs + i] = 1.0 / A.val[(size_t)p * A.bs * A.bs + i * A.bs + i];
        auto D = E.vector(n), Bv = E.vector(n), Xs = E.vector(n);
        D->upload(dinv.data());
        Bv->upload(ref.data());
        SolveSettings fixed;
        fixed.fixed_its = 30;
        SolveResult  last;
        const double tf = median_time(
          E, [&] { last = M->solve(*D, *Bv, *Xs, fixed); }, batch_s);
        std::printf("  %-26s %10.1f %10s %d its, %d host copies, %.2f us/iteration\n",
                    "CG 30 fixed iterations", tf * 1e6, "", last.its, last.host_syncs, tf * 1e6 / 30);
        SolveSettings tol;
        tol.rtol        = 1e-6;
        const double tt = median_time(
          E, [&] { last = M->solve(*D, *Bv, *Xs, tol); }, batch_s);
        std::vector<double> xs(n);
        Xs->download(xs.data());
        double xerr = 0;
        for (long i = 0; i < n; i++) xerr = std::max(xerr, std::fabs(xs[i] - x[i]));
        std::printf(
          "  %-26s %10.1f %10s %d its, reason %d, %d host copies, %.2f us/iteration, max |x - x*| %.1e\n",
          "CG to rtol 1e-6", tt * 1e6, "", last.its, last.reason, last.host_syncs,
          tt * 1e6 / std::max(1, last.its), xerr);
      }
    }
}
} // namespace

int main(int argc, char **argv)
{
  std::string              exec = "cuda";
  std::vector<int>         sizes;
  std::vector<std::string> files;
  double                   batch_s = 0.02;
  for (int i = 1; i < argc; i++) {
    const std::string a = argv[i];
    if (i + 1 < argc && a == "-executor") exec = argv[++i];
    else if (i + 1 < argc && a == "-stencil") {
      std::string v = argv[++i];
      for (size_t p = 0; p < v.size();) {
        const size_t q = v.find(',', p);
        sizes.push_back(std::atoi(v.substr(p, q - p).c_str()));
        p = q == std::string::npos ? v.size() : q + 1;
      }
    } else if (i + 1 < argc && a == "-f") files.push_back(argv[++i]);
    else if (i + 1 < argc && a == "-batch_ms") batch_s = std::atof(argv[++i]) * 1e-3;
    else {
      std::fprintf(stderr,
                   "usage: %s [-executor cuda|reference] [-stencil 16,32] [-f A.bin]... [-batch_ms 20]\n",
                   argv[0]);
      return 2;
    }
  }
  std::string why;
  auto        E = make_executor(exec, &why);
  if (!E) {
    std::fprintf(stderr, "executor %s: %s\n", exec.c_str(), why.c_str());
    return 1;
  }
  if (sizes.empty() && files.empty()) sizes = {16};
  for (int s : sizes) bench(*E, gpu_bench::stencil_matrix(s), batch_s);
  for (const std::string &f : files) bench(*E, gpu_bench::read_matrix(f, 3), batch_s);
  return 0;
}
