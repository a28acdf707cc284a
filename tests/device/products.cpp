/* The device library's bins, refill and products on the executor under test, against plain CSR. */
#include "device_test.h"
#include "fixtures.h"

#include <algorithm>

using namespace dt;

namespace {
/* max_i |y_i - ref_i| / (sum_j |a_ij x_j| + tiny) */
double product_error(const std::vector<double> &y, const std::vector<double> &ref,
                     const std::vector<double> &scale)
{
  double e = 0;
  for (size_t i = 0; i < y.size(); i++) {
    const double d = std::fabs(y[i] - ref[i]) / (scale[i] + 1e-300);
    e              = std::isfinite(y[i]) ? std::max(e, d) : 1e300;
  }
  return e;
}
} // namespace

TEST_CASE("device products match CSR: whole and symmetric storage, double and single values", "[device]")
{
  auto E = tested();
  for (const Shape &sh : shapes())
    for (int sym = 0; sym < 2; sym++)
      for (int single = 0; single < 2; single++) {
        const BlockCSR A = random_spd(sh.bs, sh.mbs, 11 + sh.bw + sh.mbs);
        const HostBins B = bins_from_bcsr(A.bs, A.mbs, A.ptr.data(), A.col.data(), A.val.data(), sh.bw, sym);
        auto M = E->matrix(B.layout(), single ? Precision::single_values : Precision::double_values);
        M->set_values(B.val.data());
        const std::vector<double> x = random_vector((long)A.mbs * A.bs, 5);
        std::vector<double>       ref, scale;
        csr_mult(A, x, ref, &scale);
        auto       X = upload(*E, x), Y = E->vector(X->size());
        const auto nan = std::vector<double>(x.size(), NAN); /* an unwritten entry fails */
        Y->upload(nan.data());
        M->mult(*X, *Y);
        const double tol = single ? 1.2e-7 : 1e-14;
        CHECK(product_error(download(*Y), ref, scale) <= tol);
        Y->upload(nan.data());
        const double d    = M->mult_dot(*X, *Y);
        double       dref = 0, dscale = 0;
        for (size_t i = 0; i < x.size(); i++) dref += x[i] * ref[i], dscale += std::fabs(x[i]) * scale[i];
        CHECK(product_error(download(*Y), ref, scale) <= tol);
        CHECK(std::fabs(d - dref) <= (tol + 1e-14) * dscale);
        /* the values round-trip (rounded to the storage precision once) */
        std::vector<double> back(B.val.size());
        M->get_values(back.data());
        double verr = 0;
        for (size_t i = 0; i < back.size(); i++)
          verr = std::max(verr, std::fabs(back[i] - B.val[i]) - (single ? std::fabs(B.val[i]) * 6e-8 : 0.0));
        CHECK(verr <= 0.0);
      }
}

TEST_CASE("device refill gathers the COO values of each stored value, padding stays zero", "[device]")
{
  auto E = tested();
  for (const Shape &sh : shapes())
    for (int sym = 0; sym < 2; sym++) {
      const BlockCSR A  = random_spd(sh.bs, sh.mbs, 3 + sh.mbs);
      const HostBins B  = bins_from_bcsr(A.bs, A.mbs, A.ptr.data(), A.col.data(), A.val.data(), sh.bw, sym);
      const int      bs = A.bs, bs2 = bs * bs;
      /* every entry split into two COO entries at different places of the list, plus entries below
         the diagonal (ignored with symmetric storage, kept otherwise) */
      std::vector<int>    ci, cj;
      std::vector<double> cv;
      for (int pass = 0; pass < 2; pass++)
        for (int r = 0; r < A.mbs; r++)
          for (int p = A.ptr[r]; p < A.ptr[r + 1]; p++)
            for (int e = 0; e < bs2; e++) {
              const double v = A.val[(size_t)p * bs2 + e];
              ci.push_back(r * bs + e / bs);
              cj.push_back(A.col[p] * bs + e % bs);
              cv.push_back(pass == 0 ? 0.25 * v : 0.75 * v);
            }
      ci.push_back(0), cj.push_back(A.mbs * bs + 5), cv.push_back(1e300); /* outside the matrix: ignored */
      const HostGather          G = gather_from_coo(B, (long)cv.size(), ci.data(), cj.data());
      auto                      M = E->matrix(B.layout(), Precision::double_values);
      const std::vector<double> junk(B.val.size(), 7.0);
      M->set_values(junk.data());
      M->set_gather_map(G.map());
      M->refill(cv.data());
      std::vector<double> got(B.val.size());
      M->get_values(got.data());
      double err = 0;
      for (size_t i = 0; i < got.size(); i++)
        err = std::max(err, std::fabs(got[i] - B.val[i]) / (std::fabs(B.val[i]) + 1e-300) * (B.val[i] != 0) +
                              std::fabs(got[i]) * (B.val[i] == 0));
      CHECK(err <= 2.3e-16);
      /* ADD_VALUES: twice the matrix */
      M->refill(cv.data(), true);
      M->get_values(got.data());
      err = 0;
      for (size_t i = 0; i < got.size(); i++)
        err = std::max(err, std::fabs(got[i] - 2 * B.val[i]) - 4.5e-16 * std::fabs(B.val[i]));
      CHECK(err <= 0.0);
      /* the refilled matrix multiplies as CSR */
      M->refill(cv.data());
      const std::vector<double> x = random_vector((long)A.mbs * bs, 9);
      std::vector<double>       ref, scale;
      csr_mult(A, x, ref, &scale);
      auto X = upload(*E, x), Y = E->vector(X->size());
      M->mult(*X, *Y);
      CHECK(product_error(download(*Y), ref, scale) <= 1e-14);
    }
}

TEST_CASE("device executors by name: unknown names and unbuilt executors say why", "[device]")
{
  std::string why;
  CHECK(make_executor("reference", &why) != nullptr);
  CHECK(make_executor("opencl", &why) == nullptr);
  CHECK(why.find("unknown executor") != std::string::npos);
  auto c = make_executor("cuda", &why);
  if (!cuda_built()) {
    CHECK(c == nullptr);
    CHECK(why.find("not built") != std::string::npos);
  } else if (!c) CHECK(why.find("device") != std::string::npos);
}
