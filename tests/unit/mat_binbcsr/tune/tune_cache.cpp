// The layout tuner's cache file: choices round trip, a corrupt, foreign, oversized or unreadable file
// is ignored with a warning and never changes a layout, and processes writing it at once leave a
// well-formed file (tests/tune.cmake runs the hidden writer and check cases).
#include "tune_support.hpp"
#include "mat_binbcsr/seq/binbcsr.h" // BINBCSR_XLOAD_TRIAL
#include <petscviewer.h>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

using namespace mat_core;

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
