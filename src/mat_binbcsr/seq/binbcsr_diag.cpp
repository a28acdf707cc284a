/* MATSEQBINBCSR diagonal: MatGetDiagonal, the inverses of the diagonal blocks (MatInvertBlockDiagonal,
   MatSOR's diagonal, MatInvertVariableBlockDiagonal). */
#include "binbcsr.h"
#include <petsc/private/kernels/blockinvert.h>
#include <vector>

PetscErrorCode MatGetDiagonal_SeqBinBCSR(Mat A, Vec v)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscScalar    *d;
  PetscInt        n;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCall(VecGetLocalSize(v, &n));
  PetscCheck(n == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Nonconforming matrix and vector: %" PetscInt_FMT " rows, vector of %" PetscInt_FMT, A->rmap->n,
             n);
  PetscCall(VecGetArrayWrite(v, &d));
  for (PetscInt r = 0; r < a->mbs; r++) {
    const PetscInt s = a->diag_slot[r];
    for (PetscInt i = 0; i < a->bs; i++)
      d[r * a->bs + i] = s < 0 ? 0.0 : BinBCSRGetValue(a, BinBCSRValueIndex(s, i * a->bs + i, a->bw, a->bs2));
  }
  PetscCall(VecRestoreArrayWrite(v, &d));
  PetscFunctionReturn(0);
}

/* In-place inverse of one bs x bs block by Gauss-Jordan with partial pivoting on [m | I] (block sizes
   without a PETSc kernel); aug holds bs * 2bs scalars. Returns false on a zero pivot. */
static PetscBool InvertBlockGeneric(PetscInt bs, MatScalar *m, MatScalar *aug)
{
  const PetscInt w = 2 * bs;
  for (PetscInt i = 0; i < bs; i++)
    for (PetscInt j = 0; j < bs; j++) {
      aug[i * w + j]      = m[i * bs + j];
      aug[i * w + bs + j] = (i == j) ? 1.0 : 0.0;
    }
  for (PetscInt k = 0; k < bs; k++) {
    PetscInt  p   = k;
    PetscReal big = PetscAbsScalar(aug[k * w + k]);
    for (PetscInt i = k + 1; i < bs; i++)
      if (PetscAbsScalar(aug[i * w + k]) > big) {
        big = PetscAbsScalar(aug[i * w + k]);
        p   = i;
      }
    if (big < PETSC_MACHINE_EPSILON) return PETSC_FALSE;
    if (p != k)
      for (PetscInt j = 0; j < w; j++) {
        const MatScalar t = aug[k * w + j];
        aug[k * w + j]    = aug[p * w + j];
        aug[p * w + j]    = t;
      }
    const MatScalar inv = 1.0 / aug[k * w + k];
    for (PetscInt j = 0; j < w; j++) aug[k * w + j] *= inv;
    for (PetscInt i = 0; i < bs; i++) {
      if (i == k) continue;
      const MatScalar f = aug[i * w + k];
      if (f != 0.0)
        for (PetscInt j = 0; j < w; j++) aug[i * w + j] -= f * aug[k * w + j];
    }
  }
  for (PetscInt i = 0; i < bs; i++)
    for (PetscInt j = 0; j < bs; j++) m[i * bs + j] = aug[i * w + bs + j];
  return PETSC_TRUE;
}

/* In-place inverse of one bs x bs block (either storage order: the inverse of the transpose is the
   transpose of the inverse); aug: scratch of 2 bs^2 scalars. *zp: a zero pivot was met (d is then
   garbage). One routine for MatInvertBlockDiagonal, MatSOR's diagonal and the variable blocks. */
static PetscErrorCode InvertBlock(PetscInt bs, MatScalar *d, MatScalar *aug, PetscBool *zp)
{
  PetscFunctionBegin;
  *zp = PETSC_FALSE;
  if (bs == 1) {
    *zp = PetscAbsScalar(d[0]) < PETSC_MACHINE_EPSILON ? PETSC_TRUE : PETSC_FALSE;
    if (!*zp) d[0] = 1.0 / d[0];
  } else if (bs == 3) {
    PetscCall(PetscKernel_A_gets_inverse_A_3(d, 0.0, PETSC_TRUE, zp));
  } else {
    *zp = InvertBlockGeneric(bs, d, aug) ? PETSC_FALSE : PETSC_TRUE;
  }
  PetscFunctionReturn(0);
}

/* out[r] = (D_r + shift I)^-1 for every block row r, column-major blocks (BAIJ's order); D_r is the
   stored diagonal block (zero if the row has none). A zero pivot is an error when the matrix errors on
   failure (MatSetErrorIfFailure) or zero_row is NULL; otherwise *zero_row is the first block row with
   one (-1: none) and it is recorded in A->factorerrortype. */
PetscErrorCode MatSeqBinBCSRInvertDiagonalBlocks(Mat A, PetscReal shift, MatScalar *out, PetscInt *zero_row)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)A->data;
  const PetscInt  bs = a->bs, bs2 = a->bs2;
  PetscBool       allowzeropivot = (PetscBool)(zero_row && !A->erroriffailure), zeropivot = PETSC_FALSE;
  MatScalar      *aug;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  if (zero_row) *zero_row = -1;
  PetscCall(PetscMalloc1(2 * bs2, &aug));
  for (PetscInt r = 0; r < a->mbs; r++) {
    MatScalar     *d = out + (size_t)r * bs2;
    const PetscInt s = a->diag_slot[r];
    /* the block, transposed into BAIJ's column-major order */
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt j = 0; j < bs; j++)
        d[j * bs + i] = (s < 0 ? 0.0 : BinBCSRGetValue(a, BinBCSRValueIndex(s, i * bs + j, a->bw, bs2))) +
                        (i == j ? shift : 0.0);
    PetscBool zp;
    PetscCall(InvertBlock(bs, d, aug, &zp));
    if (zp) {
      if (!allowzeropivot) PetscCall(PetscFree(aug));
      PetscCheck(allowzeropivot, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT,
                 "Zero pivot in the diagonal block of block row %" PetscInt_FMT, r);
      if (!zeropivot) *zero_row = r;
      zeropivot                      = PETSC_TRUE;
      A->factorerror_zeropivot_row   = r * bs;
      A->factorerror_zeropivot_value = 0.0;
    }
  }
  if (zeropivot) A->factorerrortype = MAT_FACTOR_NUMERIC_ZEROPIVOT;
  PetscCall(PetscFree(aug));
  PetscFunctionReturn(0);
}

PetscErrorCode MatInvertBlockDiagonal_SeqBinBCSR(Mat A, const PetscScalar **values)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscInt        zero_row;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  if (!a->idiag) PetscCall(PetscMalloc1((size_t)a->mbs * a->bs2, &a->idiag));
  PetscCall(MatSeqBinBCSRInvertDiagonalBlocks(A, 0.0, a->idiag, &zero_row));
  if (values) *values = a->idiag;
  PetscFunctionReturn(0);
}

/* PCVPBJACOBI's blocks: diag gets, one after the other, the inverses of the diagonal blocks of the given
   point sizes (column-major, as MatInvertVariableBlockDiagonal_SeqAIJ leaves them). A variable block may
   cut across the bs x bs blocks of the layout, so its entries are read through MatGetValues (symmetric
   storage: the mirrored lower entries too); the inversion is MatInvertBlockDiagonal's. Zero pivots as
   there: an error under MatSetErrorIfFailure, else recorded in A->factorerrortype (PCVPBJACOBI turns it
   into its failed reason; aij's scalar blocks divide by zero silently). */
PetscErrorCode MatInvertVariableBlockDiagonal_SeqBinBCSR(Mat A, PetscInt nblocks, const PetscInt *bsizes,
                                                         PetscScalar *diag)
{
  Mat_SeqBinBCSR *a     = (Mat_SeqBinBCSR *)A->data;
  PetscInt        total = 0, nmax = 0, row = 0;
  PetscBool       zeropivot = PETSC_FALSE;

  PetscFunctionBegin;
  PetscCheck(a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
             "MATSEQBINBCSR matrix has no layout: assemble it first");
  PetscCheck(nblocks >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "Negative number of blocks %" PetscInt_FMT, nblocks);
  for (PetscInt i = 0; i < nblocks; i++) {
    PetscCheck(bsizes[i] >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "Block %" PetscInt_FMT " has negative size %" PetscInt_FMT, i, bsizes[i]);
    total += bsizes[i];
    nmax = PetscMax(nmax, bsizes[i]);
  }
  PetscCheck(total == A->rmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "The block sizes add up to %" PetscInt_FMT ", the matrix has %" PetscInt_FMT " rows", total,
             A->rmap->n);
  PetscCheck(A->rmap->n == A->cmap->n, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ,
             "Diagonal blocks of a %" PetscInt_FMT " x %" PetscInt_FMT " matrix", A->rmap->n, A->cmap->n);
  std::vector<PetscInt>  idx(nmax);
  std::vector<MatScalar> rowmajor((size_t)nmax * nmax), aug(2 * (size_t)nmax * nmax);
  for (PetscInt b = 0; b < nblocks; row += bsizes[b], diag += bsizes[b] * bsizes[b], b++) {
    const PetscInt n = bsizes[b];
    PetscBool      zp;
    if (!n) continue;
    for (PetscInt i = 0; i < n; i++) idx[i] = row + i;
    PetscCall(MatGetValues(A, n, idx.data(), n, idx.data(), rowmajor.data()));
    for (PetscInt i = 0; i < n; i++)
      for (PetscInt j = 0; j < n; j++) diag[j * n + i] = rowmajor[i * n + j];
    PetscCall(InvertBlock(n, diag, aug.data(), &zp));
    if (!zp) continue;
    PetscCheck(!A->erroriffailure, PETSC_COMM_SELF, PETSC_ERR_MAT_LU_ZRPVT,
               "Zero pivot in the diagonal block %" PetscInt_FMT " (rows %" PetscInt_FMT "..%" PetscInt_FMT
               ")",
               b, row, row + n - 1);
    if (!zeropivot) {
      A->factorerror_zeropivot_row   = row;
      A->factorerror_zeropivot_value = 0.0;
    }
    zeropivot = PETSC_TRUE;
  }
  if (zeropivot) A->factorerrortype = MAT_FACTOR_NUMERIC_ZEROPIVOT;
  PetscFunctionReturn(0);
}
