// Shared by the PC tests (PCEISENSTAT, PCGAMG on binbcsr): the FEM problem of tests/unit/mat_binbcsr/mpi as a bs 3
// (3 unknowns per node) or bs 1 (one per node) matrix, assembled through COO on any communicator size,
// refilled in place, and the storage variants of binbcsr. Every function is collective.
#pragma once
#include <catch2/catch.hpp>

#include "support/fem_problem.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace pctest {

using namespace mpitest;

#define PCHK(expr) REQUIRE((expr) == 0)

struct Storage {
  const char *name;
  bool        sym, single;
};
const Storage storages[] = {
  {"full", false, false}, {"symmetric storage", true, false}, {"single", false, true}};

inline double weight0(int) { return 1.0; }
inline double weight1(int e) { return 1.0 + 3.0 * (e % 4); } // a refill that changes any preconditioner a lot

// bs 3: the FEM problem's 24 x 24 element matrices; bs 1: a scalar 8 x 8 element matrix per element
// (8 I - 1 1^T) s_e + mass on the nodes. This rank's elements are dealt round-robin, as rank_coo_entries.
inline void coo_entries(const FemProblem &fem, PetscInt bs, std::vector<PetscInt> &ci,
                        std::vector<PetscInt> &cj)
{
  if (bs == 3) return rank_coo_entries(fem, ci, cj);
  PetscMPIInt rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  for (int e = rank; e < fem.element_count(); e += size) {
    const auto blk = fem.element_blocks(e);
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        ci.push_back(blk[a]);
        cj.push_back(blk[b]);
      }
  }
}

template <class Weight> std::vector<PetscScalar> coo_values(const FemProblem &fem, PetscInt bs, Weight weight)
{
  if (bs == 3) return rank_element_values(fem, weight);
  PetscMPIInt rank, size;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  std::vector<PetscScalar> cv;
  for (int e = rank; e < fem.element_count(); e += size) {
    const double w = weight(e), s = 2.0 + 0.01 * (e % 7);
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) cv.push_back(w * (((a == b ? 8.0 : 0.0) - 1.0) * s + (a == b ? 0.5 : 0.0)));
  }
  return cv;
}

// Local rows of this rank for block size bs (nodes split evenly).
inline PetscInt rows_for(const FemProblem &fem, PetscInt bs)
{
  return local_rows(fem, PETSC_COMM_WORLD, false) / 3 * bs;
}

// A matrix of the given type (binbcsr: with the storage variant) filled through COO with weight0.
inline PetscErrorCode coo_matrix(const FemProblem &fem, PetscInt bs, MatType type, const Storage &st, Mat *A)
{
  std::vector<PetscInt> ci, cj;
  PetscFunctionBeginUser;
  const PetscInt m = rows_for(fem, bs), M = fem.nodes() * bs;
  PetscCall(MatCreate(PETSC_COMM_WORLD, A));
  PetscCall(MatSetSizes(*A, m, m, M, M));
  PetscCall(MatSetBlockSize(*A, bs));
  PetscCall(MatSetType(*A, type));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
  if (st.sym) PetscCall(MatBinBCSRSetSymmetricStorage(*A, PETSC_TRUE));
  if (st.single) PetscCall(MatBinBCSRSetPrecision(*A, MAT_BINBCSR_PRECISION_SINGLE));
  coo_entries(fem, bs, ci, cj);
  PetscCall(MatSetPreallocationCOO(*A, static_cast<PetscCount>(ci.size()), ci.data(), cj.data()));
  PetscCall(MatSetValuesCOO(*A, coo_values(fem, bs, weight0).data(), INSERT_VALUES));
  PetscFunctionReturn(0);
}

// The binbcsr matrix and its aij reference: assembled alike, or (single precision) the aij copy of the
// binbcsr values, so that both sides hold the same system.
inline PetscErrorCode matrix_pair(const FemProblem &fem, PetscInt bs, const Storage &st, Mat *A, Mat *R)
{
  PetscFunctionBeginUser;
  PetscCall(coo_matrix(fem, bs, MATBINBCSR, st, A));
  if (st.single) PetscCall(MatConvert(*A, MATAIJ, MAT_INITIAL_MATRIX, R));
  else PetscCall(coo_matrix(fem, bs, MATAIJ, st, R));
  PetscFunctionReturn(0);
}

// Both refilled in place (same pattern) with weight1.
inline PetscErrorCode refill_pair(const FemProblem &fem, PetscInt bs, const Storage &st, Mat A, Mat R)
{
  PetscFunctionBeginUser;
  const auto cv = coo_values(fem, bs, weight1);
  PetscCall(MatSetValuesCOO(A, cv.data(), INSERT_VALUES));
  if (st.single) PetscCall(MatConvert(A, MATAIJ, MAT_REUSE_MATRIX, &R));
  else PetscCall(MatSetValuesCOO(R, cv.data(), INSERT_VALUES));
  PetscFunctionReturn(0);
}

inline PetscErrorCode random_vec(Mat A, unsigned seed, Vec *b)
{
  PetscRandom rnd;
  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(A, nullptr, b));
  PetscCall(PetscRandomCreate(PETSC_COMM_WORLD, &rnd));
  PetscCall(PetscRandomSetSeed(rnd, seed));
  PetscCall(PetscRandomSeed(rnd));
  PetscCall(VecSetRandom(*b, rnd));
  PetscCall(PetscRandomDestroy(&rnd));
  PetscFunctionReturn(0);
}

// Options set for the life of the object (a KSP reads its own at KSPSetFromOptions / set-up).
struct ScopedOptions {
  std::vector<std::string> names;
  explicit ScopedOptions(const std::vector<std::pair<std::string, std::string>> &opts)
  {
    for (auto &[k, v] : opts) {
      PetscOptionsSetValue(nullptr, k.c_str(), v.c_str());
      names.push_back(k);
    }
  }
  ~ScopedOptions()
  {
    for (auto &k : names) PetscOptionsClearValue(nullptr, k.c_str());
  }
};

struct SolveResult {
  PetscInt           its    = -1;
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
};

inline PetscErrorCode solve(KSP ksp, Vec b, Vec x, SolveResult *r)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(x, 0.0));
  PetscCall(KSPSolve(ksp, b, x));
  PetscCall(KSPGetIterationNumber(ksp, &r->its));
  PetscCall(KSPGetConvergedReason(ksp, &r->reason));
  PetscFunctionReturn(0);
}

} // namespace pctest
