// Helpers of the layout tuner's tests (tune.cpp, tune_cache.cpp): a cache folder per case, options
// set for a case, a tuned matrix built from a pattern, and the check that two layouts hold the same
// matrix and give the same products.
#pragma once
#include "support/mat_support.hpp"
#include <petscviewer.h>
#include <cstdlib>
#include <map>
#include <sys/stat.h>

namespace mat_core {

// A fresh cache folder for one test case: XDG_CACHE_HOME=<base>/<name>, the file removed.
inline std::string fresh_cache(const std::string &name)
{
  const char *base = getenv("XDG_CACHE_HOME");
  std::string root = std::string(base && base[0] == '/' ? base : "/tmp") + "/" + name;
  mkdir(root.c_str(), 0755);
  std::remove((root + "/petscbinbcsr/tune.txt").c_str());
  setenv("XDG_CACHE_HOME", root.c_str(), 1);
  return root + "/petscbinbcsr/tune.txt";
}

struct Restore { // puts XDG_CACHE_HOME back at the end of a case
  std::string old;
  bool        had;
  Restore() : had(getenv("XDG_CACHE_HOME") != nullptr)
  {
    if (had) old = getenv("XDG_CACHE_HOME");
  }
  ~Restore()
  {
    if (had) setenv("XDG_CACHE_HOME", old.c_str(), 1);
    else unsetenv("XDG_CACHE_HOME");
  }
};

// Options for one case; every size is tuned (the patterns here are small, to keep the case fast).
struct Opts {
  std::vector<std::string> names;
  void                     set(const char *n, const char *v)
  {
    REQUIRE(PetscOptionsSetValue(nullptr, n, v) == 0);
    names.push_back(n);
  }
  Opts(bool cache)
  {
    set("-mat_binbcsr_tune_min_kib", "0");
    set("-mat_binbcsr_tune_cache", cache ? "1" : "0");
  }
  ~Opts()
  {
    for (auto &n : names) PetscOptionsClearValue(nullptr, n.c_str());
  }
};

inline PetscInt bin_width(Mat A)
{
  PetscInt bw;
  REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
  return bw;
}

inline PetscInt streams(Mat A)
{
  PetscInt k;
  REQUIRE(MatBinBCSRGetStreams(A, &k) == 0);
  return k;
}

// Both matrices hold the same values and give the same products: bit-identical with whole storage and
// one body set (the tuner changes only the order of slots and bins, not a row's order of summation); within the
// rounding of the sums with symmetric storage (the transposed contributions arrive in another order).
inline void check_same(Mat A, Mat R, const Pattern &p)
{
  Vec              x = make_vec(p.n, 7), y, yr;
  PetscBool        sym;
  MatBinBCSRKernel kernel;
  // R runs A's body set: bodies compiled with other target flags contract multiply-adds differently,
  // so bit identity holds within one set (tests/unit/mat_binbcsr/mat_core/bodies.cpp compares the sets)
  REQUIRE(MatBinBCSRGetKernel(A, &kernel) == 0);
  REQUIRE(MatBinBCSRSetKernel(R, kernel) == 0);
  REQUIRE(VecDuplicate(x, &y) == 0);
  REQUIRE(VecDuplicate(x, &yr) == 0);
  REQUIRE(MatMult(A, x, y) == 0);
  REQUIRE(MatMult(R, x, yr) == 0);
  REQUIRE(MatBinBCSRGetSymmetricStorage(A, &sym) == 0);
  const auto a = values(y), r = values(yr);
  if (sym) check_close(a, r, mult_bound(p, values(x), 0.0, false));
  else {
    size_t diff = 0;
    for (size_t i = 0; i < a.size(); i++) diff += a[i] != r[i];
    CHECK(diff == 0);
  }
  check_dense(dense(A), dense(R), 0);
  VecDestroy(&x);
  VecDestroy(&y);
  VecDestroy(&yr);
}

inline Mat build_tuned(const Pattern &p, MatBinBCSRPrecision prec, bool sym, MatBinBCSRTune tune,
                       PetscInt bw = 0, PetscInt k = 0)
{
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, p.bs) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  REQUIRE(MatBinBCSRSetTune(A, tune) == 0);
  if (bw) REQUIRE(MatBinBCSRSetBinWidth(A, bw) == 0);
  if (k) REQUIRE(MatBinBCSRSetStreams(A, k) == 0);
  REQUIRE(MatBinBCSRSetPrecision(A, prec) == 0);
  REQUIRE(MatBinBCSRSetSymmetricStorage(A, sym ? PETSC_TRUE : PETSC_FALSE) == 0);
  REQUIRE(MatSetFromOptions(A) == 0);
  REQUIRE(MatSetUp(A) == 0);
  for (const Entry &e : p.entries) REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  return A;
}

// A symmetric FEM pattern (values made symmetric so both storages hold the same matrix).
inline Pattern sym_pattern(PetscInt n, PetscInt bs)
{
  Pattern                                              p = fem_pattern(n, n, n, bs);
  std::map<std::pair<PetscInt, PetscInt>, PetscScalar> m;
  for (const Entry &e : p.entries) m[{std::min(e.i, e.j), std::max(e.i, e.j)}] = e.v;
  for (Entry &e : p.entries) e.v = m[{std::min(e.i, e.j), std::max(e.i, e.j)}];
  return p;
}

} // namespace mat_core
