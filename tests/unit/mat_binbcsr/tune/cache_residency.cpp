// The tuner's measured cache residency (binbcsr::stays_in_cache): what it answers depends on the
// machine, so the cases hold it to what must be true anywhere: nothing beyond the claimed cache stays,
// the answers are monotone in the size and kept for the process, and the search ends at the first size
// that misses.
#include <catch2/catch.hpp>

#include "mat_binbcsr/common/binbcsr_machine.h"

#include <chrono>

TEST_CASE("cache residency: bounded by the claim, monotone, kept", "[tune][residency]")
{
  const size_t MiB = (size_t)1 << 20;
  // beyond the limit: not resident, and nothing measured (no 1 TiB allocation)
  CHECK_FALSE(binbcsr::stays_in_cache((size_t)1 << 40, (size_t)64 << 20));
  CHECK_FALSE(binbcsr::stays_in_cache(65 * MiB, 64 * MiB));

  // up to 64 MiB: once a size misses, every larger one does
  bool sizes[7];
  for (int k = 0; k < 7; k++) sizes[k] = binbcsr::stays_in_cache((MiB << k) - 4096, 64 * MiB);
  for (int k = 1; k < 7; k++)
    if (!sizes[k - 1]) CHECK_FALSE(sizes[k]);
  // asked again: the same answers, from what the process keeps (no passes: well under a pass over
  // 64 MiB, which takes milliseconds)
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < 7; k++) CHECK(binbcsr::stays_in_cache((MiB << k) - 4096, 64 * MiB) == sizes[k]);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(seconds < 1e-3);
}
