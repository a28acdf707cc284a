/* MatSOR for MATSEQBINBCSR: SOR / Gauss-Seidel sweeps, pointwise for bs 1 and by blocks for bs > 1
   (the diagonal block is inverted exactly, as in PETSc's BAIJ), so PCSOR (SSOR with
   -pc_sor_symmetric, a symmetric preconditioner for CG), multigrid smoothers and block Jacobi with
   -sub_pc_type sor work on this type.

   One row update: x_r = (1 - omega) x_r + omega (D_r + shift I)^-1 (b_r - sum_{c != r} A_rc x_c) with the
   newest x (SOR on A + shift I, as PETSc's AIJ defines the shift). The row products reuse the per-slot
   kernels of MatMult (slot_mult, and slot_mult_transpose for the lower triangle that symmetric
   storage keeps in other rows). Sweeps are sequential over rows by nature: they walk
   the bin layout one lane at a time and do not get the SIMD speed of MatMult. */
#include "binbcsr.h"
#include "../binbcsr_kernels.h"

namespace
{

/* acc = sum over c < r (lower) or c > r (upper) of A_rc x_c for block row r: the row's stored
   blocks and, with symmetric storage, the transposed blocks (c, r), c < r, stored in the rows above
   (the lower index). The diagonal block is left out. */
template <int BS, typename V>
void row_half_product(const Mat_SeqBinBCSR *a, const V *val, PetscInt r, bool lower, const double *x, double *acc)
{
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs, bw = (int)a->bw;
  for (int i = 0; i < bs; i++) acc[i] = 0.0;
  if (a->sym && lower) {
    for (PetscInt p = a->lower_off[r]; p < a->lower_off[r + 1]; p++) {
      const PetscInt s = a->lower_slot[2 * p], c = a->lower_slot[2 * p + 1];
      binbcsr::slot_mult_transpose<BS, V>(val + BinBCSRValueIndex(s, 0, bw, bs2), bw, bs, x + (size_t)c * bs, acc);
    }
    return;
  }
  /* Whole storage keeps each row's columns ascending: the diagonal's position splits the row. */
  PetscInt k0 = 0, k1 = a->row_nz[r];
  if (!a->sym && a->diag_slot[r] >= 0) {
    const PetscInt kd = (a->diag_slot[r] - a->bin_start[r / bw]) / bw;
    k0                = lower ? 0 : kd + 1;
    k1                = lower ? kd : k1;
  }
  for (PetscInt k = k0; k < k1; k++) {
    const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
    if (lower ? c < r : c > r) binbcsr::slot_mult<BS, V>(val + BinBCSRValueIndex(s, 0, bw, bs2), bw, bs, x + (size_t)c * bs, acc);
  }
}

/* Sweeps of x_r = (1 - omega) x_r + omega (D_r + shift I)^-1 (b_r - L_r - U_r), with L_r and U_r the
   products of row r's blocks left and right of the diagonal with the newest x. A forward sweep's L_r
   still hold in the backward sweep after it (no x_c, c < r, changes before that sweep reaches row r),
   and a backward sweep's U_r in the forward sweep after it. Keeping them, as PETSc's AIJ does, makes
   every sweep after the first cost half a matrix pass; with a zero initial guess the first one needs
   no upper half either, so an SSOR application from zero costs one pass. */
struct HalfSums {
  double *lower, *upper;     /* [n] L_r and U_r of the last sweep that computed them */
  bool    lower_ok, upper_ok; /* still valid for the current x */
};

template <int BS, typename V>
void sweep(const Mat_SeqBinBCSR *a, const V *val, const MatScalar *idiag, PetscReal omega, const double *b, double *x, bool forward, HalfSums &h, double *work)
{
  const int bs = BS ? BS : (int)a->bs, bs2 = bs * bs;
  double   *lo = work, *up = work + bs, *res = work + 2 * bs;
  for (PetscInt q = 0; q < a->mbs; q++) {
    const PetscInt r   = forward ? q : a->mbs - 1 - q;
    double        *xr  = x + (size_t)r * bs;
    double        *Lr  = h.lower + (size_t)r * bs, *Ur = h.upper + (size_t)r * bs;
    if (forward || !h.lower_ok) row_half_product<BS, V>(a, val, r, true, x, lo);
    else
      for (int i = 0; i < bs; i++) lo[i] = Lr[i];
    if (!forward || !h.upper_ok) row_half_product<BS, V>(a, val, r, false, x, up);
    else
      for (int i = 0; i < bs; i++) up[i] = Ur[i];
    for (int i = 0; i < bs; i++) {
      res[i] = b[(size_t)r * bs + i] - lo[i] - up[i];
      Lr[i]  = lo[i];
      Ur[i]  = up[i];
    }
    const MatScalar *d = idiag + (size_t)r * bs2;
    for (int i = 0; i < bs; i++) {
      double s = 0.0;
      for (int j = 0; j < bs; j++) s += d[j * bs + i] * res[j];
      xr[i] = (1.0 - omega) * xr[i] + omega * s;
    }
  }
  h.lower_ok = forward;
  h.upper_ok = !forward;
}

template <typename V>
void sweep_dispatch(const Mat_SeqBinBCSR *a, const V *val, const MatScalar *idiag, PetscReal omega, const double *b, double *x, bool forward, HalfSums &h, double *work)
{
  if (a->bs == 3) sweep<3, V>(a, val, idiag, omega, b, x, forward, h, work);
  else if (a->bs == 1) sweep<1, V>(a, val, idiag, omega, b, x, forward, h, work);
  else sweep<0, V>(a, val, idiag, omega, b, x, forward, h, work);
}

} // namespace

PetscErrorCode MatSOR_SeqBinBCSR(Mat A, Vec bb, PetscReal omega, MatSORType flag, PetscReal fshift, PetscInt its, PetscInt lits, Vec xx)
{
  Mat_SeqBinBCSR    *a = (Mat_SeqBinBCSR *)A->data;
  const PetscScalar *b;
  PetscScalar       *x;
  double            *work = nullptr;
  PetscObjectState   state;
  const PetscBool    forward  = (flag & (SOR_FORWARD_SWEEP | SOR_LOCAL_FORWARD_SWEEP)) ? PETSC_TRUE : PETSC_FALSE;
  const PetscBool    backward = (flag & (SOR_BACKWARD_SWEEP | SOR_LOCAL_BACKWARD_SWEEP)) ? PETSC_TRUE : PETSC_FALSE;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCheck(a->mbs == a->nbs, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "MatSOR needs a square matrix (%" PetscInt_FMT " x %" PetscInt_FMT " blocks)", a->mbs, a->nbs);
  PetscCheck(!(flag & (SOR_EISENSTAT | SOR_APPLY_UPPER | SOR_APPLY_LOWER)), PETSC_COMM_SELF, PETSC_ERR_SUP, "MATSEQBINBCSR's MatSOR does forward, backward and symmetric sweeps only (no Eisenstat, no apply upper/lower)");
  PetscCheck(forward || backward, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "MatSOR: the flag %d asks for no sweep", (int)flag);
  PetscCheck(its > 0 && lits > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "MatSOR: its (%" PetscInt_FMT ") and lits (%" PetscInt_FMT ") must be positive", its, lits);
  PetscCheck(!PetscIsInfOrNanReal(omega) && !PetscIsInfOrNanReal(fshift), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "MatSOR: omega and the shift must be finite");
  PetscCall(PetscObjectStateGet((PetscObject)A, &state));
  if (!a->sor_idiag || a->sor_state != state || a->sor_shift != fshift) {
    PetscInt zero_row;
    if (!a->sor_idiag) PetscCall(PetscMalloc1((size_t)a->mbs * a->bs2, &a->sor_idiag));
    a->sor_state = 0;
    PetscCall(MatSeqBinBCSRInvertDiagonalBlocks(A, fshift, a->sor_idiag, &zero_row));
    PetscCheck(zero_row < 0, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT, "MatSOR: the diagonal block of block row %" PetscInt_FMT " (+ shift %g) is singular", zero_row, (double)fshift);
    a->sor_state = state;
    a->sor_shift = fshift;
  }
  if (a->sym) PetscCall(MatSeqBinBCSRBuildLowerIndex(a));
  if (flag & SOR_ZERO_INITIAL_GUESS) PetscCall(VecSet(xx, 0.0));
  PetscCall(VecGetArrayRead(bb, &b));
  PetscCall(VecGetArray(xx, &x));
  const size_t n = (size_t)a->mbs * a->bs;
  HalfSums     h = {nullptr, nullptr, false, false};
  PetscCall(PetscMalloc3(3 * a->bs, &work, n, &h.lower, n, &h.upper));
  if (flag & SOR_ZERO_INITIAL_GUESS) { /* x = 0: no row has anything right of its diagonal yet */
    PetscCall(PetscArrayzero(h.upper, n));
    h.upper_ok = true;
  }
  for (PetscInt it = 0; it < its * lits; it++) {
    if (forward) {
      if (a->val) sweep_dispatch<double>(a, a->val, a->sor_idiag, omega, b, x, true, h, work);
      else sweep_dispatch<float>(a, a->valf, a->sor_idiag, omega, b, x, true, h, work);
    }
    if (backward) {
      if (a->val) sweep_dispatch<double>(a, a->val, a->sor_idiag, omega, b, x, false, h, work);
      else sweep_dispatch<float>(a, a->valf, a->sor_idiag, omega, b, x, false, h, work);
    }
  }
  PetscCall(PetscFree3(work, h.lower, h.upper));
  PetscCall(VecRestoreArray(xx, &x));
  PetscCall(VecRestoreArrayRead(bb, &b));
  { /* per sweep: about half of the off-diagonal blocks (see HalfSums) and the block solves */
    const double offdiag = (double)(a->sym ? 2 * (a->nz - a->mbs) : a->nz - a->mbs);
    PetscCall(PetscLogFlops((double)its * lits * ((forward ? 1 : 0) + (backward ? 1 : 0)) * (offdiag * a->bs2 + 2.0 * a->mbs * a->bs2)));
  }
  PetscFunctionReturn(0);
}
