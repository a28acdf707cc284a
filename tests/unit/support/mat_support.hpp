// Shared fixtures of the mat_core unit tests: matrix patterns (random, FEM-like 27-point 3x3-block
// stencils, wildly different row lengths) built identically as seqaij and as seqbinbcsr, and
// comparisons with tolerances derived from the arithmetic (not loose constants).
#pragma once
#include <algorithm>
#include <catch2/catch.hpp>
#include <petscbinbcsr.h>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>
#include <random>
#include <vector>

namespace mat_core {

struct Entry {
  PetscInt    i, j;
  PetscScalar v;
};

// A point-entry description of a matrix: m x n with block size bs, entries with unique (i, j).
struct Pattern {
  PetscInt           m = 0, n = 0, bs = 1;
  std::vector<Entry> entries;
};

// Random block pattern: every block row gets 0..maxblocks random blocks (some rows empty), each
// block full; the diagonal block is added when `diag`.
inline Pattern random_pattern(PetscInt mbs, PetscInt nbs, PetscInt bs, PetscInt maxblocks, unsigned seed,
                              bool diag = true)
{
  std::mt19937                           rng(seed);
  std::uniform_real_distribution<double> val(-1.0, 1.0);
  Pattern                                p;
  p.m  = mbs * bs;
  p.n  = nbs * bs;
  p.bs = bs;
  for (PetscInt r = 0; r < mbs; r++) {
    std::vector<PetscInt> cols;
    const PetscInt        nb = (PetscInt)(rng() % (maxblocks + 1));
    for (PetscInt k = 0; k < nb; k++) cols.push_back((PetscInt)(rng() % nbs));
    if (diag && r < nbs && r % 7 != 3) cols.push_back(r); // some rows lack the diagonal
    if (r % 5 == 2) cols.clear();                         // empty rows
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    for (PetscInt c : cols)
      for (PetscInt i = 0; i < bs; i++)
        for (PetscInt j = 0; j < bs; j++)
          p.entries.push_back(
            {r * bs + i, c * bs + j, val(rng) + (r == c && i == j ? 4.0 * maxblocks : 0.0)});
  }
  return p;
}

// FEM-like: nodes of an nx*ny*nz grid, 3x3 blocks coupling each node with its 27-point neighbourhood,
// symmetric, diagonally dominant.
inline Pattern fem_pattern(PetscInt nx, PetscInt ny, PetscInt nz, PetscInt bs = 3)
{
  Pattern        p;
  const PetscInt nn = nx * ny * nz;
  p.m = p.n = nn * bs;
  p.bs      = bs;
  auto id   = [&](PetscInt x, PetscInt y, PetscInt z) { return (z * ny + y) * nx + x; };
  for (PetscInt z = 0; z < nz; z++)
    for (PetscInt y = 0; y < ny; y++)
      for (PetscInt x = 0; x < nx; x++) {
        const PetscInt r = id(x, y, z);
        for (PetscInt dz = -1; dz <= 1; dz++)
          for (PetscInt dy = -1; dy <= 1; dy++)
            for (PetscInt dx = -1; dx <= 1; dx++) {
              const PetscInt X = x + dx, Y = y + dy, Z = z + dz;
              if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
              const PetscInt c = id(X, Y, Z);
              for (PetscInt i = 0; i < bs; i++)
                for (PetscInt j = 0; j < bs; j++) {
                  const PetscInt lo = PetscMin(r, c), hi = PetscMax(r, c);
                  // symmetric: block (c, r) is the transpose of block (r, c)
                  const double v =
                    (r == c) ? (i == j ? 60.0 : 0.5 / (1 + i + j))
                             : -1.0 / (1.0 + ((lo * 31 + hi * 17 + (r < c ? i * 3 + j : j * 3 + i)) % 7));
                  p.entries.push_back({r * bs + i, c * bs + j, v});
                }
            }
      }
  return p;
}

// Rows of wildly different lengths in the same bin: block row 1 has `longrow` blocks, the others 1.
inline Pattern wild_pattern(PetscInt mbs, PetscInt bs, PetscInt longrow)
{
  Pattern p;
  p.m = p.n = mbs * bs;
  p.bs      = bs;
  for (PetscInt r = 0; r < mbs; r++) {
    const PetscInt nb = (r == 1) ? PetscMin(longrow, mbs) : 1;
    for (PetscInt k = 0; k < nb; k++) {
      const PetscInt c = (r == 1) ? (k * 7919) % mbs : r;
      for (PetscInt i = 0; i < bs; i++)
        for (PetscInt j = 0; j < bs; j++)
          p.entries.push_back({r * bs + i, c * bs + j, 1.0 + 0.01 * ((r + 3 * k + i + 2 * j) % 13)});
    }
  }
  // (r==1) columns k*7919 % mbs may repeat when mbs divides 7919*k: dedupe
  std::sort(p.entries.begin(), p.entries.end(),
            [](const Entry &a, const Entry &b) { return a.i < b.i || (a.i == b.i && a.j < b.j); });
  p.entries.erase(std::unique(p.entries.begin(), p.entries.end(),
                              [](const Entry &a, const Entry &b) { return a.i == b.i && a.j == b.j; }),
                  p.entries.end());
  return p;
}

// An empty `type` of the pattern's sizes and block size, not yet set up; bin width (0: the default),
// precision and storage are applied to binbcsr matrices (the setters do nothing to other types).
inline Mat create_unfilled(const Pattern &p, MatType type, PetscInt bw = 0,
                           MatBinBCSRPrecision prec = MAT_BINBCSR_PRECISION_DOUBLE,
                           PetscBool           sym  = PETSC_FALSE)
{
  Mat A = nullptr;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, p.bs) == 0);
  REQUIRE(MatSetType(A, type) == 0);
  if (bw) REQUIRE(MatBinBCSRSetBinWidth(A, bw) == 0);
  REQUIRE(MatBinBCSRSetPrecision(A, prec) == 0);
  if (sym) REQUIRE(MatBinBCSRSetSymmetricStorage(A, sym) == 0);
  return A;
}

// Creates and assembles `type` from the pattern through MatSetValues (one entry at a time, a
// shuffled order so staging sees unsorted input). bw/precision are applied to binbcsr matrices.
inline Mat build(const Pattern &p, MatType type, PetscInt bw = 0,
                 MatBinBCSRPrecision prec = MAT_BINBCSR_PRECISION_DOUBLE)
{
  Mat A = create_unfilled(p, type, bw, prec);
  REQUIRE(MatSetUp(A) == 0);
  std::vector<size_t> order(p.entries.size());
  for (size_t k = 0; k < order.size(); k++) order[k] = (k * 7919) % order.size();
  if (!order.empty() && std::__gcd(order.size(), (size_t)7919) != 1)
    for (size_t k = 0; k < order.size(); k++) order[k] = k;
  for (size_t k : order)
    REQUIRE(MatSetValue(A, p.entries[k].i, p.entries[k].j, p.entries[k].v, INSERT_VALUES) == 0);
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  return A;
}

inline Vec make_vec(PetscInt n, unsigned seed)
{
  Vec                                    v;
  std::mt19937                           rng(seed);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  REQUIRE(VecCreateSeq(PETSC_COMM_SELF, n, &v) == 0);
  PetscScalar *a;
  REQUIRE(VecGetArray(v, &a) == 0);
  for (PetscInt i = 0; i < n; i++) a[i] = d(rng);
  REQUIRE(VecRestoreArray(v, &a) == 0);
  return v;
}

inline std::vector<PetscScalar> values(Vec v)
{
  PetscInt           n;
  const PetscScalar *a;
  REQUIRE(VecGetLocalSize(v, &n) == 0);
  REQUIRE(VecGetArrayRead(v, &a) == 0);
  std::vector<PetscScalar> out(a, a + n);
  REQUIRE(VecRestoreArrayRead(v, &a) == 0);
  return out;
}

// Per-row bound of |(A x)_i - ref_i|: the rounding of the stored values (relative `unit`, i.e.
// FLT_EPSILON/2 for float storage) times sum_j |a_ij x_j|, plus double accumulation error.
inline std::vector<double> mult_bound(const Pattern &p, const std::vector<PetscScalar> &x, double unit,
                                      bool transpose)
{
  std::vector<double> b(transpose ? p.n : p.m, 0.0);
  for (const Entry &e : p.entries) {
    if (transpose) b[e.j] += std::fabs(e.v * x[e.i]);
    else b[e.i] += std::fabs(e.v * x[e.j]);
  }
  for (double &v : b) v = v * (unit + 64 * DBL_EPSILON) + 1e-300;
  return b;
}

inline void check_close(const std::vector<PetscScalar> &got, const std::vector<PetscScalar> &ref,
                        const std::vector<double> &bound)
{
  REQUIRE(got.size() == ref.size());
  size_t bad = 0;
  for (size_t i = 0; i < got.size(); i++)
    if (!(std::fabs(got[i] - ref[i]) <= bound[i])) {
      if (bad < 5)
        UNSCOPED_INFO("entry " << i << ": got " << got[i] << " ref " << ref[i] << " bound " << bound[i]);
      bad++;
    }
  CHECK(bad == 0);
}

// All entries through MatGetValues (independent of MatGetRow and the products).
inline std::vector<PetscScalar> dense(Mat A)
{
  PetscInt m, n;
  REQUIRE(MatGetSize(A, &m, &n) == 0);
  std::vector<PetscInt> rows(m), cols(n);
  for (PetscInt i = 0; i < m; i++) rows[i] = i;
  for (PetscInt j = 0; j < n; j++) cols[j] = j;
  std::vector<PetscScalar> d((size_t)m * n);
  if (m && n) REQUIRE(MatGetValues(A, m, rows.data(), n, cols.data(), d.data()) == 0);
  return d;
}

inline std::vector<PetscScalar> dense(const Pattern &p)
{
  std::vector<PetscScalar> d((size_t)p.m * p.n, 0.0);
  for (const Entry &e : p.entries) d[(size_t)e.i * p.n + e.j] = e.v;
  return d;
}

inline void check_dense(const std::vector<PetscScalar> &got, const std::vector<PetscScalar> &ref, double rel)
{
  REQUIRE(got.size() == ref.size());
  size_t bad = 0;
  for (size_t k = 0; k < got.size(); k++)
    if (!(std::fabs(got[k] - ref[k]) <= rel * std::fabs(ref[k]))) {
      if (bad < 5) UNSCOPED_INFO("entry " << k << ": got " << got[k] << " ref " << ref[k]);
      bad++;
    }
  CHECK(bad == 0);
}

// MatView(A) in PETSC_VIEWER_ASCII_INFO format, as text.
inline std::string info_view(Mat A)
{
  FILE       *f = tmpfile();
  PetscViewer v;
  REQUIRE(f != nullptr);
  REQUIRE(PetscViewerASCIIOpenWithFILE(PETSC_COMM_SELF, f, &v) == 0);
  REQUIRE(PetscViewerPushFormat(v, PETSC_VIEWER_ASCII_INFO) == 0);
  REQUIRE(MatView(A, v) == 0);
  REQUIRE(PetscViewerPopFormat(v) == 0);
  REQUIRE(PetscViewerDestroy(&v) == 0);
  rewind(f);
  std::string text;
  char        buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  fclose(f);
  return text;
}

} // namespace mat_core
