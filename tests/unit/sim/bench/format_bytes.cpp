// The bytes model spmv_bench's GB/s and %read columns come from (src/sim/format_bytes.h), checked on
// a stencil whose blocks can be counted by hand: the 27-point stencil on an nx x ny x nz node grid
// has (3 nx - 2)(3 ny - 2)(3 nz - 2) blocks, a row of 8 to 27 of them.
#include <catch2/catch.hpp>
#include <petscbinbcsr.h>

#include "sim/format_bytes.h"
#include "sim/stencil.h"

TEST_CASE("the formats' bytes model counts what each one stores", "[bench][bytes]")
{
  StencilGrid g;
  g.nx = 3, g.ny = 4, g.nz = 5; // 60 nodes, 180 rows
  Mat A = nullptr;
  REQUIRE(CreateStencilMatrix(PETSC_COMM_SELF, g, MATAIJ, nullptr, &A) == 0);
  MatrixStats st;
  REQUIRE(MeasureStats(A, &st) == 0);
  const double blocks = 7.0 * 10 * 13, rows = 180, vec = 16 * rows;
  CHECK(st.rows == 180);
  CHECK(st.bs == 3);
  CHECK(st.blocks == blocks);
  CHECK(st.nnz == 9 * blocks);
  CHECK(st.upper_blocks == (blocks + 60) / 2); // the diagonal blocks and half of the others
  CHECK(st.max_row == 27 * 3);
  CHECK(st.min_row == 8 * 3);
  REQUIRE(st.block_row_len.size() == 60);

  double         pad  = 0;
  const MPI_Comm self = PETSC_COMM_SELF;
  CHECK(FormatModelBytes("aij", false, false, 0, A, st, self, &pad) ==
        9 * blocks * 12 + 4 * (rows + 1) + vec);
  CHECK(pad == -1);
  CHECK(FormatModelBytes("baij", false, false, 0, A, st, self, &pad) == blocks * 76 + 4 * 61 + vec);
  CHECK(FormatModelBytes("sbaij", false, false, 0, A, st, self, &pad) == st.upper_blocks * 76 + 4 * 61 + vec);
  // bin width 1: no padding, a bin per block row; single storage stores 4-byte values
  CHECK(FormatModelBytes("binbcsr", false, false, 1, A, st, self, &pad) == blocks * 76 + 4 * 61 + vec);
  CHECK(pad == 0);
  CHECK(FormatModelBytes("binbcsr", true, false, 1, A, st, self, &pad) == blocks * 40 + 4 * 61 + vec);
  // one bin of 64 lanes (60 rows and 4 phantom lanes), each padded to the longest row, 27 blocks
  CHECK(FormatModelBytes("binbcsr", false, false, 64, A, st, self, &pad) == 27 * 64 * 76.0 + 4 * 2 + vec);
  CHECK(pad == Approx(100 * (27 * 64 - blocks) / blocks));
  CHECK(FormatModelBytes("dense", false, false, 1, A, st, self, &pad) == 0); // not modelled
  MatDestroy(&A);
}
