// The COO mirror of MATBINBCSR (MatBinBCSRSetCOOMirror): a COO list whose off-diagonal-block entries
// also fill their transposed places equals aij given the same list with those transposes appended.
// Random lists with duplicates, diagonal blocks, ignored (negative) entries and entries in either
// triangle; block sizes 1 and 3; on PETSC_COMM_WORLD (this program runs on 1, 2 and 3 ranks, so
// seqbinbcsr on one rank and mpibinbcsr with entries routed to other ranks otherwise) and on
// PETSC_COMM_SELF.
#include <catch2/catch.hpp>

#include "support/fem_problem.hpp"

#include <petscbinbcsr.h>
#include <petsc/private/petscimpl.h> // PetscObjectStateGet

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace mpitest;

#define PCHK(expr) REQUIRE((expr) == 0)

namespace {

struct CooList {
  std::vector<PetscInt>    i, j;
  std::vector<PetscScalar> v;
};

// Entries anywhere in the matrix (any rank's rows), a fifth of them in diagonal blocks, a tenth
// repeating an earlier position, and one ignored entry (negative row).
CooList random_list(PetscInt nblocks, PetscInt bs, int count, unsigned seed)
{
  std::mt19937                            gen(seed);
  std::uniform_int_distribution<PetscInt> block(0, nblocks - 1), point(0, bs - 1);
  std::uniform_real_distribution<double>  value(-1, 1), u(0, 1);
  CooList                                 l;
  for (int k = 0; k < count; ++k) {
    PetscInt i, j;
    if (k > 0 && u(gen) < 0.1) {
      const size_t p = std::uniform_int_distribution<size_t>(0, l.i.size() - 1)(gen);
      i              = l.i[p];
      j              = l.j[p];
    } else {
      const PetscInt I = block(gen), J = u(gen) < 0.2 ? I : block(gen);
      i = I * bs + point(gen);
      j = J * bs + point(gen);
    }
    l.i.push_back(i);
    l.j.push_back(j);
    l.v.push_back(value(gen));
  }
  l.i.push_back(-1);
  l.j.push_back(0);
  l.v.push_back(1e30);
  return l;
}

// The list the mirror stands for: every entry of an off-diagonal block once more, transposed.
CooList with_transposes(const CooList &l, PetscInt bs)
{
  CooList t = l;
  for (size_t k = 0; k < l.i.size(); ++k)
    if (l.i[k] >= 0 && l.j[k] >= 0 && l.i[k] / bs != l.j[k] / bs) {
      t.i.push_back(l.j[k]);
      t.j.push_back(l.i[k]);
      t.v.push_back(l.v[k]);
    }
  return t;
}

PetscErrorCode create(MPI_Comm comm, MatType type, PetscInt nblocks, PetscInt bs, bool mirror, bool sym,
                      const char *parts, Mat *A)
{
  PetscFunctionBeginUser;
  PetscCall(MatCreate(comm, A));
  PetscCall(MatSetSizes(*A, PETSC_DECIDE, PETSC_DECIDE, nblocks * bs, nblocks * bs));
  PetscCall(MatSetBlockSize(*A, bs));
  PetscCall(MatSetType(*A, type));
  if (parts) PetscCall(PetscOptionsSetValue(nullptr, "-mat_mpibinbcsr_inner_type", parts));
  PetscCall(MatSetFromOptions(*A));
  if (parts) PetscCall(PetscOptionsClearValue(nullptr, "-mat_mpibinbcsr_inner_type"));
  if (mirror) PetscCall(MatBinBCSRSetCOOMirror(*A, PETSC_TRUE));
  if (sym) PetscCall(MatBinBCSRSetSymmetricStorage(*A, PETSC_TRUE));
  PetscFunctionReturn(0);
}

PetscErrorCode fill(Mat A, CooList &l, InsertMode mode, double scale)
{
  PetscFunctionBeginUser;
  std::vector<PetscScalar> v(l.v);
  for (auto &x : v) x *= scale;
  PetscCall(MatSetValuesCOO(A, v.data(), mode));
  PetscFunctionReturn(0);
}

// ||A - R||_F / ||R||_F, with A converted to aij.
double relative_difference(Mat A, Mat R)
{
  Mat       C;
  PetscReal d = -1, r = 1;
  MatType   t;
  MatGetType(R, &t);
  if (MatConvert(A, t, MAT_INITIAL_MATRIX, &C)) return 1e300;
  MatNorm(R, NORM_FROBENIUS, &r);
  MatAXPY(C, -1.0, R, DIFFERENT_NONZERO_PATTERN);
  MatNorm(C, NORM_FROBENIUS, &d);
  MatDestroy(&C);
  return d / r;
}

} // namespace

TEST_CASE("COO mirror: binbcsr equals aij given the list and its transposes (bs 1 and 3, any rank's rows)",
          "[mpi][coo_mirror]")
{
  for (MPI_Comm comm : {PETSC_COMM_WORLD, PETSC_COMM_SELF})
    for (PetscInt bs : {1, 3})
      for (const char *parts : {(const char *)nullptr, "seqaij"})
        for (bool sym : {false, true}) {
          if (parts && sym) continue; // symmetric storage is a binbcsr part's
          PetscMPIInt rank, size;
          MPI_Comm_rank(comm, &rank);
          MPI_Comm_size(comm, &size);
          if (parts && size == 1) continue; // no parts on one rank
          INFO("ranks " << size << " bs " << bs << " parts " << (parts ? parts : "seqbinbcsr") << " sym "
                        << sym);
          const PetscInt nblocks = 17;
          CooList        l       = random_list(nblocks, bs, 300, 1234u + 7u * (unsigned)rank + (unsigned)bs);
          if (
            sym) { // symmetric storage ignores the lower triangle: give the upper one, diagonal blocks in full
            CooList u;
            for (size_t k = 0; k < l.i.size(); ++k)
              if (l.i[k] < 0 || l.i[k] / bs <= l.j[k] / bs) {
                u.i.push_back(l.i[k]);
                u.j.push_back(l.j[k]);
                u.v.push_back(l.v[k]);
              }
            l = u;
            // diagonal blocks must be symmetric for the stored matrix to be the whole one
            for (size_t k = 0, n = l.i.size(); k < n; ++k)
              if (l.i[k] >= 0 && l.i[k] / bs == l.j[k] / bs && l.i[k] != l.j[k]) {
                l.i.push_back(l.j[k]);
                l.j.push_back(l.i[k]);
                l.v.push_back(l.v[k]);
              }
          }
          CooList full = with_transposes(l, bs);
          Mat     A, R;
          PCHK(create(comm, MATBINBCSR, nblocks, bs, true, sym, parts, &A));
          PetscBool on = PETSC_FALSE;
          PCHK(MatBinBCSRGetCOOMirror(A, &on));
          CHECK(on);
          PCHK(MatSetPreallocationCOO(A, (PetscCount)l.i.size(), l.i.data(), l.j.data()));
          PCHK(create(comm, MATAIJ, nblocks, bs, false, false, nullptr, &R));
          PCHK(MatSetPreallocationCOO(R, (PetscCount)full.i.size(), full.i.data(), full.j.data()));
          // insert, then add on top, then insert other values: the map persists between refills
          PCHK(fill(A, l, INSERT_VALUES, 1.0));
          PCHK(fill(R, full, INSERT_VALUES, 1.0));
          CHECK(all_ranks(relative_difference(A, R) < 1e-14, comm));
          PCHK(fill(A, l, ADD_VALUES, 2.0));
          PCHK(fill(R, full, ADD_VALUES, 2.0));
          CHECK(all_ranks(relative_difference(A, R) < 1e-14, comm));
          PCHK(fill(A, l, INSERT_VALUES, -0.5));
          PCHK(fill(R, full, INSERT_VALUES, -0.5));
          CHECK(all_ranks(relative_difference(A, R) < 1e-14, comm));
          if (sym) { // and it is symmetric
            PetscBool symmetric = PETSC_FALSE;
            PCHK(MatIsSymmetric(R, 1e-14, &symmetric));
            CHECK(symmetric);
          }
          PCHK(MatDestroy(&A));
          PCHK(MatDestroy(&R));
        }
}

TEST_CASE("COO: a rank that lists no entries still gets those other ranks send it (bs 1 and 3)",
          "[mpi][coo_mirror]")
{
  // Only rank 0 lists entries, every block row's diagonal block among them; the other ranks call with
  // no entries and no values (a null array, as an empty std::vector's data()). Their rows must hold
  // what rank 0 sent: they were zeros, the received entries dropped with the missing local values.
  PetscMPIInt rank;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  for (PetscInt bs : {1, 3})
    for (bool mirror : {false, true})
      for (bool sym : {false, true}) {
        INFO("bs " << bs << " mirror " << mirror << " sym " << sym);
        const PetscInt nblocks = 13;
        CooList        l;
        if (rank == 0) {
          CooList r = random_list(nblocks, bs, 200, 99u + (unsigned)bs);
          for (size_t k = 0; k < r.i.size(); ++k)
            if (r.i[k] >= 0 && (!sym || r.i[k] / bs < r.j[k] / bs)) {
              l.i.push_back(r.i[k]);
              l.j.push_back(r.j[k]);
              l.v.push_back(r.v[k]);
            }
          for (PetscInt b = 0; b < nblocks; ++b) // SPD-like diagonal blocks, symmetric
            for (PetscInt p = 0; p < bs; ++p)
              for (PetscInt q = 0; q < bs; ++q) {
                l.i.push_back(b * bs + p);
                l.j.push_back(b * bs + q);
                l.v.push_back(p == q ? 10.0 + b : 0.5);
              }
        }
        CooList full = mirror || sym ? with_transposes(l, bs) : l;
        // symmetric storage without the mirror takes both triangles (the off-diagonal part is whole)
        if (sym && !mirror) l = full;
        Mat A, R;
        PCHK(create(PETSC_COMM_WORLD, MATBINBCSR, nblocks, bs, mirror, sym, nullptr, &A));
        PCHK(MatSetPreallocationCOO(A, (PetscCount)l.i.size(), l.i.data(), l.j.data()));
        PCHK(create(PETSC_COMM_WORLD, MATAIJ, nblocks, bs, false, false, nullptr, &R));
        PCHK(MatSetPreallocationCOO(R, (PetscCount)full.i.size(), full.i.data(), full.j.data()));
        for (InsertMode mode : {INSERT_VALUES, ADD_VALUES}) {
          PCHK(MatSetValuesCOO(A, l.v.empty() ? nullptr : l.v.data(), mode));
          PCHK(MatSetValuesCOO(R, full.v.empty() ? nullptr : full.v.data(), mode));
          CHECK(all_ranks(relative_difference(A, R) < 1e-14, PETSC_COMM_WORLD));
        }
        PCHK(MatDestroy(&A));
        PCHK(MatDestroy(&R));
      }
}

TEST_CASE("COO mirror: off by default, option, other types unaffected, non-square refused",
          "[mpi][coo_mirror]")
{
  Mat       A;
  PetscBool on = PETSC_TRUE;
  PCHK(create(PETSC_COMM_WORLD, MATBINBCSR, 5, 3, false, false, nullptr, &A));
  PCHK(MatBinBCSRGetCOOMirror(A, &on));
  CHECK(!on);
  PCHK(MatDestroy(&A));
  PCHK(PetscOptionsSetValue(nullptr, "-mat_binbcsr_coo_mirror", "1"));
  PCHK(create(PETSC_COMM_WORLD, MATBINBCSR, 5, 3, false, false, nullptr, &A));
  PCHK(PetscOptionsClearValue(nullptr, "-mat_binbcsr_coo_mirror"));
  PCHK(MatBinBCSRGetCOOMirror(A, &on));
  CHECK(on);
  PCHK(MatDestroy(&A));
  // aij: the setter is a no-op, the getter says no
  PCHK(create(PETSC_COMM_WORLD, MATAIJ, 5, 3, true, false, nullptr, &A));
  PCHK(MatBinBCSRGetCOOMirror(A, &on));
  CHECK(!on);
  PCHK(MatDestroy(&A));
  // a rectangular matrix has no transposed places
  PCHK(MatCreate(PETSC_COMM_SELF, &A));
  PCHK(MatSetSizes(A, 6, 9, 6, 9));
  PCHK(MatSetBlockSize(A, 3));
  PCHK(MatSetType(A, MATBINBCSR));
  PCHK(MatBinBCSRSetCOOMirror(A, PETSC_TRUE));
  PetscInt i[] = {0, 1}, j[] = {7, 8}; // non-const: PETSc 3.18's prototype
  CHECK(MatSetPreallocationCOO(A, 2, i, j) == PETSC_ERR_ARG_SIZ);
  PCHK(MatDestroy(&A));
}

namespace {

// Whole 3x3 blocks, row-major, anywhere in the matrix (a fifth of them on the diagonal); with `mirror`
// only I <= J. Each (I, J) at most once over all ranks (rank p lists every size-th block), or with
// `repeated` every rank lists all blocks and the first ten twice (values summed from several blocks).
// `broken` spoils the whole-block structure (one entry moved to another block position), so the
// refill must fall back to the value-by-value map.
CooList whole_blocks(PetscInt nblocks, bool mirror, bool broken, bool repeated, unsigned seed, int rank,
                     int size)
{
  std::mt19937                               gen(seed);
  std::uniform_int_distribution<PetscInt>    block(0, nblocks - 1);
  std::uniform_real_distribution<double>     value(-1, 1), u(0, 1);
  std::vector<std::pair<PetscInt, PetscInt>> blocks;
  for (int k = 0; k < 60; ++k) {
    PetscInt I = block(gen), J = u(gen) < 0.2 ? I : block(gen);
    if (mirror && I > J) std::swap(I, J);
    if (std::find(blocks.begin(), blocks.end(), std::make_pair(I, J)) == blocks.end())
      blocks.emplace_back(I, J);
  }
  std::vector<size_t> listed;
  for (size_t k = repeated ? 0 : rank; k < blocks.size(); k += repeated ? 1 : size) listed.push_back(k);
  for (size_t k = 0; repeated && k < 10; ++k) listed.push_back(k);
  CooList l;
  for (size_t k : listed)
    for (PetscInt r = 0; r < 3; ++r)
      for (PetscInt c = 0; c < 3; ++c) {
        l.i.push_back(3 * blocks[k].first + r);
        l.j.push_back(3 * blocks[k].second + c);
        l.v.push_back(value(gen));
      }
  if (broken) std::swap(l.j[1], l.j[2]); // block 0 is no longer row-major
  return l;
}

} // namespace

TEST_CASE("COO refill by whole blocks (plain, mirrored, repeated) equals aij; other lists fall back",
          "[mpi][coo_mirror]")
{
  for (MPI_Comm comm : {PETSC_COMM_WORLD, PETSC_COMM_SELF})
    for (bool mirror : {false, true})
      for (bool sym : {false, true})
        for (bool single : {false, true})
          for (int variant : {0, 1, 2}) { // whole blocks once, broken, repeated
            const bool  broken = variant == 1, repeated = variant == 2;
            PetscMPIInt rank, size;
            MPI_Comm_rank(comm, &rank);
            MPI_Comm_size(comm, &size);
            // symmetric storage keeps the blocks coupling two ranks in full: without the mirror the
            // caller lists both (the mpibinbcsr tests do); here every list is an upper triangle
            if (sym && !mirror && size > 1) continue;
            INFO("ranks " << size << " mirror " << mirror << " sym " << sym << " single " << single
                          << " broken " << broken << " repeated " << repeated);
            const PetscInt nblocks = 23;
            CooList        l       = whole_blocks(nblocks, mirror || sym, broken, repeated, 99u, rank, size);
            if (sym) // diagonal blocks symmetric, so that the stored upper triangle is the whole matrix
              for (size_t k = 0; k < l.i.size(); ++k)
                if (l.i[k] / 3 == l.j[k] / 3) {
                  const size_t t =
                    k - (l.i[k] % 3) * 3 - l.j[k] % 3 + (l.j[k] % 3) * 3 + l.i[k] % 3; // transposed entry
                  if (t < k) l.v[k] = l.v[t];
                }
            CooList full = mirror ? with_transposes(l, 3) : l;
            if (sym && !mirror) { // the reference holds the lower triangle that symmetric storage implies
              CooList t = with_transposes(l, 3);
              full      = t;
            }
            Mat A, R;
            PCHK(create(comm, MATBINBCSR, nblocks, 3, mirror, sym, nullptr, &A));
            if (single) PCHK(MatBinBCSRSetPrecision(A, MAT_BINBCSR_PRECISION_SINGLE));
            PCHK(MatSetPreallocationCOO(A, (PetscCount)l.i.size(), l.i.data(), l.j.data()));
            PCHK(create(comm, MATAIJ, nblocks, 3, false, false, nullptr, &R));
            PCHK(MatSetPreallocationCOO(R, (PetscCount)full.i.size(), full.i.data(), full.j.data()));
            const double tol = single ? 1e-7 : 1e-14;
            for (auto [mode, scale] : {std::pair<InsertMode, double>{INSERT_VALUES, 1.0},
                                       {ADD_VALUES, 2.0},
                                       {INSERT_VALUES, -0.5}}) {
              PCHK(fill(A, l, mode, scale));
              PCHK(fill(R, full, mode, scale));
              CHECK(all_ranks(relative_difference(A, R) < tol, comm));
            }
            PCHK(MatDestroy(&A));
            PCHK(MatDestroy(&R));
          }
}

namespace {

// ||A - B||_F (0: the same matrix), both converted to aij.
double absolute_difference(Mat A, Mat B)
{
  Mat       CA, CB;
  PetscReal d = -1;
  if (MatConvert(A, MATAIJ, MAT_INITIAL_MATRIX, &CA)) return 1e300;
  if (MatConvert(B, MATAIJ, MAT_INITIAL_MATRIX, &CB)) return 1e300;
  MatAXPY(CA, -1.0, CB, DIFFERENT_NONZERO_PATTERN);
  MatNorm(CA, NORM_FROBENIUS, &d);
  MatDestroy(&CA);
  MatDestroy(&CB);
  return d;
}

} // namespace

TEST_CASE("COO in single precision: the matrix the double list of the same values gives", "[mpi][coo_single]")
{
  for (MPI_Comm comm : {PETSC_COMM_WORLD, PETSC_COMM_SELF})
    for (PetscInt bs : {1, 3})
      for (bool mirror : {false, true})
        for (bool sym : {false, true})
          for (MatBinBCSRPrecision prec : {MAT_BINBCSR_PRECISION_DOUBLE, MAT_BINBCSR_PRECISION_SINGLE}) {
            PetscMPIInt rank, size;
            MPI_Comm_rank(comm, &rank);
            MPI_Comm_size(comm, &size);
            INFO("ranks " << size << " bs " << bs << " mirror " << mirror << " sym " << sym << " single "
                          << (prec == MAT_BINBCSR_PRECISION_SINGLE));
            const PetscInt nblocks = 17;
            CooList        l       = random_list(nblocks, bs, 300, 777u + 5u * (unsigned)rank + (unsigned)bs);
            // Whole 3x3 blocks too (the refill by blocks), each listed twice (summed).
            if (bs == 3)
              for (PetscInt b = 0; b + 1 < nblocks; b += 4)
                for (int rep = 0; rep < 2; ++rep)
                  for (PetscInt p = 0; p < 9; ++p) {
                    l.i.push_back(3 * b + p / 3);
                    l.j.push_back(3 * (b + 1) + p % 3);
                    l.v.push_back(0.1 * (p + 1) * (rep + 1));
                  }
            std::vector<float> f(l.v.begin(), l.v.end());        // the values as floats ...
            for (size_t k = 0; k < f.size(); ++k) l.v[k] = f[k]; // ... and the same values as doubles
            Mat A, B;
            for (Mat *M : {&A, &B}) {
              PCHK(create(comm, MATBINBCSR, nblocks, bs, mirror, sym, nullptr, M));
              PCHK(MatBinBCSRSetPrecision(*M, prec));
              std::vector<PetscInt> i = l.i, j = l.j;
              PCHK(MatSetPreallocationCOO(*M, (PetscCount)i.size(), i.data(), j.data()));
            }
            for (InsertMode mode : {INSERT_VALUES, ADD_VALUES, INSERT_VALUES}) {
              PetscObjectState s0, s1;
              PCHK(PetscObjectStateGet((PetscObject)B, &s0));
              PCHK(MatSetValuesCOO(A, l.v.data(), mode));
              PCHK(MatBinBCSRSetValuesCOOSingle(B, f.data(), mode));
              PCHK(PetscObjectStateGet((PetscObject)B, &s1));
              CHECK(s1 > s0); // a refill a KSP sees, as MatSetValuesCOO's
              PetscBool assembled = PETSC_FALSE;
              PCHK(MatAssembled(B, &assembled));
              CHECK(assembled);
              // the same sums in double in the same order, rounded once: the same matrix to the bit
              CHECK(all_ranks(absolute_difference(A, B) == 0.0, comm));
            }
            PCHK(MatSetValuesCOO(A, nullptr, INSERT_VALUES)); // null: zeros
            PCHK(MatBinBCSRSetValuesCOOSingle(B, nullptr, INSERT_VALUES));
            CHECK(all_ranks(absolute_difference(A, B) == 0.0, comm));
            PCHK(MatDestroy(&A));
            PCHK(MatDestroy(&B));
          }
}

TEST_CASE("COO in single precision: other types and unprepared matrices are errors", "[mpi][coo_single]")
{
  Mat      A;
  PetscInt i[1] = {0}, j[1] = {0};
  float    v[1] = {1};
  PCHK(MatCreateSeqAIJ(PETSC_COMM_SELF, 3, 3, 1, nullptr, &A));
  PCHK(MatSetPreallocationCOO(A, 1, i, j));
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  CHECK(MatBinBCSRSetValuesCOOSingle(A, v, INSERT_VALUES) == PETSC_ERR_SUP);
  PetscPopErrorHandler();
  PCHK(MatDestroy(&A));
  PCHK(create(PETSC_COMM_SELF, MATBINBCSR, 1, 3, false, false, nullptr, &A));
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  CHECK(MatBinBCSRSetValuesCOOSingle(A, v, INSERT_VALUES) != 0); // no preallocation
  PetscPopErrorHandler();
  PCHK(MatDestroy(&A));
}
