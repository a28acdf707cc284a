// MatBinBCSRSetStreams: the product sweeps runs of bins side by side. Each lane's sum is the same
// sequence of products for any number of runs, so every product must equal the one-run product up
// to the rounding of the double sums (the compiler may contract multiply-adds into FMAs differently in
// each instantiation: with GCC 12 the hand-written AVX-512 body agrees bit for bit, the portable one at
// bs 3 / bin width 4 in the last bits). Used by unit_mat_core (whole storage) and unit_mat_sym.
#pragma once
#include "support/mat_support.hpp"

namespace mat_core {

struct Products {
  std::vector<PetscScalar> mult, mult_add, mult_add_in_place, mult_dot;
  PetscScalar              dot = 0;
};

inline Products products(Mat A, const Pattern &p)
{
  Products out;
  Vec      x = make_vec(p.n, 1), z = make_vec(p.m, 2), y;
  REQUIRE(VecDuplicate(z, &y) == 0);
  REQUIRE(MatMult(A, x, y) == 0);
  out.mult = values(y);
  REQUIRE(MatMultAdd(A, x, z, y) == 0);
  out.mult_add = values(y);
  REQUIRE(VecCopy(z, y) == 0);
  REQUIRE(MatMultAdd(A, x, y, y) == 0);
  out.mult_add_in_place = values(y);
  if (p.m == p.n) {
    REQUIRE(MatMultDotLocal(A, x, y, &out.dot) == 0);
    out.mult_dot = values(y);
  }
  VecDestroy(&x);
  VecDestroy(&z);
  VecDestroy(&y);
  return out;
}

// A: a MATSEQBINBCSR matrix of the pattern p (whole or symmetric storage). Changes A's streams.
inline void check_streams(Mat A, const Pattern &p)
{
  REQUIRE(MatBinBCSRSetStreams(A, 1) == 0);
  const Products one = products(A, p);
  Vec            x   = make_vec(p.n, 1); // the x of products()
  const auto     xv  = values(x);
  /* the stored values are the same for every run count (single storage too): double rounding only */
  const auto bound = mult_bound(p, xv, 0.0, false);
  VecDestroy(&x);
  for (PetscInt streams : {2, 4, 8}) {
    CAPTURE(streams);
    REQUIRE(MatBinBCSRSetStreams(A, streams) == 0);
    const Products got = products(A, p);
    check_close(got.mult, one.mult, bound);
    check_close(got.mult_add, one.mult_add, bound);
    check_close(got.mult_add_in_place, one.mult_add_in_place, bound);
    if (p.m == p.n) {
      check_close(got.mult_dot, one.mult_dot, bound);
      double dbound = 0;
      for (size_t i = 0; i < xv.size(); i++)
        dbound += std::fabs(xv[i]) * (bound[i] + 64 * DBL_EPSILON * std::fabs(one.mult_dot[i]));
      CHECK(std::fabs(got.dot - one.dot) <= dbound);
    }
  }
}

// Every product of got the same bits as want's.
inline void check_same_bits(const Products &got, const Products &want)
{
  CHECK(got.mult == want.mult);
  CHECK(got.mult_add == want.mult_add);
  CHECK(got.mult_add_in_place == want.mult_add_in_place);
  CHECK(got.mult_dot == want.mult_dot);
  CHECK(got.dot == want.dot);
}

// MatBinBCSRSetPrefetch: a software prefetch changes no arithmetic, so every distance must give the
// same bits as no prefetch, at every stream count (a distance past the end of the values prefetches
// addresses that are never read: harmless, and checked here with the largest one). Changes A's
// streams and prefetch distance.
inline void check_prefetch(Mat A, const Pattern &p)
{
  for (PetscInt streams : {1, 4}) {
    CAPTURE(streams);
    REQUIRE(MatBinBCSRSetStreams(A, streams) == 0);
    REQUIRE(MatBinBCSRSetPrefetch(A, 0) == 0);
    const Products none = products(A, p);
    for (PetscInt pf : {64, 1024, 4096, 65536}) {
      CAPTURE(pf);
      REQUIRE(MatBinBCSRSetPrefetch(A, pf) == 0);
      check_same_bits(products(A, p), none);
    }
  }
}

// Gathering x in every slot group reads the same x_c as loading it where the bins allow: the same
// products to the bit (the setting only matters for 3x3 blocks at width 8 with the AVX-512 body).
inline void check_xload(Mat A, const Pattern &p)
{
  for (PetscInt streams : {1, 4}) {
    CAPTURE(streams);
    REQUIRE(MatBinBCSRSetStreams(A, streams) == 0);
    REQUIRE(MatBinBCSRSetXLoad(A, MAT_BINBCSR_XLOAD_LOADS) == 0);
    const Products loads = products(A, p);
    REQUIRE(MatBinBCSRSetXLoad(A, MAT_BINBCSR_XLOAD_GATHER) == 0);
    check_same_bits(products(A, p), loads);
    REQUIRE(MatBinBCSRSetXLoad(A, MAT_BINBCSR_XLOAD_LOADS) == 0); // and back
    check_same_bits(products(A, p), loads);
  }
}

} // namespace mat_core
