// Comparison harness for the value operations of a matrix type (zero, scale, shift, diagonal set,
// AXPY, zero rows/columns, norms, info, binary I/O): every operation is applied to the same matrix
// stored as the type under test and as seqaij (double, the reference), and the results are compared
// entry by entry with a tolerance derived from the storage precision's epsilon and the row norms.
#pragma once

#include <catch2/catch.hpp>
#include <petscbinbcsr.h>

#include <cfloat>
#include <string>
#include <vector>

namespace matops {

// Turned on once MATSEQBINBCSR's core (assembly, MatGetRow, preallocation) is on main.
#ifndef MAT_OPS_TEST_BINBCSR
  #define MAT_OPS_TEST_BINBCSR 1
#endif

// A matrix under test: a type and, for binbcsr, its storage.
struct Flavour {
  std::string         name;
  const char         *type;
  MatBinBCSRPrecision precision = MAT_BINBCSR_PRECISION_DOUBLE;
  PetscInt            bin_width = 0;   // 0: the type's default
  bool                fixed_pattern;   // refuses new nonzeros after the first assembly
  bool                validates_input; // checks vector sizes, NaN under MatSetErrorIfFailure, file data
  double eps() const { return precision == MAT_BINBCSR_PRECISION_SINGLE ? FLT_EPSILON : DBL_EPSILON; }
  bool   is_binbcsr() const { return std::string(type) == MATSEQBINBCSR; }
};
std::vector<Flavour> flavours();

// A square test matrix: block size, block pattern and values, held as scalar CSR with full blocks.
struct Pattern {
  std::string              name;
  PetscInt                 bs = 1, mbs = 0;
  std::vector<PetscInt>    rowptr, cols; // scalar rows, m + 1 and nnz
  std::vector<PetscScalar> vals;
  PetscInt                 m() const { return mbs * bs; }
  bool                     has_full_diagonal() const;
};
std::vector<Pattern> patterns();
// The same block pattern with other values (seed), for a second operand of the same structure.
Pattern revalue(const Pattern &p, unsigned seed);
// Another block pattern of the same size: overlaps p and adds new blocks.
Pattern other_pattern(const Pattern &p, unsigned seed);

// Assembled matrix of the flavour (or seqaij when f is null) holding p.
PetscErrorCode build(const Flavour *f, const Pattern &p, Mat *A);
// Created and preallocated for p, no values set, not assembled.
PetscErrorCode preallocate(const Flavour *f, const Pattern &p, Mat *A);
PetscErrorCode fill(const Pattern &p, Mat A, InsertMode mode, PetscScalar factor = 1.0);

// Row i's sum of |a_ij|: the scale of the rounding error a stored row can carry.
std::vector<double> row_abs_sums(Mat A);
// Largest |got_ij - want_ij| / (scale_i) over all entries, and the entry where it happens; compares
// values only (a stored zero and an absent entry are equal).
struct Mismatch {
  double   ratio = 0;
  PetscInt row = -1, col = -1;
  double   got = 0, want = 0;
};
Mismatch compare(Mat got, Mat want, const std::vector<double> &scale);
// Vectors: |got_i - want_i| <= tol_i.
Mismatch compare(Vec got, Vec want, const std::vector<double> &tol);

// Error margin on top of the first-order rounding bound: operations do at most a few roundings
// per entry, each <= eps/2 relative to the row scale.
constexpr double kRoundings = 4.0;

std::vector<double> scaled(const std::vector<double> &v, double a);
std::vector<double> plus(const std::vector<double> &a, const std::vector<double> &b);

PetscErrorCode random_vec(PetscInt n, unsigned seed, Vec *v);

} // namespace matops

#define PETSC_OK(expr) REQUIRE((expr) == 0)
// The result of a comparison: within kRoundings * eps of each row's scale.
#define CHECK_CLOSE(mm, eps)                                                                          \
  do {                                                                                                \
    const matops::Mismatch mm_ = (mm);                                                                \
    INFO("worst entry (" << mm_.row << "," << mm_.col << "): got " << mm_.got << " want " << mm_.want \
                         << ", error / (eps * row scale) = " << mm_.ratio / (eps));                   \
    CHECK(mm_.ratio <= matops::kRoundings * (eps));                                                   \
  } while (0)
