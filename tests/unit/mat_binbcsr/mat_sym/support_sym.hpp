// Fixtures of the symmetric-storage tests: symmetric patterns (random, FEM-like, ragged, end rows)
// and builders that create seqaij / seqsbaij / seqbinbcsr (full or symmetric storage) from them.
#pragma once
#include "support/mat_support.hpp"
#include "mat_binbcsr/seq/binbcsr.h"
#include <algorithm>
#include <map>

namespace mat_sym {
using namespace mat_core;

// The symmetric matrix whose upper block triangle (and upper triangle of each diagonal block) is p's.
inline Pattern symmetrize(const Pattern &p)
{
  std::map<std::pair<PetscInt, PetscInt>, PetscScalar> m;
  for (const Entry &e : p.entries) {
    const PetscInt br = e.i / p.bs, bc = e.j / p.bs;
    if (bc < br || (bc == br && e.j < e.i)) continue;
    m[{e.i, e.j}] = e.v;
    m[{e.j, e.i}] = e.v;
  }
  Pattern s;
  s.m = s.n = p.m;
  s.bs      = p.bs;
  for (auto &kv : m) s.entries.push_back({kv.first.first, kv.first.second, kv.second});
  return s;
}

// A band whose last rows are short while one column appears in every lane of the last bins: the
// colouring must give that column one slot group per lane (more groups than the longest row).
inline Pattern end_rows_pattern(PetscInt mbs, PetscInt bs)
{
  Pattern p;
  p.m = p.n = mbs * bs;
  p.bs      = bs;
  for (PetscInt r = 0; r < mbs; r++) {
    std::vector<PetscInt> cols = {r, mbs - 1};
    if (r + 1 < mbs) cols.push_back(r + 1);
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    for (PetscInt c : cols)
      for (PetscInt i = 0; i < bs; i++)
        for (PetscInt j = 0; j < bs; j++)
          p.entries.push_back(
            {r * bs + i, c * bs + j,
             r == c ? (i == j ? 10.0 : 0.1 * (i + j)) : -0.3 - 0.01 * ((r + c + i + j) % 5)});
  }
  return symmetrize(p);
}

inline Mat build_sym(const Pattern &p, PetscInt bw, MatBinBCSRPrecision prec, bool sym = true)
{
  Mat A = nullptr;
  REQUIRE(MatCreate(PETSC_COMM_SELF, &A) == 0);
  REQUIRE(MatSetSizes(A, p.m, p.n, p.m, p.n) == 0);
  REQUIRE(MatSetBlockSize(A, p.bs) == 0);
  REQUIRE(MatSetType(A, MATSEQBINBCSR) == 0);
  if (bw) REQUIRE(MatBinBCSRSetBinWidth(A, bw) == 0);
  REQUIRE(MatBinBCSRSetPrecision(A, prec) == 0);
  REQUIRE(MatBinBCSRSetSymmetricStorage(A, sym ? PETSC_TRUE : PETSC_FALSE) == 0);
  REQUIRE(MatSetUp(A) == 0);
  for (const Entry &e : p.entries)
    REQUIRE(MatSetValue(A, e.i, e.j, e.v, INSERT_VALUES) == 0); // both triangles
  REQUIRE(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY) == 0);
  REQUIRE(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY) == 0);
  return A;
}

// Within every slot group of every bin, the lanes whose column is not their own row have distinct
// columns (the scatter is conflict-free); every real block is stored exactly once.
inline void check_colouring(Mat A)
{
  const Mat_SeqBinBCSR *a = (const Mat_SeqBinBCSR *)A->data;
  REQUIRE(a->sym);
  size_t bad = 0;
  for (PetscInt b = 0; b < a->nbins; b++) {
    const PetscInt len = (a->bin_start[b + 1] - a->bin_start[b]) / a->bw;
    for (PetscInt k = 0; k < len; k++) {
      std::vector<PetscInt> seen;
      for (PetscInt l = 0; l < a->bw; l++) {
        const PetscInt s = a->bin_start[b] + k * a->bw + l, r = b * a->bw + l,
                       own = r < a->mbs ? r : a->mbs - 1;
        const PetscInt c   = a->col[s];
        if (c < 0 || c >= a->nbs) bad++;
        if (c == own) continue;
        if (c < r) bad++; // below the diagonal
        for (PetscInt o : seen)
          if (o == c) bad++;
        seen.push_back(c);
      }
    }
  }
  CHECK(bad == 0);
}

} // namespace mat_sym
