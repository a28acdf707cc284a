// The layout tuner (-mat_binbcsr_tune): it chooses among the candidates, the products and stored
// values stay exactly those of a fixed configuration, explicit settings win, the cache file round
// trips, a corrupt one is ignored, bad values give errors. The cache lives in a folder of the test
// run (XDG_CACHE_HOME, set by CTest; each case here points it at its own folder).
#include "support/mat_support.hpp"
#include "mat_binbcsr/seq/binbcsr.h" // BINBCSR_XLOAD_TRIAL
#include <petscviewer.h>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

using namespace mat_core;

namespace {

// A fresh cache folder for one test case: XDG_CACHE_HOME=<base>/<name>, the file removed.
std::string fresh_cache(const std::string &name)
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

PetscInt bin_width(Mat A)
{
  PetscInt bw;
  REQUIRE(MatBinBCSRGetBinWidth(A, &bw) == 0);
  return bw;
}

PetscInt streams(Mat A)
{
  PetscInt k;
  REQUIRE(MatBinBCSRGetStreams(A, &k) == 0);
  return k;
}

// Both matrices hold the same values and give the same products: bit-identical with whole storage and
// one body set (the tuner changes only the order of slots and bins, not a row's order of summation); within the
// rounding of the sums with symmetric storage (the transposed contributions arrive in another order).
void check_same(Mat A, Mat R, const Pattern &p)
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

Mat build_tuned(const Pattern &p, MatBinBCSRPrecision prec, bool sym, MatBinBCSRTune tune, PetscInt bw = 0,
                PetscInt k = 0)
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
Pattern sym_pattern(PetscInt n, PetscInt bs)
{
  Pattern                                              p = fem_pattern(n, n, n, bs);
  std::map<std::pair<PetscInt, PetscInt>, PetscScalar> m;
  for (const Entry &e : p.entries) m[{std::min(e.i, e.j), std::max(e.i, e.j)}] = e.v;
  for (Entry &e : p.entries) e.v = m[{std::min(e.i, e.j), std::max(e.i, e.j)}];
  return p;
}

} // namespace

TEST_CASE("tuning chooses among the candidates; products and values stay exact", "[tune]")
{
  Restore r;
  fresh_cache("tune_exact");
  Opts o(false);
  for (PetscInt bs : {1, 3})
    for (auto prec : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE})
      for (bool sym : {false, true}) {
        CAPTURE(bs, (int)prec, sym);
        const Pattern p   = sym_pattern(bs == 1 ? 12 : 7, bs);
        Mat           A   = build_tuned(p, prec, sym, MAT_BINBCSR_TUNE_AUTO);
        Mat           R   = build_tuned(p, prec, sym, MAT_BINBCSR_TUNE_OFF, bs == 1 ? 16 : 8, 4);
        const auto    txt = info_view(A);
        CAPTURE(txt);
        CHECK(txt.find("tuning (-mat_binbcsr_tune): bin width") != std::string::npos);
        CHECK(txt.find("measured on block rows") != std::string::npos);
        const PetscInt bw = bin_width(A), k = streams(A);
        CHECK((bw == 4 || bw == 8 || bw == 16 || (bw == 32 && bs == 1)));
        CHECK((k == 1 || k == 2 || k == 4 || k == 8));
        // every candidate was timed (the budget admits them all on a matrix this small)
        CHECK(txt.find("left out by the budget") == std::string::npos);
        CHECK(txt.find(" 4/") != std::string::npos);
        CHECK(txt.find(" 16/") != std::string::npos);
        PetscBool avx2;
        REQUIRE(MatBinBCSRKernelAvailable(MAT_BINBCSR_KERNEL_AVX2, &avx2) == 0);
        if (avx2) CHECK(txt.find("/portable ") != std::string::npos); // the other body sets were timed too
        // and the prefetch distances other than the default
        CHECK(txt.find("/pf0 ") != std::string::npos);
        CHECK(txt.find("/pf1024 ") != std::string::npos);
        PetscInt pf = -1;
        REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
        CHECK((pf == 0 || pf == 1024 || pf == 4096));
        check_same(A, R, p);
        Mat D;
        REQUIRE(MatDuplicate(A, MAT_COPY_VALUES, &D) == 0);
        CHECK(bin_width(D) == bw);
        CHECK(streams(D) == k);
        check_same(D, R, p);
        MatDestroy(&D);
        CHECK(info_view(R).find("tuning (-mat_binbcsr_tune): off") != std::string::npos);
        MatDestroy(&A);
        MatDestroy(&R);
      }
}

TEST_CASE("tuning through COO assembly keeps the values exact", "[tune]")
{
  Restore r;
  fresh_cache("tune_coo");
  Opts                     o(false);
  const Pattern            p = fem_pattern(7, 7, 7, 3);
  std::vector<PetscInt>    ii, jj;
  std::vector<PetscScalar> vv;
  for (const Entry &e : p.entries) ii.push_back(e.i), jj.push_back(e.j), vv.push_back(e.v);
  Mat A, R = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_OFF, 8, 4);
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, 3) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  REQUIRE(MatSetFromOptions(A) == 0);
  REQUIRE(MatSetPreallocationCOO(A, (PetscCount)ii.size(), ii.data(), jj.data()) == 0);
  REQUIRE(MatSetValuesCOO(A, vv.data(), INSERT_VALUES) == 0);
  CHECK(info_view(A).find("measured on block rows") != std::string::npos);
  check_same(A, R, p);
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("tuning: explicit settings win", "[tune]")
{
  Restore r;
  fresh_cache("tune_explicit");
  Opts          o(false);
  const Pattern p = fem_pattern(7, 7, 7, 3);
  {
    Mat A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 16, 0);
    CHECK(bin_width(A) == 16);
    const auto txt = info_view(A);
    CHECK(txt.find(" 16/1 ") != std::string::npos); // only the streams were timed
    CHECK(txt.find(" 4/") == std::string::npos);
    MatDestroy(&A);
  }
  {
    Mat A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 0, 2);
    CHECK(streams(A) == 2);
    CHECK(info_view(A).find("/1 ") == std::string::npos); // only the widths, at streams 2
    MatDestroy(&A);
  }
  {
    // the kernel set explicitly: kept, and only it is timed
    o.set("-mat_binbcsr_kernel", "portable");
    Mat              A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    MatBinBCSRKernel k;
    REQUIRE(MatBinBCSRGetKernel(A, &k) == 0);
    CHECK(k == MAT_BINBCSR_KERNEL_PORTABLE);
    CHECK(info_view(A).find("/avx") == std::string::npos);
    MatDestroy(&A);
  }
  {
    // width, streams and kernel set: only the prefetch distance is timed
    o.set("-mat_binbcsr_bin_width", "4");
    o.set("-mat_binbcsr_streams", "8");
    Mat A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    CHECK(bin_width(A) == 4);
    CHECK(streams(A) == 8);
    auto txt = info_view(A);
    CAPTURE(txt);
    CHECK(txt.find("nothing to tune") == std::string::npos);
    CHECK(txt.find(" 4/8/pf0 ") != std::string::npos);
    CHECK(txt.find(" 4/8/pf1024 ") != std::string::npos);
    CHECK(txt.find(" 8/") == std::string::npos);
    MatDestroy(&A);
    // and with the distance set too, nothing is
    o.set("-mat_binbcsr_prefetch", "1024");
    A           = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    PetscInt pf = -1;
    REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
    CHECK(pf == 1024);
    CHECK(info_view(A).find("nothing to tune") != std::string::npos);
    MatDestroy(&A);
  }
  {
    // only the distance set: kept, the rest tuned at it
    for (const char *n : {"-mat_binbcsr_bin_width", "-mat_binbcsr_streams", "-mat_binbcsr_kernel"})
      REQUIRE(PetscOptionsClearValue(nullptr, n) == 0);
    o.set("-mat_binbcsr_prefetch", "0");
    Mat      A  = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    PetscInt pf = -1;
    REQUIRE(MatBinBCSRGetPrefetch(A, &pf) == 0);
    CHECK(pf == 0);
    const auto txt = info_view(A);
    CHECK(txt.find("measured on block rows") != std::string::npos);
    CHECK(txt.find("/pf1024 ") == std::string::npos); // no other distance timed
    CHECK(txt.find("/pf4096 ") == std::string::npos);
    MatDestroy(&A);
  }
}

TEST_CASE("tuning: a precision change times the streams again, at the layout's width", "[tune]")
{
  Restore r;
  fresh_cache("tune_precision");
  Opts o(false);
  for (bool sym : {false, true}) {
    CAPTURE(sym);
    const Pattern  p  = sym_pattern(7, 3);
    Mat            A  = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, sym, MAT_BINBCSR_TUNE_AUTO);
    const PetscInt bw = bin_width(A);
    REQUIRE(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_SINGLE) == 0);
    const auto txt = info_view(A);
    CAPTURE(txt);
    CHECK(txt.find("after the precision change, at the layout's bin width: bin width " +
                   std::to_string(bw)) != std::string::npos);
    CHECK(bin_width(A) == bw);
    const PetscInt k = streams(A);
    CHECK((k == 1 || k == 2 || k == 4 || k == 8));
    Mat R = build_tuned(p, MAT_BINBCSR_PRECISION_SINGLE, sym, MAT_BINBCSR_TUNE_OFF, bw, k);
    check_same(A, R, p); // the values converted once, the products those of the fixed configuration
    MatDestroy(&R);
    MatDestroy(&A);
    // explicit streams, kernel and prefetch distance: nothing is timed again
    o.set("-mat_binbcsr_kernel", "portable");
    o.set("-mat_binbcsr_prefetch", "4096");
    A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, sym, MAT_BINBCSR_TUNE_AUTO, 0, 2);
    REQUIRE(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_SINGLE) == 0);
    CHECK(info_view(A).find("after the precision change") == std::string::npos);
    CHECK(streams(A) == 2);
    MatDestroy(&A);
    PetscOptionsClearValue(nullptr, "-mat_binbcsr_kernel");
  }
}

TEST_CASE("tuning: the first products decide the x load", "[tune][xload]")
{
  Restore   r;
  PetscBool avx512;
  REQUIRE(MatBinBCSRKernelAvailable(MAT_BINBCSR_KERNEL_AVX512, &avx512) == 0);
  if (!avx512) return; // the x load is read by the AVX-512 body only
  fresh_cache("tune_xload_trial");
  Opts o(false);
  o.set("-mat_binbcsr_kernel", "avx512");
  const Pattern p = fem_pattern(7, 7, 7, 3);
  Mat           A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 8);
  Mat           R = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_OFF, 8, 1);
  // every product of the trial, in either x load, is R's to the bit; its end is reported
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL + 1; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products: loads ") != std::string::npos);
  MatBinBCSRXLoad x;
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK((x == MAT_BINBCSR_XLOAD_LOADS || x == MAT_BINBCSR_XLOAD_GATHER));
  MatDestroy(&A);
  // a body that does not read the x load, set after the tuner's: its products do not count
  A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 8);
  check_same(A, R, p); // the trial's untimed first product, with the AVX-512 body
  REQUIRE(MatBinBCSRSetKernel(A, MAT_BINBCSR_KERNEL_PORTABLE) == 0);
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products") == std::string::npos);
  REQUIRE(MatBinBCSRSetKernel(A, MAT_BINBCSR_KERNEL_AVX512) == 0);
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL - 1; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products: loads ") != std::string::npos);
  MatDestroy(&A);
  // an x load set explicitly: no trial
  o.set("-mat_binbcsr_xload", "gather");
  A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO, 8);
  for (int k = 0; k < BINBCSR_XLOAD_TRIAL + 1; k++) check_same(A, R, p);
  CHECK(info_view(A).find("the first products") == std::string::npos);
  REQUIRE(MatBinBCSRGetXLoad(A, &x) == 0);
  CHECK(x == MAT_BINBCSR_XLOAD_GATHER);
  MatDestroy(&A);
  MatDestroy(&R);
}

TEST_CASE("tuning cache: round trip, corrupt files ignored", "[tune][cache]")
{
  Restore           r;
  const std::string file = fresh_cache("tune_cache");
  Opts              o(true);
  const Pattern     p = fem_pattern(7, 7, 7, 3);
  Mat               A = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
  CHECK(info_view(A).find("measured on block rows") != std::string::npos);
  std::string content;
  {
    std::ifstream in(file);
    REQUIRE(in.good());
    std::stringstream ss;
    ss << in.rdbuf();
    content = ss.str();
  }
  CHECK(content.rfind("# petscbinbcsr tune cache v5\n", 0) == 0);
  CHECK(content.find("bs 3 double whole") != std::string::npos);
#if defined(__x86_64__) || defined(__i386__)
  // the machine is named with CPUID's family and model: VMs of several CPU generations share a name
  CHECK(content.find(" (family ") != std::string::npos);
#endif
  // the second matrix of the class takes the choice from the file
  Mat B = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
  CHECK(info_view(B).find("from the cache") != std::string::npos);
  CHECK(bin_width(B) == bin_width(A));
  CHECK(streams(B) == streams(A));
  {
    PetscInt pa = -1, pb = -2;
    REQUIRE(MatBinBCSRGetPrefetch(A, &pa) == 0);
    REQUIRE(MatBinBCSRGetPrefetch(B, &pb) == 0);
    CHECK(pb == pa);
    CHECK((pa == 0 || pa == 1024 || pa == 4096));
  }
  MatDestroy(&B);
  // another class (single precision) is measured and added
  B = build_tuned(p, MAT_BINBCSR_PRECISION_SINGLE, false, MAT_BINBCSR_TUNE_AUTO);
  CHECK(info_view(B).find("measured on block rows") != std::string::npos);
  MatDestroy(&B);
  // -mat_binbcsr_tune_cache 0: neither read nor written
  o.set("-mat_binbcsr_tune_cache", "0");
  B = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
  CHECK(info_view(B).find("measured on block rows") != std::string::npos);
  MatDestroy(&B);
  o.set("-mat_binbcsr_tune_cache", "1");

  // corrupt files: garbage, a bad choice, a choice the block size cannot take, an empty file; and a
  // well-formed file of an older tuner version, whose choices must not be taken either
  const std::string key =
    content.substr(content.find('\n') + 1, content.rfind('\t') - content.find('\n') - 1);
  for (const std::string bad :
       {std::string("garbage\n\x01\x02"), std::string("# petscbinbcsr tune cache v5\n") + key + "\t7 3\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t32 1\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\tx\n", std::string(""),
        // the prefetch distance: missing (a v3 line under a v5 header), negative, not a multiple of 64,
        // too far
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable -64 loads\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable 100 loads\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable 131072 loads\n",
        // the x load: missing (a v4 line under a v5 header), unknown, one token too many
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable 0\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable 0 scatter\n",
        std::string("# petscbinbcsr tune cache v5\n") + key + "\t16 1 portable 0 gather 1\n",
        // a well-formed v4 file: another version, measured again
        std::string("# petscbinbcsr tune cache v4\n") + key + "\t16 1 portable 0\n",
        std::string("# petscbinbcsr tune cache v3\n") + key + "\t16 1 portable\n",
        std::string("# petscbinbcsr tune cache v1\n") + key + "\t16 1 auto\n",
        std::string("# petscbinbcsr tune cache v2\n") + key + "\t16 1 auto\n"}) {
    CAPTURE(bad);
    {
      std::ofstream out(file, std::ios::trunc);
      out << bad;
    }
    Mat C = nullptr;
    C     = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    CHECK(info_view(C).find("measured on block rows") != std::string::npos);
    const PetscInt bw = bin_width(C);
    CHECK((bw == 4 || bw == 8 || bw == 16));
    check_same(C, A, p);
    MatDestroy(&C);
    std::ifstream in(file); // rewritten, valid
    std::string   first;
    std::getline(in, first);
    CHECK(first == "# petscbinbcsr tune cache v5");
  }
  // this machine's entries written by a library with other kernels (another kernel id), or by one from
  // before the id was in the key: not taken (measured again), and dropped by the store that follows
  const size_t kid = key.find(" | kernels ");
  REQUIRE(kid != std::string::npos);
  const size_t      tab      = key.find('\t');
  const std::string other_id = key.substr(0, kid) + " | kernels 000000000000" + key.substr(tab);
  const std::string no_id    = key.substr(0, kid) + key.substr(tab);
  for (const std::string &stale : {other_id, no_id}) {
    CAPTURE(stale);
    {
      std::ofstream out(file, std::ios::trunc);
      out
        << "# petscbinbcsr tune cache v5\n"
        << stale << "\t16 1 portable 0 loads\n"
        << "Another CPU (family 1 model 2) | 64 cores | avx2 | kernels 000000000000\tbs 3 double whole size "
           "2^20 rowlen 2^4 spread 0\t16 2 portable 1024 gather\n";
    }
    Mat C = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    CHECK(info_view(C).find("measured on block rows") != std::string::npos);
    check_same(C, A, p);
    MatDestroy(&C);
    std::ifstream     in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    CHECK(ss.str().find(stale + "\t") == std::string::npos);  // dropped
    CHECK(ss.str().find(key + "\t") != std::string::npos);    // the new choice
    CHECK(ss.str().find("Another CPU") != std::string::npos); // other machines' entries kept
  }
  // the cache's path taken by a folder: read as no file, measured, the folder left alone
  REQUIRE(std::remove(file.c_str()) == 0);
  REQUIRE(mkdir(file.c_str(), 0755) == 0);
  {
    Mat C = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    CHECK(info_view(C).find("measured on block rows") != std::string::npos);
    check_same(C, A, p);
    MatDestroy(&C);
    struct stat st;
    REQUIRE(stat(file.c_str(), &st) == 0);
    CHECK(S_ISDIR(st.st_mode));
    REQUIRE(rmdir(file.c_str()) == 0);
  }
  // a FIFO (an open for reading would wait for a writer), a link to an endless device, a regular file
  // far larger than a cache: measured, never blocking or reading without end, and left alone. The
  // alarm turns a hang into a failure of this test.
  for (const std::string kind : {"fifo", "device", "large"}) {
    CAPTURE(kind);
    if (kind == "fifo") REQUIRE(mkfifo(file.c_str(), 0644) == 0);
    else if (kind == "device") REQUIRE(symlink("/dev/zero", file.c_str()) == 0);
    else {
      std::ofstream out(file, std::ios::trunc);
      out << "# petscbinbcsr tune cache v5\n" << std::string(2 << 20, '#') << "\n";
    }
    alarm(120);
    Mat C = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
    alarm(0);
    CHECK(info_view(C).find("measured on block rows") != std::string::npos);
    check_same(C, A, p);
    MatDestroy(&C);
    struct stat st;
    REQUIRE(lstat(file.c_str(), &st) == 0);
    CHECK((kind == "fifo"     ? S_ISFIFO(st.st_mode)
           : kind == "device" ? S_ISLNK(st.st_mode)
                              : S_ISREG(st.st_mode)));
    if (kind == "large") CHECK(st.st_size > (1 << 20));
    REQUIRE(std::remove(file.c_str()) == 0);
  }
  // an unreadable cache folder: no file written, no error
  setenv("XDG_CACHE_HOME", "/proc/no/such/folder", 1);
  Mat C = build_tuned(p, MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
  CHECK(info_view(C).find("measured on block rows") != std::string::npos);
  MatDestroy(&C);
  MatDestroy(&A);
}

TEST_CASE("tuning: bad values give clear errors", "[tune]")
{
  Restore r;
  fresh_cache("tune_bad");
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, 6, 6, 6, 6) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  CHECK(MatBinBCSRSetTune(A, (MatBinBCSRTune)7) == PETSC_ERR_ARG_OUTOFRANGE);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune", "sometimes") == 0);
  CHECK(MatSetFromOptions(A) != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune") == 0);
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune_cache", "perhaps") == 0);
  CHECK(MatSetFromOptions(A) != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune_cache") == 0);
  MatBinBCSRTune t;
  REQUIRE(MatBinBCSRGetTune(A, &t) == 0);
  CHECK(t == MAT_BINBCSR_TUNE_AUTO); // the default
  MatDestroy(&A);
  // read at the layout build when MatSetFromOptions was not called
  const Pattern p = fem_pattern(4, 4, 4, 3);
  // an empty assembly of p's sizes: where the layout build reads the options
  auto assemble = [&]() {
    Mat B;
    REQUIRE(MatCreate(PETSC_COMM_SELF, &B) == 0);
    REQUIRE(MatSetSizes(B, p.m, p.n, p.m, p.n) == 0);
    REQUIRE(MatSetBlockSize(B, 3) == 0);
    REQUIRE(MatSetType(B, MATSEQBINBCSR) == 0);
    REQUIRE(MatSetUp(B) == 0);
    REQUIRE(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY) == 0);
    const PetscErrorCode ierr = MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY);
    MatDestroy(&B);
    return ierr;
  };
  REQUIRE(PetscOptionsSetValue(nullptr, "-mat_binbcsr_tune", "never") == 0);
  CHECK(assemble() != 0);
  REQUIRE(PetscOptionsClearValue(nullptr, "-mat_binbcsr_tune") == 0);
  // the benchmark knobs: sizes and budgets must be positive
  for (const char *knob : {"-mat_binbcsr_tune_sample_mib", "-mat_binbcsr_tune_budget_ms"}) {
    CAPTURE(knob);
    Opts o(false);
    o.set(knob, "0");
    CHECK(assemble() == PETSC_ERR_ARG_OUTOFRANGE);
  }
  // other types: no-ops
  REQUIRE(MatCreateSeqAIJ(PETSC_COMM_SELF, 4, 4, 1, nullptr, &A) == 0);
  CHECK(MatBinBCSRSetTune(A, MAT_BINBCSR_TUNE_AUTO) == 0);
  REQUIRE(MatBinBCSRGetTune(A, &t) == 0);
  CHECK(t == MAT_BINBCSR_TUNE_OFF);
  MatDestroy(&A);
}

// Run by tests/tune.cmake as several processes at once on one cache folder (hidden from the plain
// run): each tunes matrices of several classes with the cache on, so they rewrite the file together.
TEST_CASE("tuning cache writer", "[.cache_writer]")
{
  Opts o(true);
  for (int round = 0; round < 3; round++)
    for (PetscInt n : {4, 5, 6, 7})
      for (auto prec : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE}) {
        Mat A = build_tuned(fem_pattern(n, n, n + round, 3), prec, false, MAT_BINBCSR_TUNE_AUTO);
        MatDestroy(&A);
      }
}

// ... and then this one checks the file they left: the header and only well-formed lines.
TEST_CASE("tuning cache check", "[.cache_check]")
{
  const char   *x = getenv("XDG_CACHE_HOME");
  std::ifstream in(std::string(x ? x : "") + "/petscbinbcsr/tune.txt");
  REQUIRE(in.good());
  std::string line;
  std::getline(in, line);
  CHECK(line == "# petscbinbcsr tune cache v5");
  int n = 0;
  while (std::getline(in, line)) {
    CAPTURE(line);
    const size_t t1 = line.find('\t'), t2 = line.find('\t', t1 + 1);
    REQUIRE(t2 != std::string::npos);
    int  bw = 0, k = 0, pf = -1;
    char body[32], xload[32] = "";
    CHECK(sscanf(line.c_str() + t2 + 1, "%d %d %31s %d %31s", &bw, &k, body, &pf, xload) == 5);
    CHECK((std::string(xload) == "loads" || std::string(xload) == "gather"));
    CHECK((bw == 4 || bw == 8 || bw == 16));
    CHECK((k == 1 || k == 2 || k == 4 || k == 8));
    CHECK((pf == 0 || pf == 1024 || pf == 4096));
    n++;
  }
  CHECK(n >= 1);
  // the next process reads it without warning and takes the choice
  Opts o(true);
  Mat  A = build_tuned(fem_pattern(7, 7, 7, 3), MAT_BINBCSR_PRECISION_DOUBLE, false, MAT_BINBCSR_TUNE_AUTO);
  CHECK(info_view(A).find("tuning (-mat_binbcsr_tune): bin width") != std::string::npos);
  MatDestroy(&A);
}
