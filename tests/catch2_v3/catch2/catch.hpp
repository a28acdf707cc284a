// Catch2 3 (Debian 13) has no single header catch2/catch.hpp: this one, on the include path only when
// CMake finds Catch2 3, gives the tests the names they use from Catch2 2 (Debian 12), so the test
// sources are written once.
#pragma once
#include <catch2/catch_all.hpp>
#include <string>

using Catch::Approx;

namespace Catch {
// Catch2 2's string matcher Catch::Contains is Catch::Matchers::ContainsSubstring in Catch2 3.
inline Matchers::StringContainsMatcher Contains(const std::string &s, CaseSensitive cs = CaseSensitive::Yes)
{
  return Matchers::ContainsSubstring(s, cs);
}
} // namespace Catch
