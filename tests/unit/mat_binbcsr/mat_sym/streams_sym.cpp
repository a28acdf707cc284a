// MatBinBCSRSetStreams on symmetric storage (mat_core/streams_check.h says what is checked): the bins of
// one sweep scatter into each other's rows, and with several runs the fused dot is a pass of its own.
// Patterns: a random symmetric one whose bins are no multiple of the runs, the ragged end rows whose
// last bins have more slot groups than rows, a stencil with unit-stride groups, bs 1 and 3, bin widths
// 4-32, both precisions.
#include "support/streams_check.hpp"
#include "support_sym.hpp"

using namespace mat_sym;

TEST_CASE("symmetric storage: every streams count gives the one-run product up to rounding",
          "[mat_sym][mult][streams]")
{
  const PetscInt            bs   = GENERATE(1, 3);
  const PetscInt            bw   = GENERATE(4, 8, 16, 32);
  const MatBinBCSRPrecision prec = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, bw, prec);
  const Pattern patterns[] = {
    symmetrize(random_pattern(301, 301, bs, 9, 17 + bs)),
    end_rows_pattern(203, bs),
    symmetrize(fem_pattern(49, 3, 2, bs)),
  };
  for (const Pattern &p : patterns) {
    Mat A = build_sym(p, bw, prec);
    check_streams(A, p);
    check_prefetch(A, p);
    MatDestroy(&A);
  }
}
