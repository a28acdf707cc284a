/* The -mat_binbcsr_* options, read for seq and mpi binbcsr alike (MatSetFromOptions of either type,
   and MatBinBCSRSetFromOptions): one place for each option's name, help string and default.

   Each option shows the matrix's current value as its default and, when given, is applied through
   the public setter, which dispatches to the type (an mpi matrix forwards it to its parts). To add an
   option: one block below with its getter and setter; both types then read it. */
#include "binbcsr_impl.h"

PetscErrorCode MatBinBCSRReadOptions_Private(Mat A, PetscOptionItems *PetscOptionsObject)
{
  PetscFunctionBegin;
  {
    PetscInt  bw;
    PetscBool set;
    PetscCall(MatBinBCSRGetBinWidth(A, &bw));
    PetscCall(PetscOptionsInt("-mat_binbcsr_bin_width", "Rows (block rows) per bin", "MatBinBCSRSetBinWidth", bw, &bw, &set));
    if (set) PetscCall(MatBinBCSRSetBinWidth(A, bw));
  }
  {
    MatBinBCSRPrecision p;
    PetscBool           set;
    PetscCall(MatBinBCSRGetPrecision(A, &p));
    PetscCall(PetscOptionsEnum("-mat_binbcsr_precision", "Storage precision of the values (products accumulate in double)", "MatBinBCSRSetPrecision", MatBinBCSRPrecisions, (PetscEnum)p, (PetscEnum *)&p, &set));
    if (set) PetscCall(MatBinBCSRSetPrecision(A, p));
  }
  {
    PetscBool sym, set;
    PetscCall(MatBinBCSRGetSymmetricStorage(A, &sym));
    PetscCall(PetscOptionsBool("-mat_binbcsr_symmetric_storage", "Store the upper triangle only (symmetric matrices; the lower triangle given is ignored; on several ranks, of the diagonal part)", "MatBinBCSRSetSymmetricStorage", sym, &sym, &set));
    if (set) PetscCall(MatBinBCSRSetSymmetricStorage(A, sym));
  }
  {
    PetscBool mirror, set;
    PetscCall(MatBinBCSRGetCOOMirror(A, &mirror));
    PetscCall(PetscOptionsBool("-mat_binbcsr_coo_mirror", "COO entries of off-diagonal blocks also fill the transposed place (give one triangle of a symmetric matrix)", "MatBinBCSRSetCOOMirror", mirror, &mirror, &set));
    if (set) PetscCall(MatBinBCSRSetCOOMirror(A, mirror));
  }
  {
    PetscInt  streams;
    PetscBool set;
    PetscCall(MatBinBCSRGetStreams(A, &streams));
    PetscCall(PetscOptionsInt("-mat_binbcsr_streams", "Runs of bins the product sweeps side by side (1, 2, 4, 8)", "MatBinBCSRSetStreams", streams, &streams, &set));
    if (set) PetscCall(MatBinBCSRSetStreams(A, streams));
  }
  PetscFunctionReturn(0);
}
