// Fixtures of the row/column operation tests: one matrix defined entry by entry by a formula, built on
// PETSC_COMM_WORLD as -mat_type binbcsr (seq on one rank, mpi on more) and as aij from the same entries,
// and comparisons of the two (collective, any communicator size).
#pragma once

#include <catch2/catch.hpp>
#include <petscbinbcsr.h>

#include <cfloat>
#include <cmath>
#include <string>
#include <vector>

namespace rowops {

#define PETSC_OK(expr) REQUIRE((expr) == 0)

// The test matrix: mbs block rows of bs x bs blocks. Pattern: the block diagonal, its neighbours and
// about a quarter of the other blocks (symmetric); with holes, every block row and column I with
// I % 7 == 5 is empty (empty rows, missing diagonals); without, block row and column 1 are dense. Values: random in [-1, 1] with about 10% exact
// zeros, all negative in the rows of blocks 1, 6, 11, ... and all positive in 3, 8, ... (the implicit
// zeros decide MatGetRowMax/Min there), times row and column scales 10^-2 .. 10^2; symmetric when sym (symmetric storage needs it).
// Variants for MatAXPY: drop removes some off-diagonal blocks (a subset), extra adds some.
struct Config {
  PetscInt            bs         = 3;
  bool                sym        = false; // symmetric values and -mat_binbcsr_symmetric_storage
  MatBinBCSRPrecision prec       = MAT_BINBCSR_PRECISION_DOUBLE;
  PetscInt            bw         = 0; // 0: the default bin width
  bool                holes      = true;
  unsigned            value_seed = 1;
  bool                drop = false, extra = false;
  bool                float_values = false; // float-representable entries whatever the precision
  bool                ties         = false;
  bool                full_storage =
    false; // symmetric values (sym) kept in full storage         // entries -1, 0, 1 (times the scales): rows with equal extremes
  PetscInt    mbs() const { return bs == 1 ? 43 : 23; }
  double      eps() const { return prec == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON : DBL_EPSILON; }
  std::string name() const
  {
    return "bs " + std::to_string(bs) + (sym ? " symmetric storage" : " full storage") +
           (prec == MAT_BINBCSR_PRECISION_SINGLE ? " single" : " double") +
           (bw ? " bw " + std::to_string(bw) : "") + (holes ? " holes" : "");
  }
};

// bs 1 and 3, full and symmetric storage, double and single, default bin width with holes and 5 without
// (neither divides
// the rows: 43 rows of bs 1, 23 block rows of bs 3).
// Plus bs 2 (the generic block size path), full double and symmetric single.
std::vector<Config> configs();

inline unsigned hash3(unsigned a, unsigned b, unsigned c)
{
  unsigned h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return h;
}

bool   block_present(const Config &c, PetscInt I, PetscInt J);
double entry(const Config &c, PetscInt i, PetscInt j); // the stored value (float-rounded for single)

// type "aij" or "binbcsr"; binbcsr gets the config's storage options
PetscErrorCode make(const Config &c, const char *type, Mat *A);

// The same matrix as binbcsr and as aij.
struct Pair {
  Mat bin = nullptr, aij = nullptr;
  explicit Pair(const Config &c)
  {
    PETSC_OK(make(c, MATBINBCSR, &bin));
    PETSC_OK(make(c, MATAIJ, &aij));
  }
  ~Pair()
  {
    MatDestroy(&bin);
    MatDestroy(&aij);
  }
};

// Largest |got_ij - want_ij| / (sum_j |want_ij|) over the rows (collective); rows of zeros compare
// absolutely.
double row_error(Mat got, Mat want);
// Deterministic vector: entry i is 0.5 .. 2 with a random sign, times 10^k, k in -1..1.
PetscErrorCode make_vec(Mat A, bool left, unsigned seed, Vec *v);

// Error code of an expression that must fail (the unit tests' main pushes PetscReturnErrorHandler).
#define PETSC_FAILS_WITH(expr, code) CHECK((expr) == (code))

} // namespace rowops
