#include "sim/slab_gs.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace {

// x = M^-1 b for a 3x3 row-major M; false when M is singular (or not finite)
bool Invert3(const double *m, double *inv)
{
  const double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8],
               c02   = m[3] * m[7] - m[4] * m[6];
  const double det   = m[0] * c00 + m[1] * c01 + m[2] * c02;
  const double scale = std::max({std::abs(m[0]), std::abs(m[4]), std::abs(m[8])});
  if (!(std::abs(det) > 1e-14 * scale * scale * scale) || !std::isfinite(det)) return false;
  const double r = 1.0 / det;
  inv[0] = c00 * r, inv[1] = (m[2] * m[7] - m[1] * m[8]) * r, inv[2] = (m[1] * m[5] - m[2] * m[4]) * r;
  inv[3] = c01 * r, inv[4] = (m[0] * m[8] - m[2] * m[6]) * r, inv[5] = (m[2] * m[3] - m[0] * m[5]) * r;
  inv[6] = c02 * r, inv[7] = (m[1] * m[6] - m[0] * m[7]) * r, inv[8] = (m[0] * m[4] - m[1] * m[3]) * r;
  return true;
}

} // namespace

std::string SlabGSBuild(int n, std::vector<SlabGS::Entry> entries, bool column_major_source, SlabGS *gs)
{
  constexpr int L = SlabGS::lanes;
  SlabGS        g;
  g.n     = n;
  g.steps = (n + L - 1) / L;
  // rows' off-diagonal entries, in the order given
  std::vector<int> count(n, 0);
  for (const SlabGS::Entry &e : entries) {
    if (e.row < 0 || e.row >= n || e.col < 0 || e.col >= n) return "an entry outside the level";
    if (e.row == e.col) continue;
    if (std::abs(e.row - e.col) >= g.steps)
      return "row " + std::to_string(e.row) + " is coupled to row " + std::to_string(e.col) +
             ", a slab or more away";
    count[e.row]++;
  }
  g.step_start.assign(g.steps + 1, 0);
  for (int j = 0; j < g.steps; ++j) {
    int len = 0;
    for (int l = 0; l < L; ++l)
      if (l * g.steps + j < n) len = std::max(len, count[l * g.steps + j]);
    g.step_start[j + 1] = g.step_start[j] + len;
  }
  const long groups = g.step_start[g.steps];
  g.col.assign(groups * L, 0);
  g.val.assign(groups * 9 * L, 0.0f);
  std::vector<int> next(n, 0);
  for (const SlabGS::Entry &e : entries) {
    const int flip = e.transposed != column_major_source;
    if (e.row == e.col) {
      g.diagonal_copies[flip].push_back({e.source, e.row});
      continue;
    }
    const int  step = e.row % g.steps, lane = e.row / g.steps;
    const long s = (long)(g.step_start[step] + next[e.row]++) * L + lane;
    g.col[s]     = e.col;
    g.copies[flip].push_back({e.source, (s / L) * 9 * L + lane});
  }
  g.diag.assign(9 * (size_t)n, 0.0);
  g.dinv.assign(9 * (size_t)g.steps * L, 0.0);
  *gs = std::move(g);
  return "";
}

PetscErrorCode SlabGSRefill(SlabGS *gs, const PetscScalar *blocks)
{
  constexpr int L = SlabGS::lanes;

  PetscFunctionBegin;
  std::fill(gs->diag.begin(), gs->diag.end(), 0.0);
  for (int flip = 0; flip < 2; ++flip) { // entry e = 3 i + j of the block, read at e or at 3 j + i
    for (const SlabGS::Copy &c : gs->copies[flip]) {
      const PetscScalar *b = blocks + 9 * c.source;
      float             *v = gs->val.data() + c.dest;
      for (int e = 0; e < 9; ++e) v[e * L] = (float)b[flip ? 3 * (e % 3) + e / 3 : e];
    }
    for (const SlabGS::Copy &c : gs->diagonal_copies[flip]) {
      const PetscScalar *b = blocks + 9 * c.source;
      double            *d = gs->diag.data() + 9 * c.dest;
      for (int e = 0; e < 9; ++e) d[e] += b[flip ? 3 * (e % 3) + e / 3 : e];
    }
  }
  for (int r = 0; r < gs->n; ++r) {
    double inv[9];
    PetscCheck(Invert3(&gs->diag[9 * (size_t)r], inv), PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT,
               "slab Gauss-Seidel: the diagonal block of block row %d is singular", r);
    const int step = r % gs->steps, lane = r / gs->steps;
    for (int e = 0; e < 9; ++e) gs->dinv[((size_t)step * 9 + e) * L + lane] = inv[e];
  }
  PetscFunctionReturn(0);
}

// One build per instruction set, picked by the CPU at load time (GCC's target_clones): the lane loop
// is a vector of 8 with gathers of x where the CPU has them; the library's baseline (x86-64-v2) has no
// gathers, and there the lanes ran at a third of the speed of binbcsr's own SOR.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("default", "avx2", "avx512f")))
#endif
void SlabGSSweep(const SlabGS &gs, const double *b, double *x, bool forward)
{
  constexpr int L = SlabGS::lanes;
  const int     S = gs.steps;
  for (int q = 0; q < S; ++q) {
    const int j = forward ? q : S - 1 - q;
    double    a0[L], a1[L], a2[L];
#pragma omp simd
    for (int l = 0; l < L; ++l) {
      const int r = l * S + j;
      a0[l]       = r < gs.n ? b[3 * r] : 0.0;
      a1[l]       = r < gs.n ? b[3 * r + 1] : 0.0;
      a2[l]       = r < gs.n ? b[3 * r + 2] : 0.0;
    }
    // b_r minus the row's off-diagonal blocks times the newest x: the lanes' rows are not coupled to
    // each other, so none of them reads an x another lane writes in this step
    for (int g = gs.step_start[j]; g < gs.step_start[j + 1]; ++g) {
      const int   *c = gs.col.data() + (size_t)g * L;
      const float *v = gs.val.data() + (size_t)g * 9 * L;
#pragma omp simd
      for (int l = 0; l < L; ++l) {
        const double x0 = x[3 * c[l]], x1 = x[3 * c[l] + 1], x2 = x[3 * c[l] + 2];
        a0[l] -= (double)v[0 * L + l] * x0 + (double)v[1 * L + l] * x1 + (double)v[2 * L + l] * x2;
        a1[l] -= (double)v[3 * L + l] * x0 + (double)v[4 * L + l] * x1 + (double)v[5 * L + l] * x2;
        a2[l] -= (double)v[6 * L + l] * x0 + (double)v[7 * L + l] * x1 + (double)v[8 * L + l] * x2;
      }
    }
    const double *d = gs.dinv.data() + (size_t)j * 9 * L;
    for (int l = 0; l < L; ++l) {
      const int r = l * S + j;
      if (r >= gs.n) continue;
      for (int i = 0; i < 3; ++i)
        x[3 * r + i] =
          d[(3 * i) * L + l] * a0[l] + d[(3 * i + 1) * L + l] * a1[l] + d[(3 * i + 2) * L + l] * a2[l];
    }
  }
}

#if defined(__GNUC__) && defined(__x86_64__)
  #include <immintrin.h>
// The same sweep in AVX-512: one register of 8 lanes per component, x of the lanes' columns gathered,
// the new x scattered (the lanes' rows are distinct), b gathered. GCC vectorised the portable loop
// with 256-bit halves and no gathers (3 x 8 scalar loads per slot group).
__attribute__((target("avx512f,avx512vl"))) static void SweepAVX512(const SlabGS &gs, const double *b,
                                                                    double *x, bool forward)
{
  constexpr int L     = SlabGS::lanes;
  const int     S     = gs.steps;
  const __m256i iota  = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i rows0 = _mm256_mullo_epi32(iota, _mm256_set1_epi32(S));
  for (int q = 0; q < S; ++q) {
    const int      j    = forward ? q : S - 1 - q;
    const __m256i  rows = _mm256_add_epi32(rows0, _mm256_set1_epi32(j));
    const __mmask8 real = _mm256_cmplt_epi32_mask(rows, _mm256_set1_epi32(gs.n));
    const __m256i  o    = _mm256_add_epi32(rows, _mm256_add_epi32(rows, rows)); /* 3 r */
    __m512d        a0   = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, o, b, 8);
    __m512d        a1   = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, o, b + 1, 8);
    __m512d        a2   = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, o, b + 2, 8);
    for (int g = gs.step_start[j]; g < gs.step_start[j + 1]; ++g) {
      const float  *v  = gs.val.data() + (size_t)g * 9 * L;
      const __m256i c  = _mm256_loadu_si256((const __m256i *)(gs.col.data() + (size_t)g * L));
      const __m256i oc = _mm256_add_epi32(c, _mm256_add_epi32(c, c));
      const __m512d x0 = _mm512_i32gather_pd(oc, x, 8), x1 = _mm512_i32gather_pd(oc, x + 1, 8),
                    x2 = _mm512_i32gather_pd(oc, x + 2, 8);
      a0               = _mm512_fnmadd_pd(
                      _mm512_cvtps_pd(_mm256_loadu_ps(v + 2 * L)), x2,
                      _mm512_fnmadd_pd(_mm512_cvtps_pd(_mm256_loadu_ps(v + 1 * L)), x1,
                                       _mm512_fnmadd_pd(_mm512_cvtps_pd(_mm256_loadu_ps(v + 0 * L)), x0, a0)));
      a1 = _mm512_fnmadd_pd(
        _mm512_cvtps_pd(_mm256_loadu_ps(v + 5 * L)), x2,
        _mm512_fnmadd_pd(_mm512_cvtps_pd(_mm256_loadu_ps(v + 4 * L)), x1,
                         _mm512_fnmadd_pd(_mm512_cvtps_pd(_mm256_loadu_ps(v + 3 * L)), x0, a1)));
      a2 = _mm512_fnmadd_pd(
        _mm512_cvtps_pd(_mm256_loadu_ps(v + 8 * L)), x2,
        _mm512_fnmadd_pd(_mm512_cvtps_pd(_mm256_loadu_ps(v + 7 * L)), x1,
                         _mm512_fnmadd_pd(_mm512_cvtps_pd(_mm256_loadu_ps(v + 6 * L)), x0, a2)));
    }
    const double *d  = gs.dinv.data() + (size_t)j * 9 * L;
    const __m512d y0 = _mm512_fmadd_pd(
      _mm512_loadu_pd(d + 2 * L), a2,
      _mm512_fmadd_pd(_mm512_loadu_pd(d + 1 * L), a1, _mm512_mul_pd(_mm512_loadu_pd(d + 0 * L), a0)));
    const __m512d y1 = _mm512_fmadd_pd(
      _mm512_loadu_pd(d + 5 * L), a2,
      _mm512_fmadd_pd(_mm512_loadu_pd(d + 4 * L), a1, _mm512_mul_pd(_mm512_loadu_pd(d + 3 * L), a0)));
    const __m512d y2 = _mm512_fmadd_pd(
      _mm512_loadu_pd(d + 8 * L), a2,
      _mm512_fmadd_pd(_mm512_loadu_pd(d + 7 * L), a1, _mm512_mul_pd(_mm512_loadu_pd(d + 6 * L), a0)));
    _mm512_mask_i32scatter_pd(x, real, o, y0, 8);
    _mm512_mask_i32scatter_pd(x + 1, real, o, y1, 8);
    _mm512_mask_i32scatter_pd(x + 2, real, o, y2, 8);
  }
}
#endif

void SlabGSSweepBest(const SlabGS &gs, const double *b, double *x, bool forward)
{
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  if (avx512 && 3L * gs.n < (1L << 31)) return SweepAVX512(gs, b, x, forward);
#endif
  SlabGSSweep(gs, b, x, forward);
}

namespace {

PetscErrorCode SymmetricSweeps(SlabGS *gs, Vec b, Vec x, PetscInt its, PetscBool zero_guess)
{
  const PetscScalar *ba;
  PetscScalar       *xa;

  PetscFunctionBegin;
  if (zero_guess) PetscCall(VecSet(x, 0.0));
  PetscCall(VecGetArrayRead(b, &ba));
  PetscCall(VecGetArray(x, &xa));
  for (PetscInt k = 0; k < its; ++k) {
    SlabGSSweepBest(*gs, ba, xa, true);
    SlabGSSweepBest(*gs, ba, xa, false);
  }
  PetscCall(VecRestoreArray(x, &xa));
  PetscCall(VecRestoreArrayRead(b, &ba));
  // two passes over the off-diagonal blocks and the diagonal solves
  PetscCall(PetscLogFlops(its * 2.0 * (18.0 * (double)gs->val.size() / 9 + 15.0 * gs->n)));
  PetscFunctionReturn(0);
}

PetscErrorCode ApplyRichardson(PC pc, Vec b, Vec x, Vec, PetscReal, PetscReal, PetscReal, PetscInt its,
                               PetscBool zero_guess, PetscInt *outits, PCRichardsonConvergedReason *reason)
{
  SlabGS *gs;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &gs));
  PetscCall(SymmetricSweeps(gs, b, x, its, zero_guess));
  *outits = its;
  *reason = PCRICHARDSON_CONVERGED_ITS;
  PetscFunctionReturn(0);
}

PetscErrorCode Apply(PC pc, Vec b, Vec x)
{
  SlabGS *gs;

  PetscFunctionBegin;
  PetscCall(PCShellGetContext(pc, &gs));
  PetscCall(SymmetricSweeps(gs, b, x, 1, PETSC_TRUE));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode SlabGSSetPC(PC pc, SlabGS *gs)
{
  PetscFunctionBegin;
  PetscCall(PCSetType(pc, PCSHELL));
  PetscCall(PCShellSetContext(pc, gs));
  PetscCall(PCShellSetApply(pc, Apply));
  PetscCall(PCShellSetApplyRichardson(pc, ApplyRichardson));
  PetscCall(PCShellSetName(pc, "slab Gauss-Seidel (symmetric sweep, 8 rows side by side)"));
  PetscFunctionReturn(0);
}
