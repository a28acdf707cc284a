/* Test harness of the device library's tests: Catch2 where its header is installed (CI), otherwise
   a minimal stand-in with the same macros (a GPU machine with CUDA but nothing else,
   scripts/gpu_check). The executor under test: BINBCSR_DEVICE_EXECUTOR (reference by default);
   every result is checked against plain CSR arithmetic and, for cuda, against the reference executor. */
#pragma once
#if __has_include(<catch2/catch.hpp>) && !defined(BINBCSR_MINI_CATCH)
  #include <catch2/catch.hpp>
#else
  #include <cstdio>
  #include <functional>
  #include <string>
  #include <vector>
namespace mini_catch {
struct Case {
  const char           *name;
  std::function<void()> fn;
};
inline std::vector<Case> &cases()
{
  static std::vector<Case> c;
  return c;
}
struct Add {
  Add(const char *n, std::function<void()> f) { cases().push_back({n, f}); }
};
struct Failure {};
inline int &checks_failed()
{
  static int n = 0;
  return n;
}
inline void report(const char *expr, const char *file, int line)
{
  std::printf("%s:%d: FAILED: %s\n", file, line, expr), checks_failed()++;
}
} // namespace mini_catch
  #define MC_CAT2(a, b) a##b
  #define MC_CAT(a, b)  MC_CAT2(a, b)
  #define TEST_CASE(name, tags)                                                         \
    static void            MC_CAT(mc_test_, __LINE__)();                                \
    static mini_catch::Add MC_CAT(mc_add_, __LINE__)(name, MC_CAT(mc_test_, __LINE__)); \
    static void            MC_CAT(mc_test_, __LINE__)()
  #define CHECK(e)                                          \
    do {                                                    \
      if (!(e)) mini_catch::report(#e, __FILE__, __LINE__); \
    } while (0)
  #define REQUIRE(e)                                \
    do {                                            \
      if (!(e)) {                                   \
        mini_catch::report(#e, __FILE__, __LINE__); \
        throw mini_catch::Failure{};                \
      }                                             \
    } while (0)
  #define INFO(x) (void)0
#endif
