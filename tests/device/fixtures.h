/* Matrices and plain CSR arithmetic for the device library's tests (no PETSc). */
#pragma once
#include "device/device.h"
#include "device/host_bins.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace dt {
using namespace binbcsr::device;

inline double rnd(uint64_t k)
{
  k += 0x9e3779b97f4a7c15ull;
  k = (k ^ (k >> 30)) * 0xbf58476d1ce4e5b9ull;
  k = (k ^ (k >> 27)) * 0x94d049bb133111ebull;
  k ^= k >> 31;
  return (double)(k >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

/* A symmetric, diagonally dominant block matrix in block CSR: a band plus random long-range couplings,
   so rows have different lengths and bins padding. */
struct BlockCSR {
  int                 bs = 3, mbs = 0;
  std::vector<int>    ptr, col;
  std::vector<double> val;
};
inline BlockCSR random_spd(int bs, int mbs, uint64_t seed, double shift = 1.0)
{
  std::vector<std::vector<int>> adj(mbs);
  for (int r = 0; r < mbs; r++) {
    adj[r].push_back(r);
    if (r + 1 < mbs) adj[r].push_back(r + 1), adj[r + 1].push_back(r);
    const int extra = (int)((rnd(seed * 7919 + r) + 1.0) * 2.5);
    for (int e = 0; e < extra; e++) {
      const int c = (int)((rnd(seed * 104729 + r * 31 + e) + 1.0) * 0.5 * (mbs - 1));
      if (c != r) adj[r].push_back(c), adj[c].push_back(r);
    }
  }
  BlockCSR A;
  A.bs  = bs;
  A.mbs = mbs;
  A.ptr.assign(1, 0);
  for (auto &a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    A.col.insert(A.col.end(), a.begin(), a.end());
    A.ptr.push_back((int)A.col.size());
  }
  const int bs2 = bs * bs;
  A.val.assign(A.col.size() * bs2, 0.0);
  auto find = [&](int r, int c) {
    return (int)(std::lower_bound(A.col.begin() + A.ptr[r], A.col.begin() + A.ptr[r + 1], c) - A.col.begin());
  };
  std::vector<double> rowsum(mbs * bs, 0.0);
  for (int r = 0; r < mbs; r++)
    for (int p = A.ptr[r]; p < A.ptr[r + 1]; p++) {
      const int c = A.col[p];
      if (c <= r) continue;
      const int q = find(c, r);
      for (int i = 0; i < bs; i++)
        for (int j = 0; j < bs; j++) {
          const double v              = rnd(seed * 1000003 + (uint64_t)p * bs2 + i * bs + j);
          A.val[p * bs2 + i * bs + j] = v;
          A.val[q * bs2 + j * bs + i] = v;
          rowsum[r * bs + i] += std::fabs(v);
          rowsum[c * bs + j] += std::fabs(v);
        }
    }
  for (int r = 0; r < mbs; r++) {
    const int p = find(r, r);
    for (int i = 0; i < bs; i++)
      for (int j = 0; j < bs; j++) {
        const double v = i == j ? 0.0 : 0.1 * rnd(seed * 7 + r * 131 + std::min(i, j) * 11 + std::max(i, j));
        A.val[p * bs2 + i * bs + j] = v;
        rowsum[r * bs + i] += std::fabs(v);
      }
    for (int i = 0; i < bs; i++) A.val[p * bs2 + i * bs + i] = shift * (rowsum[r * bs + i] + 1.0 + i);
  }
  return A;
}

/* y = A x by point rows of the block CSR, and sum_j |a_ij x_j| (the scale of a product's rounding). */
inline void csr_mult(const BlockCSR &A, const std::vector<double> &x, std::vector<double> &y,
                     std::vector<double> *scale = nullptr)
{
  const int bs = A.bs, bs2 = bs * bs;
  y.assign((size_t)A.mbs * bs, 0.0);
  if (scale) scale->assign(y.size(), 0.0);
  for (int r = 0; r < A.mbs; r++)
    for (int p = A.ptr[r]; p < A.ptr[r + 1]; p++)
      for (int i = 0; i < bs; i++)
        for (int j = 0; j < bs; j++) {
          const double t = A.val[(size_t)p * bs2 + i * bs + j] * x[(size_t)A.col[p] * bs + j];
          y[(size_t)r * bs + i] += t;
          if (scale) (*scale)[(size_t)r * bs + i] += std::fabs(t);
        }
}

inline std::vector<double> inverse_diagonal(const BlockCSR &A)
{
  std::vector<double> d((size_t)A.mbs * A.bs);
  for (int r = 0; r < A.mbs; r++)
    for (int p = A.ptr[r]; p < A.ptr[r + 1]; p++)
      if (A.col[p] == r)
        for (int i = 0; i < A.bs; i++)
          d[(size_t)r * A.bs + i] = 1.0 / A.val[(size_t)p * A.bs * A.bs + i * A.bs + i];
  return d;
}

inline std::vector<double> random_vector(long n, uint64_t seed)
{
  std::vector<double> v(n);
  for (long i = 0; i < n; i++) v[i] = rnd(seed * 65537 + i);
  return v;
}

/* The executor under test, and the reference executor it is compared with. */
inline std::string tested_name()
{
  const char *e = std::getenv("BINBCSR_DEVICE_EXECUTOR");
  return e && *e ? e : "reference";
}
inline std::unique_ptr<Executor> tested()
{
  std::string why;
  auto        e = make_executor(tested_name(), &why);
  if (!e) throw std::runtime_error("executor " + tested_name() + ": " + why);
  return e;
}
inline std::unique_ptr<Executor> reference()
{
  std::string why;
  return make_executor("reference", &why);
}

/* The shapes every product test runs: block size, bin width, block rows (partial last bins). */
struct Shape {
  int bs, bw, mbs;
};
inline std::vector<Shape> shapes()
{
  return {{3, 8, 37}, {3, 32, 70}, {3, 4, 5}, {1, 16, 101}, {1, 8, 64}, {1, 32, 33}, {3, 8, 1}};
}

inline std::vector<double> download(const Vector &v)
{
  std::vector<double> h(v.size());
  v.download(h.data());
  return h;
}
inline std::unique_ptr<Vector> upload(Executor &E, const std::vector<double> &h)
{
  auto v = E.vector((long)h.size());
  v->upload(h.data());
  return v;
}

} // namespace dt
