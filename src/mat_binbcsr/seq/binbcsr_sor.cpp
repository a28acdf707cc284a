/* MatSOR for MATSEQBINBCSR: SOR / Gauss-Seidel sweeps, pointwise for bs 1 and by blocks for bs > 1
   (the diagonal block is inverted exactly, as in PETSc's BAIJ), so PCSOR (SSOR with
   -pc_sor_symmetric, a symmetric preconditioner for CG), multigrid smoothers and block Jacobi with
   -sub_pc_type sor work on this type.

   One row update: x_r = (1 - omega) x_r + omega (D_r + shift I)^-1 (b_r - sum_{c != r} A_rc x_c) with the
   newest x (SOR on A + shift I, as PETSc's AIJ defines the shift). The row products reuse the per-slot
   kernels of MatMult (slot_mult, and slot_mult_transpose for the lower triangle that upper-triangle
   storage keeps in other rows, pushed from those rows: sweep_upper_storage). Sweeps are sequential
   over rows by nature: they walk the bin layout one lane at a time and do not get the SIMD speed of
   MatMult.

   PCEISENSTAT's operations as well: SOR_EISENSTAT applies (L + E)^-1 A (U + E)^-1, E = (D + shift I) / omega,
   with one backward and one forward sweep from zero (Eisenstat's trick, as PETSc's AIJ: about one matrix
   pass instead of two for SSOR plus a product); SOR_APPLY_UPPER applies U + E; MatMultDiagonalBlock
   applies D (PCEISENSTAT's diagonal scaling). D is the block diagonal, so for bs 3 this is the point-block
   Eisenstat that AIJ's inodes give for 3-row nodes. */
#include "binbcsr.h"
#include "../kernels/binbcsr_kernels.h"

#include <type_traits>

namespace {

/* acc = sum over c < r (lower) or c > r (upper) of A_rc x_c for block row r from the row's stored
   blocks: whole storage, or the upper half of upper-triangle storage. The diagonal block is left out. */
template <int BS, typename V>
void row_half_product(const Mat_SeqBinBCSR *a, const V *val, PetscInt r, bool lower, const double *x,
                      double *acc)
{
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs, bw = (int)a->bw;
  for (int i = 0; i < bs; i++) acc[i] = 0.0;
  /* Whole storage keeps each row's columns ascending: the diagonal's position splits the row. */
  PetscInt k0 = 0, k1 = a->row_nz[r];
  if (!a->sym && a->diag_slot[r] >= 0) {
    const PetscInt kd = (a->diag_slot[r] - a->bin_start[r / bw]) / bw;
    k0                = lower ? 0 : kd + 1;
    k1                = lower ? kd : k1;
  }
  for (PetscInt k = k0; k < k1; k++) {
    const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
    if (lower ? c < r : c > r)
      binbcsr::slot_mult<BS, V>(val + BinBCSRValueIndex(s, 0, bw, bs2), bw, bs, x + (size_t)c * bs, acc);
  }
}

/* Sweeps of x_r = (1 - omega) x_r + omega (D_r + shift I)^-1 (b_r - L_r - U_r), with L_r and U_r the
   products of row r's blocks left and right of the diagonal with the newest x. A forward sweep's L_r
   still hold in the backward sweep after it (no x_c, c < r, changes before that sweep reaches row r),
   and a backward sweep's U_r in the forward sweep after it. Keeping them, as PETSc's AIJ does, makes
   every sweep after the first cost half a matrix pass; with a zero initial guess the first one needs
   no upper half either, so an SSOR application from zero costs one pass. */
struct HalfSums {
  double *lower, *upper;      /* [n] L_r and U_r of the last sweep that computed them */
  bool    lower_ok, upper_ok; /* still valid for the current x */
};

/* The row update both sweeps share: x_r = (1 - omega) x_r + omega (D_r + shift I)^-1 (b_r - L_r - U_r),
   with L_r, U_r kept for the next sweep (see HalfSums). */
template <int BS>
inline void relax_row(int bs_rt, PetscInt r, const MatScalar *idiag, PetscReal omega, const double *b,
                      const double *lo, const double *up, double *Lr, double *Ur, double *res, double *xr)
{
  const int bs = BS ? BS : bs_rt;
  for (int i = 0; i < bs; i++) {
    res[i] = b[(size_t)r * bs + i] - lo[i] - up[i];
    Lr[i]  = lo[i];
    Ur[i]  = up[i];
  }
  const MatScalar *d = idiag + (size_t)r * bs * bs;
  for (int i = 0; i < bs; i++) {
    double s = 0.0;
    for (int j = 0; j < bs; j++) s += d[j * bs + i] * res[j];
    xr[i] = (1.0 - omega) * xr[i] + omega * s;
  }
}

/* lower = L x for upper-triangle storage: each stored block (c, r), r > c, adds its transpose times x_c
   to row r, one pass in storage order. */
template <int BS, typename V>
void lower_products(const Mat_SeqBinBCSR *a, const V *val, const double *x, double *lower)
{
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs, bw = (int)a->bw;
  for (PetscInt i = 0; i < a->mbs * bs; i++) lower[i] = 0.0;
  for (PetscInt c = 0; c < a->mbs; c++)
    for (PetscInt k = 0; k < a->row_nz[c]; k++) {
      const PetscInt s = BinBCSRSlot(a, c, k), r = a->col[s];
      if (r != c)
        binbcsr::slot_mult_transpose<BS, V>(val + BinBCSRValueIndex(s, 0, bw, bs2), bw, bs,
                                            x + (size_t)c * bs, lower + (size_t)r * bs);
    }
}

/* Requests part `part` of `parts` of bin b's values into the caches. A sweep walks one lane of a bin at
   a time, and the first lane of a bin meets each line of the bin's values as a miss the prefetchers
   did not foresee; one part per row spreads the requests over the bin before. */
template <typename V>
inline void prefetch_bin(const Mat_SeqBinBCSR *a, const V *val, PetscInt b, int part, int parts)
{
  if (b < 0 || b >= a->nbins) return;
  const char  *p0    = (const char *)(val + (size_t)a->bin_start[b] * a->bs2);
  const char  *p1    = (const char *)(val + (size_t)a->bin_start[b + 1] * a->bs2);
  const size_t lines = (size_t)(p1 - p0) / 64, l0 = lines * part / parts, l1 = lines * (part + 1) / parts;
  for (size_t l = l0; l < l1; l++) __builtin_prefetch(p0 + 64 * l);
}

/* The sweep for upper-triangle storage. Row r keeps only its blocks (r, c), c > r; the lower half L_r is
   spread over the rows above. Gathering it row by row (the lower index) reads one block of another
   bin per term, scattered over the whole array. Instead the sweep walks each row once, in storage
   order: a forward sweep pushes A_rc^T x_r into row c's L_c as soon as x_r is new (L_c then holds
   the newest x when the sweep reaches c); a backward sweep needs only U_r from its own row, with L_r
   kept from the forward sweep before it, or computed for the starting x in one pass.
   A sweep runs at a fraction of the product's speed (one lane at a time, scalar arithmetic, a chain of
   dependences from row to row), so the instructions per block count: the bin width is a compile-time
   constant where it can be (a tile's entries at constant offsets), U_r is summed in two halves (so
   that consecutive slots do not queue their additions behind one another), and the next bin's values
   are requested a part per row ahead of the lane that first meets them. Against the gathered lower
   half: 16-35% less time per symmetric sweep on the 160 x 160 cloth's matrix (docs/cloth.md). */
template <int BS, int BW, typename V>
void sweep_upper_storage(const Mat_SeqBinBCSR *a, const V *val, const MatScalar *idiag, PetscReal omega,
                         const double *b, double *x, bool forward, HalfSums &h, double *work)
{
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs, bw = BW ? BW : (int)a->bw;
  double    fixed[BS ? 4 * BS : 1]; /* small fixed block sizes: the sums stay in registers */
  double   *u0 = BS ? fixed : work, *u1 = u0 + bs, *up = u0 + 2 * bs, *res = u0 + 3 * bs;
  if (forward)
    for (PetscInt i = 0; i < a->mbs * bs; i++) h.lower[i] = 0.0;
  else if (!h.lower_ok) lower_products<BS, V>(a, val, x, h.lower);
  const bool upper_kept = forward && h.upper_ok;
  const auto tile       = [&](PetscInt s) { return val + BinBCSRValueIndex(s, 0, bw, bs2); };
  for (PetscInt q = 0; q < a->mbs; q++) {
    const PetscInt r = forward ? q : a->mbs - 1 - q, nz = a->row_nz[r];
    double        *xr = x + (size_t)r * bs, *Lr = h.lower + (size_t)r * bs, *Ur = h.upper + (size_t)r * bs;
    prefetch_bin<V>(a, val, forward ? r / bw + 1 : r / bw - 1, forward ? r % bw : bw - 1 - r % bw, bw);
    if (upper_kept)
      for (int i = 0; i < bs; i++) up[i] = Ur[i];
    else {
      const auto add = [&](PetscInt k, double *acc) { /* slot k's block times x, unless the diagonal */
                                                      const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
                                                      if (c != r)
                                                        binbcsr::slot_mult<BS, V>(tile(s), bw, bs,
                                                                                  x + (size_t)c * bs, acc);
      };
      for (int i = 0; i < bs; i++) u0[i] = u1[i] = 0.0;
      PetscInt k = 0;
      for (; k + 1 < nz; k += 2) add(k, u0), add(k + 1, u1);
      if (k < nz) add(k, u0);
      for (int i = 0; i < bs; i++) up[i] = u0[i] + u1[i];
    }
    relax_row<BS>(bs, r, idiag, omega, b, Lr, up, Lr, Ur, res, xr);
    if (forward)
      for (PetscInt k = 0; k < nz; k++) {
        const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
        if (c != r) binbcsr::slot_mult_transpose<BS, V>(tile(s), bw, bs, xr, h.lower + (size_t)c * bs);
      }
  }
  h.lower_ok = forward;
  h.upper_ok = !forward;
}

/* sweep_upper_storage with the bin width as a constant for 3x3 blocks at the widths the tuner picks. */
template <int BS, typename V>
void sweep_upper_any_width(const Mat_SeqBinBCSR *a, const V *val, const MatScalar *idiag, PetscReal omega,
                           const double *b, double *x, bool forward, HalfSums &h, double *work)
{
  if (BS == 3 && a->bw == 4) sweep_upper_storage<BS, 4, V>(a, val, idiag, omega, b, x, forward, h, work);
  else if (BS == 3 && a->bw == 8) sweep_upper_storage<BS, 8, V>(a, val, idiag, omega, b, x, forward, h, work);
  else if (BS == 3 && a->bw == 16)
    sweep_upper_storage<BS, 16, V>(a, val, idiag, omega, b, x, forward, h, work);
  else sweep_upper_storage<BS, 0, V>(a, val, idiag, omega, b, x, forward, h, work);
}

template <int BS, typename V>
void sweep(const Mat_SeqBinBCSR *a, const V *val, const MatScalar *idiag, PetscReal omega, const double *b,
           double *x, bool forward, HalfSums &h, double *work)
{
  if (a->sym) {
    sweep_upper_any_width<BS, V>(a, val, idiag, omega, b, x, forward, h, work);
    return;
  }
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs;
  double   *lo = work, *up = work + bs, *res = work + 2 * bs;
  for (PetscInt q = 0; q < a->mbs; q++) {
    const PetscInt r  = forward ? q : a->mbs - 1 - q;
    double        *xr = x + (size_t)r * bs;
    double        *Lr = h.lower + (size_t)r * bs, *Ur = h.upper + (size_t)r * bs;
    if (forward || !h.lower_ok) row_half_product<BS, V>(a, val, r, true, x, lo);
    else
      for (int i = 0; i < bs; i++) lo[i] = Lr[i];
    if (!forward || !h.upper_ok) row_half_product<BS, V>(a, val, r, false, x, up);
    else
      for (int i = 0; i < bs; i++) up[i] = Ur[i];
    relax_row<BS>(bs, r, idiag, omega, b, lo, up, Lr, Ur, res, xr);
  }
  h.lower_ok = forward;
  h.upper_ok = !forward;
}

/* y_r += alpha (D_r + shift I) x_r for every block row r (D_r: the stored diagonal block, zero if none). */
template <int BS, typename V>
void diagonal_block_axpy(const Mat_SeqBinBCSR *a, const V *val, double alpha, double shift, const double *x,
                         double *y, double *acc)
{
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs, bw = (int)a->bw;
  for (PetscInt r = 0; r < a->mbs; r++) {
    const double *xr = x + (size_t)r * bs;
    for (int i = 0; i < bs; i++) acc[i] = shift * xr[i];
    if (a->diag_slot[r] >= 0)
      binbcsr::slot_mult<BS, V>(val + BinBCSRValueIndex(a->diag_slot[r], 0, bw, bs2), bw, bs, xr, acc);
    for (int i = 0; i < bs; i++) y[(size_t)r * bs + i] += alpha * acc[i];
  }
}

/* x_r = (D_r + shift I) b_r / omega + U_r b: SOR_APPLY_UPPER, (U + E) b. */
template <int BS, typename V>
void apply_upper(const Mat_SeqBinBCSR *a, const V *val, PetscReal omega, PetscReal shift, const double *b,
                 double *x, double *work)
{
  const int bs = BS ? BS : (int)a->bs;
  for (PetscInt r = 0; r < a->mbs; r++) row_half_product<BS, V>(a, val, r, false, b, x + (size_t)r * bs);
  diagonal_block_axpy<BS, V>(a, val, 1.0 / omega, shift, b, x, work);
}

/* f(block size constant, values) for the storage and block size of a: the kernels are compiled for
   bs 3 and 1 and a runtime block size (0), in double or single storage. */
template <typename F> void dispatch(const Mat_SeqBinBCSR *a, F &&f)
{
  if (a->val) {
    if (a->bs == 3) f(std::integral_constant<int, 3>(), (const MatScalar *)a->val);
    else if (a->bs == 1) f(std::integral_constant<int, 1>(), (const MatScalar *)a->val);
    else f(std::integral_constant<int, 0>(), (const MatScalar *)a->val);
  } else {
    if (a->bs == 3) f(std::integral_constant<int, 3>(), (const float *)a->valf);
    else if (a->bs == 1) f(std::integral_constant<int, 1>(), (const float *)a->valf);
    else f(std::integral_constant<int, 0>(), (const float *)a->valf);
  }
}

template <typename P> using ValueType = std::remove_const_t<std::remove_pointer_t<P>>;

/* One sweep of x (forward or backward) in the storage and block size of a. */
void sweep_any(const Mat_SeqBinBCSR *a, PetscReal omega, const double *b, double *x, bool forward,
               HalfSums &h, double *work)
{
  dispatch(a, [&](auto BS, const auto *val) {
    sweep<decltype(BS)::value, ValueType<decltype(val)>>(a, val, a->sor_idiag, omega, b, x, forward, h, work);
  });
}

/* x = 0 and the half sums of x = 0: the first sweep in either direction needs neither. */
void zero_start(PetscInt n, double *x, HalfSums &h)
{
  for (PetscInt i = 0; i < n; i++) x[i] = h.lower[i] = h.upper[i] = 0.0;
  h.lower_ok = h.upper_ok = true;
}

} // namespace

namespace {
/* sor_idiag = (D + shift I)^-1, recomputed when the matrix or the shift changed. */
PetscErrorCode SORInvertDiagonal(Mat A, PetscReal fshift)
{
  Mat_SeqBinBCSR  *a = (Mat_SeqBinBCSR *)A->data;
  PetscObjectState state;

  PetscFunctionBegin;
  PetscCall(PetscObjectStateGet((PetscObject)A, &state));
  if (!a->sor_idiag || a->sor_state != state || a->sor_shift != fshift) {
    PetscInt zero_row;
    if (!a->sor_idiag) PetscCall(PetscMalloc1((size_t)a->mbs * a->bs2, &a->sor_idiag));
    a->sor_state = 0;
    PetscCall(MatSeqBinBCSRInvertDiagonalBlocks(A, fshift, a->sor_idiag, &zero_row));
    PetscCheck(zero_row < 0, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT,
               "MatSOR: the diagonal block of block row %" PetscInt_FMT " (+ shift %g) is singular", zero_row,
               (double)fshift);
    a->sor_state = state;
    a->sor_shift = fshift;
  }
  PetscFunctionReturn(0);
}

/* Eisenstat's trick (SOR_EISENSTAT): x = (L + E)^-1 A (U + E)^-1 b with E = (D + shift I) / omega, from
     y = (U + E)^-1 b                     a backward sweep from zero
     t = b - (2 E - D - shift I) y       since A y = (L + E) y + (U + E) y - (2 E - D - shift I) y
     x = y + (L + E)^-1 t                 a forward sweep from zero
   The two sweeps cost one pass over the off-diagonal blocks together. */
PetscErrorCode SOREisenstat(Mat A, PetscReal omega, PetscReal fshift, const double *b, double *x)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  n = a->mbs * a->bs;
  double         *work, *t, *z;
  HalfSums        h = {nullptr, nullptr, false, false};

  PetscFunctionBegin;
  PetscCall(PetscMalloc5(4 * a->bs, &work, n, &h.lower, n, &h.upper, n, &t, n, &z));
  zero_start(n, x, h);
  sweep_any(a, omega, b, x, false, h, work);
  PetscCall(PetscArraycpy(t, b, n));
  dispatch(a, [&](auto BS, const auto *val) {
    diagonal_block_axpy<decltype(BS)::value, ValueType<decltype(val)>>(a, val, 1.0 - 2.0 / omega, fshift, x,
                                                                       t, work);
  });
  zero_start(n, z, h);
  sweep_any(a, omega, t, z, true, h, work);
  for (PetscInt i = 0; i < n; i++) x[i] += z[i];
  PetscCall(PetscFree5(work, h.lower, h.upper, t, z));
  PetscCall(
    PetscLogFlops((double)(a->sym ? 2 * (a->nz - a->mbs) : a->nz - a->mbs) * a->bs2 + 6.0 * a->mbs * a->bs2));
  PetscFunctionReturn(0);
}
} // namespace

/* y = D x (block diagonal): PCEISENSTAT's diagonal scaling, consistent with the block sweeps. */
PetscErrorCode MatMultDiagonalBlock_SeqBinBCSR(Mat A, Vec xx, Vec yy)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscScalar *x;
  PetscScalar       *y;
  double            *work;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCheck(a->mbs == a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "MatMultDiagonalBlock needs a square matrix (%" PetscInt_FMT " x %" PetscInt_FMT " blocks)",
             a->mbs, a->nbs);
  PetscCall(PetscMalloc1(a->bs, &work));
  PetscCall(VecGetArrayRead(xx, &x));
  PetscCall(VecGetArrayWrite(yy, &y));
  PetscCall(PetscArrayzero(y, A->rmap->n));
  dispatch(a, [&](auto BS, const auto *val) {
    diagonal_block_axpy<decltype(BS)::value, ValueType<decltype(val)>>(a, val, 1.0, 0.0, x, y, work);
  });
  PetscCall(VecRestoreArrayWrite(yy, &y));
  PetscCall(VecRestoreArrayRead(xx, &x));
  PetscCall(PetscFree(work));
  PetscCall(PetscLogFlops(2.0 * a->mbs * a->bs2));
  PetscFunctionReturn(0);
}

PetscErrorCode MatSOR_SeqBinBCSR(Mat A, Vec bb, PetscReal omega, MatSORType flag, PetscReal fshift,
                                 PetscInt its, PetscInt lits, Vec xx)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscScalar *b;
  PetscScalar       *x;
  double            *work = nullptr;
  const PetscBool forward = (flag & (SOR_FORWARD_SWEEP | SOR_LOCAL_FORWARD_SWEEP)) ? PETSC_TRUE : PETSC_FALSE;
  const PetscBool backward =
    (flag & (SOR_BACKWARD_SWEEP | SOR_LOCAL_BACKWARD_SWEEP)) ? PETSC_TRUE : PETSC_FALSE;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCheck(a->mbs == a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "MatSOR needs a square matrix (%" PetscInt_FMT " x %" PetscInt_FMT " blocks)", a->mbs, a->nbs);
  PetscCheck(
    !(flag & SOR_APPLY_LOWER), PETSC_COMM_SELF, PETSC_ERR_SUP,
    "MATSEQBINBCSR's MatSOR has no SOR_APPLY_LOWER (nor has PETSc's AIJ; PCEISENSTAT does not use it)");
  PetscCheck(!PetscIsInfOrNanReal(omega) && !PetscIsInfOrNanReal(fshift) && omega != 0.0, PETSC_COMM_SELF,
             PETSC_ERR_ARG_WRONG, "MatSOR: omega (%g) must be finite and nonzero, the shift finite",
             (double)omega);
  if (flag == SOR_APPLY_UPPER) {
    PetscCall(VecGetArrayRead(bb, &b));
    PetscCall(VecGetArrayWrite(xx, &x));
    PetscCall(PetscMalloc1(a->bs, &work));
    dispatch(a, [&](auto BS, const auto *val) {
      apply_upper<decltype(BS)::value, ValueType<decltype(val)>>(a, val, omega, fshift, b, x, work);
    });
    PetscCall(PetscFree(work));
    PetscCall(VecRestoreArrayWrite(xx, &x));
    PetscCall(VecRestoreArrayRead(bb, &b));
    PetscCall(PetscLogFlops((double)(a->sym ? a->nz - a->mbs : (a->nz - a->mbs) / 2) * 2 * a->bs2 +
                            2.0 * a->mbs * a->bs2));
    PetscFunctionReturn(0);
  }
  PetscCheck(!(flag & SOR_APPLY_UPPER), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
             "MatSOR: SOR_APPLY_UPPER cannot be combined with other flags (%d)", (int)flag);
  PetscCall(SORInvertDiagonal(A, fshift));
  if (flag & SOR_EISENSTAT) {
    PetscCall(VecGetArrayRead(bb, &b));
    PetscCall(VecGetArrayWrite(xx, &x));
    PetscCall(SOREisenstat(A, omega, fshift, b, x));
    PetscCall(VecRestoreArrayWrite(xx, &x));
    PetscCall(VecRestoreArrayRead(bb, &b));
    PetscFunctionReturn(0);
  }
  PetscCheck(forward || backward, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
             "MatSOR: the flag %d asks for no sweep", (int)flag);
  PetscCheck(its > 0 && lits > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
             "MatSOR: its (%" PetscInt_FMT ") and lits (%" PetscInt_FMT ") must be positive", its, lits);
  PetscCall(VecGetArrayRead(bb, &b));
  PetscCall(VecGetArray(xx, &x));
  const size_t n = (size_t)a->mbs * a->bs;
  HalfSums     h = {nullptr, nullptr, false, false};
  PetscCall(PetscMalloc3(4 * a->bs, &work, n, &h.lower, n, &h.upper));
  if (flag & SOR_ZERO_INITIAL_GUESS) zero_start((PetscInt)n, x, h);
  for (PetscInt it = 0; it < its * lits; it++) {
    if (forward) sweep_any(a, omega, b, x, true, h, work);
    if (backward) sweep_any(a, omega, b, x, false, h, work);
  }
  PetscCall(PetscFree3(work, h.lower, h.upper));
  PetscCall(VecRestoreArray(xx, &x));
  PetscCall(VecRestoreArrayRead(bb, &b));
  { /* per sweep: about half of the off-diagonal blocks (see HalfSums) and the block solves */
    const double offdiag = (double)(a->sym ? 2 * (a->nz - a->mbs) : a->nz - a->mbs);
    PetscCall(PetscLogFlops((double)its * lits * ((forward ? 1 : 0) + (backward ? 1 : 0)) *
                            (offdiag * a->bs2 + 2.0 * a->mbs * a->bs2)));
  }
  PetscFunctionReturn(0);
}
