/* Operations that replace every stored value at once, for seq and mpi binbcsr: MatSetRandom,
   MatRealPart, MatImaginaryPart. The pattern is kept (padding stays zero).

   MatSetRandom fills the stored pattern (as seqaij does once a pattern exists; binbcsr has no pattern to
   pick random locations in before its first assembly, so that is refused).
   - Whole storage: one draw from the PetscRandom per stored value, in CSR order (point row by point
     row, ascending columns), on MPI the diagonal part then the off-diagonal part: the order of
     seqaij/mpiaij, so the same PetscRandom gives aij's values on the same pattern (single storage:
     rounded to float).
   - Symmetric storage must stay symmetric, also across ranks (the off-diagonal part of mpibinbcsr is
     stored whole, so a_ij and a_ji may lie on different ranks). So a_ij = a_ji = low + (high - low) u,
     u in [0, 1) a 64-bit hash (splitmix64) of one key drawn from the PetscRandom (rank 0's draw) and
     the global pair (min(i, j), max(i, j)), low/high the PetscRandom's interval. The matrix does not
     depend on the number of ranks, the bin width or the precision (beyond rounding); aij's values
     differ (aij draws every entry, a_ij and a_ji independently).

   MatRealPart / MatImaginaryPart: the plug-in stores real values (PETSc built with real scalars, as
   Debian's), so the real part is the matrix itself and the imaginary part is zero, as aij computes them
   for real scalars; MatConjugate needs nothing (PETSc's interface does nothing for real scalars). */
#include "../mpi/mpibinbcsr.h"
#include "../seq/binbcsr.h"

#include <cstdint>

#if defined(PETSC_USE_COMPLEX)
  #error "binbcsr stores real values: PETSc must be built with real scalars"
#endif

namespace {

/* Symmetric storage: the value of a pair of global indices, the same wherever it is stored. */
struct PairDraw {
  std::uint64_t   key;
  PetscReal       low, width;
  PetscInt        row0;   /* global point row of local row 0 */
  PetscInt        col0;   /* global point column of local column 0 when garray is NULL */
  const PetscInt *garray; /* off-diagonal part: global block column of each local block column */
};

std::uint64_t Mix64(std::uint64_t z)
{
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

PetscReal PairValue(const PairDraw &d, PetscInt i, PetscInt j)
{
  const std::uint64_t lo = (std::uint64_t)PetscMin(i, j), hi = (std::uint64_t)PetscMax(i, j);
  const std::uint64_t z = Mix64(d.key ^ Mix64((lo << 32) | hi));
  return d.low + d.width * (PetscReal)(z >> 11) * 0x1.0p-53;
}

/* Every real slot of the MATSEQBINBCSR P: draws from rctx in CSR order (pair == NULL) or pair values. */
PetscErrorCode FillPart(Mat P, PetscRandom rctx, const PairDraw *pair)
{
  Mat_SeqBinBCSR *a  = (Mat_SeqBinBCSR *)P->data;
  const PetscInt  bs = a->bs;

  PetscFunctionBegin;
  PetscCheck(
    a->built, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE,
    "MatSetRandom needs the nonzero pattern of the binbcsr matrix: assemble it first (binbcsr does not choose random locations)");
  for (PetscInt r = 0; r < a->mbs; r++)
    for (PetscInt i = 0; i < bs; i++)
      for (PetscInt k = 0; k < a->row_nz[r]; k++) {
        const PetscInt s = BinBCSRSlot(a, r, k), c = a->col[s];
        for (PetscInt j = 0; j < bs; j++) {
          PetscScalar x;
          if (pair)
            x = PairValue(*pair, pair->row0 + r * bs + i,
                          (pair->garray ? pair->garray[c] * bs : pair->col0 + c * bs) + j);
          else PetscCall(PetscRandomGetValue(rctx, &x));
          BinBCSRSetValue(a, BinBCSRValueIndex(s, i * bs + j, a->bw, a->bs2), x);
        }
      }
  PetscCall(PetscObjectStateIncrease((PetscObject)P));
  PetscFunctionReturn(0);
}

/* One part of an mpibinbcsr matrix: its own fill, or the inner type's MatSetRandom (whole storage only). */
PetscErrorCode FillMPIPart(Mat P, PetscRandom rctx, const PairDraw *pair)
{
  PetscBool bin;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)P, MATSEQBINBCSR, &bin));
  if (bin) PetscCall(FillPart(P, rctx, pair));
  else {
    PetscCheck(!pair, PETSC_COMM_SELF, PETSC_ERR_SUP,
               "MatSetRandom with symmetric storage needs binbcsr parts, not %s",
               ((PetscObject)P)->type_name);
    PetscCall(MatSetRandom(P, rctx));
  }
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode MatSetRandom_BinBCSR(Mat A, PetscRandom rctx)
{
  PetscBool mpi, sym;
  PairDraw  pair{};

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBINBCSR, &mpi));
  PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym));
  if (mpi)
    PetscCheck(
      MPIBinBCSR(A)->compressed, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_WRONGSTATE,
      "MatSetRandom needs the nonzero pattern of the binbcsr matrix: assemble it first (binbcsr does not choose random locations)");
  if (sym) {
    PetscScalar u, low, high;
    PetscCall(PetscRandomGetValue(rctx, &u)); /* every rank draws once, rank 0's draw is the key */
    PetscCall(PetscRandomGetInterval(rctx, &low, &high));
    pair.key = (std::uint64_t)((PetscRealPart(u) - PetscRealPart(low)) /
                               (PetscRealPart(high) - PetscRealPart(low)) * 0x1.0p53);
    PetscCallMPI(MPI_Bcast(&pair.key, 1, MPIU_INT64, 0, PetscObjectComm((PetscObject)A)));
    pair.low   = PetscRealPart(low);
    pair.width = PetscRealPart(high) - PetscRealPart(low);
    pair.row0  = A->rmap->rstart;
    pair.col0  = A->cmap->rstart;
  }
  if (!mpi) PetscCall(FillPart(A, rctx, sym ? &pair : nullptr));
  else {
    Mat_MPIBinBCSR *b = MPIBinBCSR(A);
    PetscCall(FillMPIPart(b->A, rctx, sym ? &pair : nullptr));
    if (b->B) {
      pair.garray = b->garray.data();
      PetscCall(FillMPIPart(b->B, rctx, sym ? &pair : nullptr));
    }
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MatRealPart_BinBCSR(Mat A)
{
  PetscFunctionBegin;
  (void)A; /* real values: each is its own real part */
  PetscFunctionReturn(0);
}

PetscErrorCode MatImaginaryPart_BinBCSR(Mat A)
{
  PetscFunctionBegin;
  PetscCall(MatZeroEntries(A)); /* real values: imaginary parts are zero, the pattern stays */
  PetscFunctionReturn(0);
}
