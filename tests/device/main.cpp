/* main of the device library's tests (tests/device/device_test.h says which harness). */
#if __has_include(<catch2/catch.hpp>) && !defined(BINBCSR_MINI_CATCH)
  #define CATCH_CONFIG_MAIN
  #include <catch2/catch.hpp>
#else
  #include "device_test.h"
  #include <exception>
int main()
{
  int failed_cases = 0;
  for (auto &c : mini_catch::cases()) {
    const int before = mini_catch::checks_failed();
    bool      thrown = false;
    try {
      c.fn();
    } catch (const mini_catch::Failure &) {
      thrown = true;
    } catch (const std::exception &e) {
      std::printf("%s: exception: %s\n", c.name, e.what());
      thrown = true;
    }
    const bool ok = !thrown && mini_catch::checks_failed() == before;
    failed_cases += !ok;
    std::printf("%s %s\n", ok ? "passed" : "FAILED", c.name);
  }
  std::printf("%zu test cases, %d failed\n", mini_catch::cases().size(), failed_cases);
  return failed_cases ? 1 : 0;
}
#endif
