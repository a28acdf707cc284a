// MatSetPreallocationCOO of a list made of whole blocks (bs^2 consecutive entries, one block row-major,
// every index valid: what the simulation drivers list) takes a path that sorts blocks instead of
// entries. Its maps must be the ones the general path makes for the same list: the same matrix, to
// the bit, for every refill (the entries summed in the same order), by blocks and value by value,
// with the COO mirror and symmetric storage, in double and single. The general path is forced by
// appending one dropped entry (negative row), which no list of whole blocks has.
#include "support/mat_support.hpp"

#include <random>

using namespace mat_core;

namespace {

struct BlockList {
  std::vector<PetscInt> i, j;
};

// nblocks blocks of a bs x bs-block matrix of m block rows: near the diagonal, some repeated, diagonal
// blocks among them, in both triangles (the upper one only where `upper`).
BlockList block_list(PetscInt m, PetscInt bs, int nblocks, bool upper, unsigned seed)
{
  std::mt19937 gen(seed);
  BlockList    l;
  for (int t = 0; t < nblocks; ++t) {
    PetscInt I = (PetscInt)(gen() % m), J = (I + (PetscInt)(gen() % 9) - 4 + m) % m;
    if (t % 5 == 0) J = I;
    if (t % 7 == 3 && t > 0) { // a block listed again
      I = l.i[(size_t)bs * bs * (gen() % t)] / bs;
      J = l.j[(size_t)bs * bs * (gen() % t)] / bs;
    }
    if (upper && I > J) std::swap(I, J);
    for (PetscInt r = 0; r < bs; ++r)
      for (PetscInt c = 0; c < bs; ++c) {
        l.i.push_back(I * bs + r);
        l.j.push_back(J * bs + c);
      }
  }
  return l;
}

Mat coo_matrix(PetscInt n, PetscInt bs, bool mirror, bool sym, MatBinBCSRPrecision prec, BlockList l,
               bool general)
{
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, n, n, n, n) == 0);
  REQUIRE(MatSetBlockSize(A, bs) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  REQUIRE(MatBinBCSRSetCOOMirror(A, mirror ? PETSC_TRUE : PETSC_FALSE) == 0);
  REQUIRE(MatBinBCSRSetSymmetricStorage(A, sym ? PETSC_TRUE : PETSC_FALSE) == 0);
  REQUIRE(MatBinBCSRSetPrecision(A, prec) == 0);
  if (general) { // one dropped entry: not a list of whole blocks
    l.i.push_back(-1);
    l.j.push_back(0);
  }
  REQUIRE(MatSetPreallocationCOO(A, (PetscCount)l.i.size(), l.i.data(), l.j.data()) == 0);
  return A;
}

} // namespace

TEST_CASE("COO of whole blocks: the general path's matrix, to the bit", "[mat_core][coo]")
{
  const PetscInt            bs     = GENERATE(2, 3);
  const bool                mirror = GENERATE(false, true);
  const bool                sym    = GENERATE(false, true);
  const MatBinBCSRPrecision prec   = GENERATE(MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE);
  CAPTURE(bs, mirror, sym, prec);
  const PetscInt                         m = 37, n = m * bs;
  const BlockList                        l    = block_list(m, bs, 260, mirror || sym, 11u + (unsigned)bs);
  Mat                                    fast = coo_matrix(n, bs, mirror, sym, prec, l, false);
  Mat                                    slow = coo_matrix(n, bs, mirror, sym, prec, l, true);
  std::mt19937                           gen(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (InsertMode mode : {INSERT_VALUES, ADD_VALUES, INSERT_VALUES}) {
    std::vector<PetscScalar> v(l.i.size() + 1);
    for (PetscScalar &x : v) x = u(gen);
    REQUIRE(MatSetValuesCOO(fast, v.data(), mode) == 0);
    REQUIRE(MatSetValuesCOO(slow, v.data(), mode) == 0); // (its last value, the dropped entry's, unread)
    check_dense(dense(fast), dense(slow), 0);
  }
  // both refill by whole blocks
  CHECK(info_view(fast).find("by whole blocks") != std::string::npos);
  CHECK(info_view(slow).find("by whole blocks") != std::string::npos);
  MatDestroy(&fast);
  MatDestroy(&slow);
}

TEST_CASE("COO of whole blocks: a block out of range is the general path's error", "[mat_core][coo]")
{
  BlockList l = block_list(5, 3, 10, false, 3u);
  l.i[9 * 4]  = 15; // block 4's first entry: row 15 of a 15-row matrix
  Mat A;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, 15, 15, 15, 15) == 0);
  REQUIRE(MatSetBlockSize(A, 3) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  CHECK(MatSetPreallocationCOO(A, (PetscCount)l.i.size(), l.i.data(), l.j.data()) ==
        PETSC_ERR_ARG_OUTOFRANGE);
  PetscPopErrorHandler();
  MatDestroy(&A);
}
