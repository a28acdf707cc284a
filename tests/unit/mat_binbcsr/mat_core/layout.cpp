// The layout rule of src/mat_binbcsr/kernels/binbcsr_layout.h (the CPU Mat and the CUDA benchmark both build
// their bins with it) on the worked example of seq/binbcsr.h, docs/mat_binbcsr.md and the README, and
// the value index of 3x3 tiles.
#include "mat_binbcsr/kernels/binbcsr_layout.h"

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

TEST_CASE("x_c by loads: the slot groups that pass and the bins' hint", "[layout]")
{
  // groups of 8 lanes (the AVX-512 body's width), 100 block columns
  const unsigned all     = 0xff;
  const int      unit[8] = {10, 11, 12, 13, 14, 15, 16, 17}, two_off[8] = {3, 11, 12, 13, 14, 15, 40, 17},
            three_off[8] = {3, 11, 12, 13, 14, 15, 40, 41}, tail_run[8] = {0, 0, 0, 13, 14, 15, 16, 17},
            past_end[8] = {93, 94, 95, 96, 97, 98, 99, 100}, scattered[8] = {5, 40, 2, 77, 13, 60, 31, 8};
  CHECK(binbcsr::near_unit_group<int>(unit, all, 8, 100));
  CHECK(binbcsr::near_unit_group<int>(two_off, all, 8, 100)); // two odd lanes, the run from the last
  CHECK_FALSE(binbcsr::near_unit_group<int>(three_off, all, 8, 100));
  CHECK_FALSE(binbcsr::near_unit_group<int>(tail_run, all, 8, 100)); // three lanes off either run
  CHECK(binbcsr::near_unit_group<int>(tail_run, 0xf8, 8, 100));      // lanes 0-2 padding: the run from lane 3
  CHECK_FALSE(binbcsr::near_unit_group<int>(past_end, all, 8, 100)); // the run leaves x
  CHECK(binbcsr::near_unit_group<int>(past_end, all, 8, 101));
  CHECK_FALSE(binbcsr::near_unit_group<int>(scattered, all, 8, 100));
  CHECK_FALSE(binbcsr::near_unit_group<int>(unit, 0u, 8, 100)); // no real lane: nothing to load

  // two bins of 8 rows, 4 groups each: bin 0 three unit groups and one scattered (hint 1), bin 1 one
  // unit group and three scattered (hint 0); then 12 rows, bin 1 with 4 phantom lanes, whose columns
  // (here 0) are not looked at: its groups 1 and 2 hold a run in lanes 0-3 (hint 1)
  std::vector<int> bin_start = {0, 32, 64}, col(64), row_nz(16, 4);
  for (int k = 0; k < 4; k++)
    for (int l = 0; l < 8; l++) {
      col[k * 8 + l]      = k < 3 ? 10 * k + l : scattered[l];
      col[32 + k * 8 + l] = k == 0 ? 50 + l : scattered[(l + k) % 8];
    }
  unsigned char hint[2] = {7, 7};
  binbcsr::xload_bins<int>(bin_start.data(), col.data(), row_nz.data(), 16, 2, 8, 100, hint);
  CHECK(hint[0] == 1);
  CHECK(hint[1] == 0);
  for (int k = 1; k < 3; k++)
    for (int l = 0; l < 8; l++) col[32 + k * 8 + l] = l < 4 ? 60 + l : 0;
  binbcsr::xload_bins<int>(bin_start.data(), col.data(), row_nz.data(), 12, 2, 8, 100, hint);
  CHECK(hint[0] == 1);
  CHECK(hint[1] == 1);
}
