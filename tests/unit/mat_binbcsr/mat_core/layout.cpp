// The layout rule of src/mat_binbcsr/binbcsr_layout.h (the CPU Mat and the CUDA benchmark both build
// their bins with it) on the worked example of seq/binbcsr.h, docs/mat_binbcsr.md and the README, and
// the value index of 3x3 tiles.
#include "mat_binbcsr/binbcsr_layout.h"

#include <catch2/catch.hpp>
#include <vector>

TEST_CASE("layout rule: the documented 5x5 example, bin width 2", "[layout]")
{
  // [ a . b . . ] / [ . c . . . ] / [ d . e f . ] / [ . . . h . ] / [ . . . . i ]
  const std::vector<int> ptr = {0, 2, 3, 6, 7, 8}, cols = {0, 2, 1, 0, 2, 3, 3, 4};
  std::vector<int>       bin_start(4, -7), diag(5, -7);
  const long             nslots = binbcsr::bin_starts<int>(ptr.data(), 5, 2, bin_start.data());
  CHECK(nslots == 12);
  CHECK(bin_start == std::vector<int>{0, 4, 10, 12});
  std::vector<int> col(nslots, -7);
  binbcsr::bin_columns<int>(ptr.data(), cols.data(), 5, 2, bin_start.data(), col.data(), diag.data());
  // padding repeats the lane's last column; the phantom lane (slot 11) reads column 0
  CHECK(col == std::vector<int>{0, 1, 2, 1, 0, 3, 2, 3, 3, 3, 4, 0});
  CHECK(diag == std::vector<int>{0, 1, 6, 5, 10});
  // entry k of row r is slot bin_start[r / bw] + k bw + r % bw: f (row 2, entry 2) at 4 + 4 = 8, h (row 3, entry 0) at 5
  CHECK(binbcsr::row_slot<int>(bin_start.data(), 2, 2, 2) == 8);
  CHECK(binbcsr::row_slot<int>(bin_start.data(), 2, 3, 0) == 5);
  CHECK(binbcsr::row_slot<int>(bin_start.data(), 2, 4, 0) == 10);
}

TEST_CASE("layout rule: a diagonal-free row and an empty row", "[layout]")
{
  // row 0 empty, row 1 = columns {0}, bw 4: one bin of 4 lanes (2 phantom), longest row 1
  const std::vector<int> ptr = {0, 0, 1}, cols = {0};
  std::vector<int>       bin_start(2), diag(2, -7);
  CHECK(binbcsr::bin_starts<int>(ptr.data(), 2, 4, bin_start.data()) == 4);
  std::vector<int> col(4, -7);
  binbcsr::bin_columns<int>(ptr.data(), cols.data(), 2, 4, bin_start.data(), col.data(), diag.data());
  CHECK(col == std::vector<int>{0, 0, 0, 0});
  CHECK(diag == std::vector<int>{-1, -1});
}

TEST_CASE("layout rule: value index of 3x3 tiles", "[layout]")
{
  // entry e of slot s in lane l = s % bw at (s - l) * 9 + e * bw + l: for fixed k and e the lanes are contiguous
  const int bw = 8, bs2 = 9;
  CHECK(binbcsr::value_index(0, 0, bw, bs2) == 0);
  CHECK(binbcsr::value_index(3, 0, bw, bs2) == 3);
  CHECK(binbcsr::value_index(3, 1, bw, bs2) == 8 + 3);
  CHECK(binbcsr::value_index(8 + 3, 4, bw, bs2) == 72 + 32 + 3);
  CHECK(binbcsr::value_index(8 + 7, 8, bw, bs2) == 72 + 64 + 7);
  CHECK(binbcsr::value_index(16, 0, bw, bs2) == 144);
}
