// Slab Gauss-Seidel (slab_gs.h): the lane layout built from a level's blocks, its refill, and the
// passes over it (the lane-by-lane definition and the AVX-512 body); the PETSc side is slab_gs_pc.cpp.
#include "sim/slab_gs.h"
#include "sim/slab_gs_lanes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

namespace slab_gs_detail {

PetscLogEvent SLAB_Refill = 0, SLAB_Smooth = 0, SLAB_Residual = 0;

PetscErrorCode SlabGSRegisterEvents()
{
  static PetscClassId classid = 0;
  PetscFunctionBegin;
  if (classid) PetscFunctionReturn(0);
  PetscCall(PetscClassIdRegister("SlabGS", &classid));
  PetscCall(PetscLogEventRegister("SlabGSRefill", classid, &SLAB_Refill));
  PetscCall(PetscLogEventRegister("SlabGSSmooth", classid, &SLAB_Smooth));
  PetscCall(PetscLogEventRegister("SlabGSResidual", classid, &SLAB_Residual));
  PetscFunctionReturn(0);
}

} // namespace slab_gs_detail

using namespace slab_gs_detail;

std::string SlabGSBuild(int n, std::vector<SlabGS::Entry> entries, bool column_major_source, SlabGS *gs)
{
  constexpr int L = SlabGS::lanes;
  SlabGS        g;
  g.n         = n;
  g.steps     = (n + L - 1) / L;
  const int S = g.steps;
  // each row's off-diagonal entries as (offset c - r, how many of that offset came before, entry)
  std::vector<std::vector<std::array<long, 3>>> row_entries(n);
  for (size_t k = 0; k < entries.size(); ++k) {
    const SlabGS::Entry &e = entries[k];
    if (e.row < 0 || e.row >= n || e.col < 0 || e.col >= n) return "an entry outside the level";
    const int flip = e.transposed != column_major_source;
    if (e.row == e.col) {
      g.diagonal_copies.push_back({e.source, (long)(e.row % S) * 9 * L + e.row / S, flip == 1});
      continue;
    }
    if (std::abs(e.row - e.col) >= S)
      return "row " + std::to_string(e.row) + " is coupled to row " + std::to_string(e.col) +
             ", a slab or more away";
    // upper storage in the sweep's order: a row keeps its blocks toward rows of later steps; a block
    // toward an earlier step is the transpose of one its column's row keeps (the level is symmetric)
    if (e.col % S > e.row % S) row_entries[e.row].push_back({e.col - e.row, 0, (long)k});
  }
  for (auto &list : row_entries) { // a repeated (row, col) gets a group of its own: (offset, repeat)
    std::sort(list.begin(), list.end());
    for (size_t q = 1; q < list.size(); ++q)
      if (list[q][0] == list[q - 1][0]) list[q][1] = list[q - 1][1] + 1;
  }
  // Step j's groups: one per (offset, repeat) any of its lanes has, in that order, so that lanes whose
  // rows have the same neighbours (the grid away from its edges) meet them in the same group.
  g.step_start.assign(S + 1, 0);
  for (int j = 0; j < S; ++j) {
    std::vector<std::array<long, 2>> keys;
    for (int l = 0; l < L && l * S + j < n; ++l)
      for (const auto &e : row_entries[l * S + j]) keys.push_back({e[0], e[1]});
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    g.step_start[j + 1] = g.step_start[j] + (int)keys.size();
    for (const auto &key : keys) {
      const long group = (long)g.xidx.size() / L;
      int        shift = 0, shifts = 0;
      bool       same  = true;
      unsigned   lanes = 0;
      for (int l = 0; l < L; ++l) {
        const int r = l * S + j;
        int       c = r < n ? r : 0; // padding: the lane's own row (or row 0), zero block
        if (r < n) {
          const auto &list = row_entries[r];
          const auto  it = std::lower_bound(list.begin(), list.end(), std::array<long, 3>{key[0], key[1], 0});
          if (it != list.end() && (*it)[0] == key[0] && (*it)[1] == key[1]) {
            const SlabGS::Entry &e = entries[(*it)[2]];
            c                      = e.col;
            lanes |= 1u << l;
            g.copies.push_back({e.source, group * 9 * L + l, e.transposed != column_major_source});
            const int s = LaneIndex(c, S) - l;
            if (shifts++ == 0) shift = s;
            same &= s == shift;
          }
        }
        g.xidx.push_back(LaneIndex(c, S));
      }
      g.base.push_back(same && shifts > 0 ? shift : -1);
      g.real.push_back((unsigned char)lanes);
    }
  }
  // The refill reads the source blocks in their order, both places of a mirrored block one after the
  // other: 4.8 against 6.3 ms per step for the cloth's levels in the layout's order, where it read the
  // sources at random and waited on the loads (stores scattered over a group's lanes cost less).
  std::sort(g.copies.begin(), g.copies.end(), [](const SlabGS::Copy &a, const SlabGS::Copy &b) {
    return a.source != b.source ? a.source < b.source : a.flip < b.flip;
  });
  g.val.assign(g.xidx.size() * 9, 0.0f);
  g.dinv.assign(9 * (size_t)S * L, 0.0);
  g.dl.assign(g.dinv.size(), 0.0);
  g.xl.assign((size_t)(3 * S + 2) * L, 0.0);
  g.bl.assign(g.xl.size(), 0.0);
  g.rl.assign(g.xl.size(), 0.0);
  g.ll.assign(g.xl.size(), 0.0);
  g.column_major = column_major_source;
  *gs            = std::move(g);
  return "";
}

void SlabGSSetHalo(SlabGS *gs, std::vector<SlabGS::HaloEntry> halo, std::vector<PetscInt> ghost_nodes)
{
  std::sort(halo.begin(), halo.end(),
            [](const SlabGS::HaloEntry &a, const SlabGS::HaloEntry &b) { return a.source < b.source; });
  gs->distributed = true;
  gs->halo        = std::move(halo);
  gs->ghost_nodes = std::move(ghost_nodes);
  gs->halo_val.assign(9 * gs->halo.size(), 0.0);
  gs->halo_scatter.reset();
}

PetscErrorCode SlabGSRefill(SlabGS *gs, const PetscScalar *blocks)
{
  constexpr int L = SlabGS::lanes;

  PetscFunctionBegin;
  PetscCall(SlabGSRegisterEvents());
  PetscCall(PetscLogEventBegin(SLAB_Refill, 0, 0, 0, 0));
  std::fill(gs->dl.begin(), gs->dl.end(), 0.0);
  for (size_t k = 0; k < gs->halo.size(); ++k) { // row-major
    const PetscScalar *b    = blocks + 9 * gs->halo[k].source;
    const bool         flip = gs->halo[k].transposed != gs->column_major;
    for (int e = 0; e < 9; ++e) gs->halo_val[9 * k + e] = flip ? b[3 * (e % 3) + e / 3] : b[e];
  }
  // entry e = 3 i + j of a block, read at e or (flip) at 3 j + i
  for (const SlabGS::Copy &c : gs->copies) {
    const PetscScalar *b = blocks + 9 * c.source;
    float             *v = gs->val.data() + c.dest;
    if (c.flip)
      for (int e = 0; e < 9; ++e) v[e * L] = (float)b[3 * (e % 3) + e / 3];
    else
      for (int e = 0; e < 9; ++e) v[e * L] = (float)b[e];
  }
  for (const SlabGS::Copy &c : gs->diagonal_copies) {
    const PetscScalar *b = blocks + 9 * c.source;
    double            *d = gs->dl.data() + c.dest;
    for (int e = 0; e < 9; ++e) d[e * L] += b[c.flip ? 3 * (e % 3) + e / 3 : e];
  }
  // the inverses, 8 lanes (rows) at a time in the layout's order: the adjugate over the determinant (PETSc's
  // pivoting 3x3 kernel row by row took a third of the refill: cloth.opts 1.3 of 4 ms per step on one
  // rank). A block whose determinant is zero, or whose inverse is not finite (a NaN or Inf in it), is
  // refused; padding lanes (zero blocks) get zero inverses.
  for (int j = 0; j < gs->steps; ++j) {
    const double *a = gs->dl.data() + (size_t)j * 9 * L;
    double       *v = gs->dinv.data() + (size_t)j * 9 * L;
    double        bad[L];
#pragma omp simd
    for (int l = 0; l < L; ++l) {
      const double a0 = a[0 * L + l], a1 = a[1 * L + l], a2 = a[2 * L + l], a3 = a[3 * L + l],
                   a4 = a[4 * L + l], a5 = a[5 * L + l], a6 = a[6 * L + l], a7 = a[7 * L + l],
                   a8 = a[8 * L + l];
      const double c0 = a4 * a8 - a5 * a7, c1 = a5 * a6 - a3 * a8, c2 = a3 * a7 - a4 * a6;
      const double det = a0 * c0 + a1 * c1 + a2 * c2, d = det != 0 ? 1.0 / det : 0.0;
      v[0 * L + l] = c0 * d;
      v[1 * L + l] = (a2 * a7 - a1 * a8) * d;
      v[2 * L + l] = (a1 * a5 - a2 * a4) * d;
      v[3 * L + l] = c1 * d;
      v[4 * L + l] = (a0 * a8 - a2 * a6) * d;
      v[5 * L + l] = (a2 * a3 - a0 * a5) * d;
      v[6 * L + l] = c2 * d;
      v[7 * L + l] = (a1 * a6 - a0 * a7) * d;
      v[8 * L + l] = (a0 * a4 - a1 * a3) * d;
      double sum   = d; // NaN or Inf anywhere in the inverse shows in the sum
      for (int e = 0; e < 9; ++e) sum += v[e * L + l];
      bad[l] = det == 0 || !(sum - sum == 0) ? 1.0 : 0.0;
    }
    for (int l = 0; l < L; ++l) {
      const int r = l * gs->steps + j;
      PetscCheck(r >= gs->n || bad[l] == 0, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT,
                 "slab Gauss-Seidel: the diagonal block of block row %d is singular or not finite", r);
    }
  }
  PetscCall(PetscLogEventEnd(SLAB_Refill, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

namespace slab_gs_detail {

// v (3 n values, row by row) into / out of the lane layout lv (padding lanes stay zero): lane l of step j
// is row l S + j. The layout is written (read) in its order, from (into) the 8 slabs as 8 streams: a
// slab at a time, every write of one slab lands on its own cache line, 8 times over the whole layout.
void ToLanes(const SlabGS &gs, const double *v, std::vector<double> &lv)
{
  constexpr int L = SlabGS::lanes;
  const int     S = gs.steps;
  double       *o = lv.data() + L;
  for (int j = 0; j < S; ++j, o += 3 * L)
    for (int l = 0; l < L; ++l) {
      const int     r  = l * S + j;
      const double *s  = v + 3 * (size_t)r;
      const bool    in = r < gs.n;
      o[l]             = in ? s[0] : 0.0;
      o[L + l]         = in ? s[1] : 0.0;
      o[2 * L + l]     = in ? s[2] : 0.0;
    }
}

void FromLanes(const SlabGS &gs, const std::vector<double> &lv, double *v)
{
  constexpr int L = SlabGS::lanes;
  const int     S = gs.steps;
  const double *o = lv.data() + L;
  for (int j = 0; j < S; ++j, o += 3 * L)
    for (int l = 0; l < L && l * S + j < gs.n; ++l) {
      double *d = v + 3 * (size_t)(l * S + j);
      d[0] = o[l], d[1] = o[L + l], d[2] = o[2 * L + l];
    }
}

} // namespace slab_gs_detail

namespace {

// One pass in the lane layout, lane by lane: the definition.
void PassLanes(const SlabGS &gs, const double *b, double *x, double *lower, double *r, PassMode mode)
{
  constexpr int L      = SlabGS::lanes;
  const int     S      = gs.steps;
  const bool    pushes = mode != kBackward, products = mode != kForwardZero && mode != kLower;
  if (pushes) std::fill(lower, lower + (size_t)(3 * S + 2) * L, 0.0);
  for (int q = 0; q < S; ++q) {
    const int j = mode == kBackward ? S - 1 - q : q;
    double    a[3][L];
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < L; ++l) a[i][l] = b[L + (3 * j + i) * L + l] - lower[L + (3 * j + i) * L + l];
    // minus the row's U blocks times x: the lanes' rows are not coupled to each other, so none of
    // them reads an x another lane writes in this step
    if (products)
      for (int g = gs.step_start[j]; g < gs.step_start[j + 1]; ++g) {
        const int   *c = gs.xidx.data() + (size_t)g * L;
        const float *v = gs.val.data() + (size_t)g * 9 * L;
        for (int l = 0; l < L; ++l)
          for (int i = 0; i < 3; ++i)
            a[i][l] -= (double)v[(3 * i) * L + l] * x[c[l]] + (double)v[(3 * i + 1) * L + l] * x[c[l] + L] +
                       (double)v[(3 * i + 2) * L + l] * x[c[l] + 2 * L];
      }
    double *xj = x + L + 3 * j * L;
    if (mode == kResidual) {
      const double *d = gs.dl.data() + (size_t)j * 9 * L;
      for (int i = 0; i < 3; ++i)
        for (int l = 0; l < L; ++l)
          r[L + (3 * j + i) * L + l] =
            a[i][l] - (d[(3 * i) * L + l] * xj[l] + d[(3 * i + 1) * L + l] * xj[L + l] +
                       d[(3 * i + 2) * L + l] * xj[2 * L + l]);
    } else if (mode != kLower) {
      const double *d = gs.dinv.data() + (size_t)j * 9 * L;
      for (int i = 0; i < 3; ++i)
        for (int l = 0; l < L; ++l)
          xj[i * L + l] = d[(3 * i) * L + l] * a[0][l] + d[(3 * i + 1) * L + l] * a[1][l] +
                          d[(3 * i + 2) * L + l] * a[2][l];
    }
    if (pushes)
      for (int g = gs.step_start[j]; g < gs.step_start[j + 1]; ++g) {
        const int   *c = gs.xidx.data() + (size_t)g * L;
        const float *v = gs.val.data() + (size_t)g * 9 * L;
        for (int l = 0; l < L; ++l) {
          if (!(gs.real[g] >> l & 1)) continue;
          for (int k = 0; k < 3; ++k) // (A_rc^T x_r)_k
            lower[c[l] + k * L] += (double)v[k * L + l] * xj[l] + (double)v[(3 + k) * L + l] * xj[L + l] +
                                   (double)v[(6 + k) * L + l] * xj[2 * L + l];
        }
      }
  }
}

} // namespace

#if defined(__GNUC__) && defined(__x86_64__)
  #include <immintrin.h>
// The same passes in AVX-512, one register of 8 lanes per component: x of a group (and its pushes) by
// plain masked loads and stores where its lanes read the same offset (base), else gathered (scattered:
// a group's lanes read one offset from 8 different rows, so their columns differ and the scatters of
// the pushes never collide). Gathers of x in the rows' own order, and the new x
// scattered back, took 1.4-1.9 ms per symmetric sweep of the cloth's fine level.
__attribute__((target("avx512f,avx512vl"))) static void
PassLanesAVX512(const SlabGS &gs, const double *b, double *x, double *lower, double *r, PassMode mode)
{
  constexpr int L      = SlabGS::lanes;
  const int     S      = gs.steps;
  const bool    pushes = mode != kBackward, products = mode != kForwardZero && mode != kLower;
  if (pushes) std::fill(lower, lower + (size_t)(3 * S + 2) * L, 0.0);
  #define SLAB_W(e) _mm512_cvtps_pd(_mm256_loadu_ps(v + (e)*L))
  #define SLAB_D(e) _mm512_loadu_pd(d + (e)*L)
  for (int q = 0; q < S; ++q) {
    const int j  = mode == kBackward ? S - 1 - q : q;
    double   *xj = x + L + 3 * j * L;
    __m512d   a0 =
      _mm512_sub_pd(_mm512_loadu_pd(b + L + (3 * j) * L), _mm512_loadu_pd(lower + L + (3 * j) * L));
    __m512d a1 =
      _mm512_sub_pd(_mm512_loadu_pd(b + L + (3 * j + 1) * L), _mm512_loadu_pd(lower + L + (3 * j + 1) * L));
    __m512d a2 =
      _mm512_sub_pd(_mm512_loadu_pd(b + L + (3 * j + 2) * L), _mm512_loadu_pd(lower + L + (3 * j + 2) * L));
    if (products)
      for (int g = gs.step_start[j]; g < gs.step_start[j + 1]; ++g) {
        const float   *v    = gs.val.data() + (size_t)g * 9 * L;
        const __mmask8 real = gs.real[g];
        __m512d        x0, x1, x2;
        if (gs.base[g] >= 0) {
          const double *xs = x + gs.base[g];
          x0               = _mm512_maskz_loadu_pd(real, xs);
          x1               = _mm512_maskz_loadu_pd(real, xs + L);
          x2               = _mm512_maskz_loadu_pd(real, xs + 2 * L);
        } else {
          const __m256i c = _mm256_loadu_si256((const __m256i *)(gs.xidx.data() + (size_t)g * L));
          x0              = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, c, x, 8);
          x1              = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, c, x + L, 8);
          x2              = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, c, x + 2 * L, 8);
        }
        // a_i -= (block row i) x_c as one subtraction: the products of a group do not wait for the
        // accumulator, which would make the step a chain of 3 dependent FMAs per group
        a0 = _mm512_sub_pd(
          a0, _mm512_fmadd_pd(SLAB_W(2), x2, _mm512_fmadd_pd(SLAB_W(1), x1, _mm512_mul_pd(SLAB_W(0), x0))));
        a1 = _mm512_sub_pd(
          a1, _mm512_fmadd_pd(SLAB_W(5), x2, _mm512_fmadd_pd(SLAB_W(4), x1, _mm512_mul_pd(SLAB_W(3), x0))));
        a2 = _mm512_sub_pd(
          a2, _mm512_fmadd_pd(SLAB_W(8), x2, _mm512_fmadd_pd(SLAB_W(7), x1, _mm512_mul_pd(SLAB_W(6), x0))));
      }
    __m512d y0, y1, y2;
    if (mode == kResidual || mode == kLower) {
      y0 = _mm512_loadu_pd(xj), y1 = _mm512_loadu_pd(xj + L), y2 = _mm512_loadu_pd(xj + 2 * L);
      if (mode == kResidual) {
        const double *d = gs.dl.data() + (size_t)j * 9 * L;
        _mm512_storeu_pd(
          r + L + (3 * j) * L,
          _mm512_sub_pd(a0, _mm512_fmadd_pd(SLAB_D(2), y2,
                                            _mm512_fmadd_pd(SLAB_D(1), y1, _mm512_mul_pd(SLAB_D(0), y0)))));
        _mm512_storeu_pd(
          r + L + (3 * j + 1) * L,
          _mm512_sub_pd(a1, _mm512_fmadd_pd(SLAB_D(5), y2,
                                            _mm512_fmadd_pd(SLAB_D(4), y1, _mm512_mul_pd(SLAB_D(3), y0)))));
        _mm512_storeu_pd(
          r + L + (3 * j + 2) * L,
          _mm512_sub_pd(a2, _mm512_fmadd_pd(SLAB_D(8), y2,
                                            _mm512_fmadd_pd(SLAB_D(7), y1, _mm512_mul_pd(SLAB_D(6), y0)))));
      }
    } else {
      const double *d = gs.dinv.data() + (size_t)j * 9 * L;
      y0 = _mm512_fmadd_pd(SLAB_D(2), a2, _mm512_fmadd_pd(SLAB_D(1), a1, _mm512_mul_pd(SLAB_D(0), a0)));
      y1 = _mm512_fmadd_pd(SLAB_D(5), a2, _mm512_fmadd_pd(SLAB_D(4), a1, _mm512_mul_pd(SLAB_D(3), a0)));
      y2 = _mm512_fmadd_pd(SLAB_D(8), a2, _mm512_fmadd_pd(SLAB_D(7), a1, _mm512_mul_pd(SLAB_D(6), a0)));
      _mm512_storeu_pd(xj, y0);
      _mm512_storeu_pd(xj + L, y1);
      _mm512_storeu_pd(xj + 2 * L, y2);
    }
    if (pushes)
      for (int g = gs.step_start[j]; g < gs.step_start[j + 1]; ++g) {
        const float   *v    = gs.val.data() + (size_t)g * 9 * L;
        const __mmask8 real = gs.real[g];
        // (A_rc^T x_r)_k = sum_i A(i, k) x_r(i)
        const __m512d t0 =
          _mm512_fmadd_pd(SLAB_W(6), y2, _mm512_fmadd_pd(SLAB_W(3), y1, _mm512_mul_pd(SLAB_W(0), y0)));
        const __m512d t1 =
          _mm512_fmadd_pd(SLAB_W(7), y2, _mm512_fmadd_pd(SLAB_W(4), y1, _mm512_mul_pd(SLAB_W(1), y0)));
        const __m512d t2 =
          _mm512_fmadd_pd(SLAB_W(8), y2, _mm512_fmadd_pd(SLAB_W(5), y1, _mm512_mul_pd(SLAB_W(2), y0)));
        if (gs.base[g] >= 0) {
          double *ls = lower + gs.base[g];
          _mm512_mask_storeu_pd(ls, real, _mm512_add_pd(_mm512_maskz_loadu_pd(real, ls), t0));
          _mm512_mask_storeu_pd(ls + L, real, _mm512_add_pd(_mm512_maskz_loadu_pd(real, ls + L), t1));
          _mm512_mask_storeu_pd(ls + 2 * L, real, _mm512_add_pd(_mm512_maskz_loadu_pd(real, ls + 2 * L), t2));
        } else {
          const __m256i c = _mm256_loadu_si256((const __m256i *)(gs.xidx.data() + (size_t)g * L));
          _mm512_mask_i32scatter_pd(
            lower, real, c,
            _mm512_add_pd(_mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, c, lower, 8), t0), 8);
          _mm512_mask_i32scatter_pd(
            lower + L, real, c,
            _mm512_add_pd(_mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, c, lower + L, 8), t1), 8);
          _mm512_mask_i32scatter_pd(
            lower + 2 * L, real, c,
            _mm512_add_pd(_mm512_mask_i32gather_pd(_mm512_setzero_pd(), real, c, lower + 2 * L, 8), t2), 8);
        }
      }
  }
  #undef SLAB_W
  #undef SLAB_D
}
#endif

namespace slab_gs_detail {

PassBody BestBody()
{
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  if (avx512) return PassLanesAVX512;
#endif
  return PassLanes;
}

} // namespace slab_gs_detail

namespace {

// one sweep from x, row by row in and out (a backward one first takes L x for the x it starts from)
void SweepWith(PassBody body, SlabGS &gs, const double *b, double *x, bool forward)
{
  gs.held_b = gs.held_x = SlabGS::Held();
  ToLanes(gs, b, gs.bl);
  ToLanes(gs, x, gs.xl);
  if (!forward) body(gs, gs.bl.data(), gs.xl.data(), gs.ll.data(), nullptr, kLower);
  body(gs, gs.bl.data(), gs.xl.data(), gs.ll.data(), nullptr, forward ? kForward : kBackward);
  FromLanes(gs, gs.xl, x);
}

} // namespace

void SlabGSSweep(SlabGS &gs, const double *b, double *x, bool forward)
{
  SweepWith(PassLanes, gs, b, x, forward);
}

void SlabGSSweepBest(SlabGS &gs, const double *b, double *x, bool forward)
{
  SweepWith(BestBody(), gs, b, x, forward);
}

void SlabGSResidual(SlabGS &gs, const double *b, const double *x, double *r, bool best)
{
  gs.held_b = gs.held_x = SlabGS::Held();
  ToLanes(gs, b, gs.bl);
  ToLanes(gs, x, gs.xl);
  (best ? BestBody() : PassLanes)(gs, gs.bl.data(), gs.xl.data(), gs.ll.data(), gs.rl.data(), kResidual);
  FromLanes(gs, gs.rl, r);
}
