#include "harness.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace matops {

std::vector<Flavour> flavours()
{
  std::vector<Flavour> f;
  f.push_back({"seqbaij", MATSEQBAIJ, MAT_BINBCSR_PRECISION_DOUBLE, 0, false, false});
#if MAT_OPS_TEST_BINBCSR
  f.push_back({"binbcsr double", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_DOUBLE, 0, true, true});
  f.push_back({"binbcsr double bw 3", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_DOUBLE, 3, true, true});
  f.push_back({"binbcsr single", MATSEQBINBCSR, MAT_BINBCSR_PRECISION_SINGLE, 0, true, true});
#endif
  return f;
}

bool Pattern::has_full_diagonal() const
{
  for (PetscInt i = 0; i < m(); i++) {
    if (!std::binary_search(cols.begin() + rowptr[i], cols.begin() + rowptr[i + 1], i)) return false;
  }
  return true;
}

namespace {

// Expands per-block-row block columns into scalar CSR with full bs x bs blocks. Values: random in
// [-1, 1] scaled per block row by 10^k (k in -3..3) so tolerances must follow row norms, and a
// dominant diagonal like a stiffness matrix.
Pattern expand(const std::string &name, PetscInt bs, const std::vector<std::set<PetscInt>> &block_cols,
               unsigned seed)
{
  Pattern p;
  p.name = name;
  p.bs   = bs;
  p.mbs  = (PetscInt)block_cols.size();
  std::mt19937                           rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int>     decade(-3, 3);
  p.rowptr.push_back(0);
  for (PetscInt I = 0; I < p.mbs; I++) {
    const double row_scale = std::pow(10.0, decade(rng));
    for (PetscInt r = 0; r < bs; r++) {
      const PetscInt i = I * bs + r;
      for (PetscInt J : block_cols[I]) {
        for (PetscInt c = 0; c < bs; c++) {
          const PetscInt j = J * bs + c;
          p.cols.push_back(j);
          p.vals.push_back(row_scale * (i == j ? 4.0 * (double)block_cols[I].size() + u(rng) : u(rng)));
        }
      }
      p.rowptr.push_back((PetscInt)p.cols.size());
    }
  }
  return p;
}

std::vector<std::set<PetscInt>> block_pattern(const Pattern &p)
{
  std::vector<std::set<PetscInt>> b(p.mbs);
  for (PetscInt i = 0; i < p.m(); i++)
    for (PetscInt k = p.rowptr[i]; k < p.rowptr[i + 1]; k++) b[i / p.bs].insert(p.cols[k] / p.bs);
  return b;
}

// Node graph of a structured hexahedral mesh: nodes sharing an element are coupled (27 points).
std::vector<std::set<PetscInt>> grid_pattern(PetscInt nx, PetscInt ny, PetscInt nz)
{
  std::vector<std::set<PetscInt>> b(nx * ny * nz);
  for (PetscInt z = 0; z < nz; z++)
    for (PetscInt y = 0; y < ny; y++)
      for (PetscInt x = 0; x < nx; x++)
        for (PetscInt dz = -1; dz <= 1; dz++)
          for (PetscInt dy = -1; dy <= 1; dy++)
            for (PetscInt dx = -1; dx <= 1; dx++) {
              const PetscInt X = x + dx, Y = y + dy, Z = z + dz;
              if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
              b[(z * ny + y) * nx + x].insert((Z * ny + Y) * nx + X);
            }
  return b;
}

// Random pattern; with holes, 15% of the rows and the whole block rows 8..15 (a full bin for bin
// widths up to 8) are empty, diagonal included.
std::vector<std::set<PetscInt>> random_pattern(PetscInt mbs, unsigned seed, bool holes)
{
  std::mt19937                       rng(seed);
  std::uniform_int_distribution<int> len(0, 8), col(0, (int)mbs - 1), pct(0, 99);
  std::vector<std::set<PetscInt>>    b(mbs);
  for (PetscInt I = 0; I < mbs; I++) {
    if (holes && ((I >= 8 && I < 16) || pct(rng) < 15)) continue;
    b[I].insert(I);
    for (int k = len(rng); k > 0; k--) b[I].insert(col(rng));
  }
  return b;
}

// Rows of 500 blocks next to rows of one block, in the same bins and in the last, partial bin.
std::vector<std::set<PetscInt>> wild_pattern()
{
  const PetscInt                  mbs = 503;
  std::vector<std::set<PetscInt>> b(mbs);
  for (PetscInt I = 0; I < mbs; I++) b[I].insert(I);
  for (PetscInt I : {0, 9, 502})
    for (PetscInt J = 0; J < 500; J++) b[I].insert((J * 7 + I) % mbs);
  return b;
}

} // namespace

std::vector<Pattern> patterns()
{
  std::vector<Pattern> p;
  p.push_back(expand("fem 3x3 blocks 5x4x3 nodes", 3, grid_pattern(5, 4, 3), 1));
  p.push_back(expand("fem scalar 7x5x3 nodes", 1, grid_pattern(7, 5, 3), 2));
  p.push_back(expand("random bs 1 n 37 with empty rows", 1, random_pattern(37, 3, true), 3));
  p.push_back(expand("random bs 3 mbs 29 with empty rows", 3, random_pattern(29, 4, true), 4));
  p.push_back(expand("random bs 3 mbs 13", 3, random_pattern(13, 5, false), 5));
  p.push_back(expand("one row bs 1", 1, {{0}}, 6));
  p.push_back(expand("one block row bs 3", 3, {{0}}, 7));
  p.push_back(expand("rows of 1 and 500 blocks", 3, wild_pattern(), 8));
  return p;
}

Pattern revalue(const Pattern &p, unsigned seed) { return expand(p.name, p.bs, block_pattern(p), seed); }

Pattern other_pattern(const Pattern &p, unsigned seed)
{
  std::vector<std::set<PetscInt>>    b = block_pattern(p);
  std::mt19937                       rng(seed);
  std::uniform_int_distribution<int> col(0, (int)p.mbs - 1), pct(0, 99);
  for (auto &row : b) {
    if (!row.empty() && pct(rng) < 30) row.erase(row.begin()); // drop a block
    if (pct(rng) < 50) row.insert(col(rng));                   // add a block
  }
  return expand(p.name + " (other pattern)", p.bs, b, seed);
}

PetscErrorCode preallocate(const Flavour *f, const Pattern &p, Mat *A)
{
  const std::vector<std::set<PetscInt>> b = block_pattern(p);
  std::vector<PetscInt>                 nnz(p.mbs);
  for (PetscInt I = 0; I < p.mbs; I++) nnz[I] = (PetscInt)b[I].size();

  PetscFunctionBeginUser;
  PetscCall(MatCreate(PETSC_COMM_SELF, A));
  PetscCall(MatSetSizes(*A, p.m(), p.m(), p.m(), p.m()));
  PetscCall(MatSetBlockSize(*A, p.bs));
  PetscCall(MatSetType(*A, f ? f->type : MATSEQAIJ));
  if (f && f->is_binbcsr()) {
    PetscCall(MatBinBCSRSetPrecision(*A, f->precision));
    if (f->bin_width) PetscCall(MatBinBCSRSetBinWidth(*A, f->bin_width));
  }
  PetscCall(MatXAIJSetPreallocation(*A, p.bs, nnz.data(), nullptr, nullptr, nullptr));
  PetscFunctionReturn(0);
}

PetscErrorCode fill(const Pattern &p, Mat A, InsertMode mode, PetscScalar factor)
{
  std::vector<PetscScalar> v(p.vals);
  for (auto &x : v) x *= factor;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < p.m(); i++) {
    const PetscInt s = p.rowptr[i], n = p.rowptr[i + 1] - s;
    PetscCall(MatSetValues(A, 1, &i, n, p.cols.data() + s, v.data() + s, mode));
  }
  PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

PetscErrorCode build(const Flavour *f, const Pattern &p, Mat *A)
{
  PetscFunctionBeginUser;
  PetscCall(preallocate(f, p, A));
  PetscCall(fill(p, *A, INSERT_VALUES));
  // Formats that can grow their pattern may do so (MatShift on a missing diagonal, ...): the
  // reference then shows what PETSc's own formats compute.
  if (!f || !f->fixed_pattern) PetscCall(MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  PetscFunctionReturn(0);
}

std::vector<double> row_abs_sums(Mat A)
{
  PetscInt m, n;
  REQUIRE(MatGetSize(A, &m, &n) == 0);
  std::vector<double> s(m, 0.0);
  bool                ok = true;
  for (PetscInt i = 0; i < m && ok; i++) {
    PetscInt           nc;
    const PetscInt    *c;
    const PetscScalar *v;
    ok = MatGetRow(A, i, &nc, &c, &v) == 0;
    if (!ok) break;
    for (PetscInt k = 0; k < nc; k++) s[i] += std::abs(v[k]);
    ok = MatRestoreRow(A, i, &nc, &c, &v) == 0;
  }
  REQUIRE(ok);
  return s;
}

static double ratio(double got, double want, double scale)
{
  const double d = std::abs(got - want);
  if (d == 0) return 0;
  if (std::isnan(d) || scale == 0) return std::numeric_limits<double>::infinity();
  return d / scale;
}

Mismatch compare(Mat got, Mat want, const std::vector<double> &scale)
{
  PetscInt m, n, mg, ng;
  REQUIRE(MatGetSize(want, &m, &n) == 0);
  REQUIRE(MatGetSize(got, &mg, &ng) == 0);
  REQUIRE(mg == m);
  REQUIRE(ng == n);
  REQUIRE((PetscInt)scale.size() == m);
  Mismatch              worst;
  std::vector<double>   g(n), w(n);
  std::vector<char>     touched(n, 0);
  std::vector<PetscInt> list;
  bool                  calls_ok = true, columns_ok = true; // one assertion per matrix, not per entry
  for (PetscInt i = 0; i < m && calls_ok && columns_ok; i++) {
    PetscInt           nc;
    const PetscInt    *c;
    const PetscScalar *v;
    list.clear();
    calls_ok = calls_ok && MatGetRow(got, i, &nc, &c, &v) == 0;
    if (!calls_ok) break;
    for (PetscInt k = 0; k < nc; k++) {
      if (c[k] < 0 || c[k] >= n) {
        columns_ok = false;
        break;
      }
      if (!touched[c[k]]) {
        touched[c[k]] = 1;
        list.push_back(c[k]);
        g[c[k]] = w[c[k]] = 0;
      }
      g[c[k]] += v[k];
    }
    calls_ok = calls_ok && MatRestoreRow(got, i, &nc, &c, &v) == 0;
    calls_ok = calls_ok && MatGetRow(want, i, &nc, &c, &v) == 0;
    if (!calls_ok) break;
    for (PetscInt k = 0; k < nc; k++) {
      if (!touched[c[k]]) {
        touched[c[k]] = 1;
        list.push_back(c[k]);
        g[c[k]] = w[c[k]] = 0;
      }
      w[c[k]] += v[k];
    }
    calls_ok = calls_ok && MatRestoreRow(want, i, &nc, &c, &v) == 0;
    for (PetscInt j : list) {
      const double r = ratio(g[j], w[j], scale[i]);
      if (r > worst.ratio || (std::isinf(r) && worst.row < 0)) worst = {r, i, j, g[j], w[j]};
      touched[j] = 0;
    }
  }
  REQUIRE(calls_ok);
  REQUIRE(columns_ok);
  return worst;
}

Mismatch compare(Vec got, Vec want, const std::vector<double> &tol)
{
  PetscInt n, ng;
  REQUIRE(VecGetSize(want, &n) == 0);
  REQUIRE(VecGetSize(got, &ng) == 0);
  REQUIRE(n == ng);
  const PetscScalar *g, *w;
  REQUIRE(VecGetArrayRead(got, &g) == 0);
  REQUIRE(VecGetArrayRead(want, &w) == 0);
  Mismatch worst;
  for (PetscInt i = 0; i < n; i++) {
    const double r = ratio(g[i], w[i], tol[i]);
    if (r > worst.ratio) worst = {r, i, 0, g[i], w[i]};
  }
  REQUIRE(VecRestoreArrayRead(got, &g) == 0);
  REQUIRE(VecRestoreArrayRead(want, &w) == 0);
  return worst;
}

std::vector<double> scaled(const std::vector<double> &v, double a)
{
  std::vector<double> r(v);
  for (auto &x : r) x *= std::abs(a);
  return r;
}

std::vector<double> plus(const std::vector<double> &a, const std::vector<double> &b)
{
  std::vector<double> r(a);
  for (size_t i = 0; i < r.size(); i++) r[i] += b[i];
  return r;
}

PetscErrorCode random_vec(PetscInt n, unsigned seed, Vec *v)
{
  std::mt19937                           rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PetscScalar                           *a;

  PetscFunctionBeginUser;
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, n, v));
  PetscCall(VecGetArray(*v, &a));
  for (PetscInt i = 0; i < n; i++) a[i] = u(rng);
  PetscCall(VecRestoreArray(*v, &a));
  PetscFunctionReturn(0);
}

} // namespace matops
