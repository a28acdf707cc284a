/*
   Private header of MATSEQBINBCSR.

   The BIN-BCSR layout
   -------------------
   The matrix has mbs block rows of bs x bs blocks (bs = 3: BIN-BCSR; bs = 1: BIN-CSR). Block rows
   are grouped into bins of bw ("bin width") consecutive rows; bin b holds rows b*bw .. b*bw+bw-1
   (the last bin is completed with phantom rows that store only padding). Each row of the bin is a
   lane. A bin is padded to its own longest row, len_b, so it holds len_b * bw slots; the slots are
   interleaved: entry k of lane l is slot

        s = bin_start[b] + k * bw + l,

   so one sweep over k feeds all bw lanes from contiguous memory (SIMD lanes on a CPU, threads of a
   warp on a GPU), and no lane needs a reduction afterwards. Every slot has one block column
   index, col[s]. Padding slots hold zero values and a valid column (the lane's last real column),
   so kernels run without branches.

   The bs*bs values of a slot are stored entry-plane by entry-plane within each group of bw slots
   (a "tile"): entry e (row-major in the block, e = i*bs + j) of slot s is

        val[(s - l) * bs2 + e * bw + l]        with l = s % bw (the lane),

   so for fixed k and e the bw lanes' values are contiguous as well.

   Worked example: bs = 1, bw = 2, the 5x5 matrix

        [ a . b . . ]        rows 0,1 -> bin 0, longest row 2 -> 4 slots
        [ . c . . . ]        rows 2,3 -> bin 1, longest row 3 -> 6 slots
        [ d . e f g ]        row  4   -> bin 2 (lane 1 phantom), longest 1 -> 2 slots
        [ . . . h . ]
        [ . . . . i ]

     bin_start = [0, 4, 10, 12]
     slot:  0  1  2  3 |  4  5  6  7  8  9 | 10 11
     col:   0  1  2  1 |  0  3  2  3  3  3 |  4  4
     val:   a  c  b  0 |  d  h  e  0  f  0 |  i  0
            k=0   k=1    k=0   k=1   k=2     k=0

   (row 1's slot k=1 and row 3's slots k=1,2 are padding: zero values, repeated last column).
   The padding overhead is nslots / nz - 1 (here 12/9 - 1 = 33%; FEM matrices give a few %).
*/
#ifndef BINBCSR_SEQ_H
#define BINBCSR_SEQ_H

#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

struct BinBCSRStaging; /* the pattern and values while the matrix is being filled for the first time */

typedef struct {
  /* configuration */
  PetscInt            bw;        /* bin width: (block) rows per bin */
  MatBinBCSRPrecision precision; /* value storage; products accumulate in double */

  /* the bin layout: valid once built (first final assembly) */
  PetscBool  built;
  PetscInt   bs, bs2;      /* block size and its square */
  PetscInt   mbs, nbs;     /* block rows, block columns */
  PetscInt   nbins;        /* ceil(mbs / bw) */
  PetscInt  *bin_start;    /* [nbins + 1]: first slot of each bin (a multiple of bw) */
  PetscInt  *row_nz;       /* [mbs]: stored blocks of each row, padding excluded */
  PetscInt  *diag_slot;    /* [mbs]: slot of the diagonal block, -1 if the row has none */
  PetscInt  *col;          /* [nslots]: block column of each slot */
  PetscInt   nslots;       /* bin_start[nbins] */
  PetscInt   nz;           /* stored blocks (sum of row_nz) */
  MatScalar *val;          /* [nslots * bs2] when precision is double, else NULL */
  float     *valf;         /* [nslots * bs2] when precision is single, else NULL */

  struct BinBCSRStaging *staging; /* non-NULL until the layout is built */

  /* COO assembly: slot-entry v (v = s * bs2 + e in the value-index space) sums the COO entries
     coo_perm[coo_jmap[v] .. coo_jmap[v+1]-1]. */
  PetscCount  coo_n;
  PetscCount *coo_jmap;
  PetscCount *coo_perm;
} Mat_SeqBinBCSR;

/* Lane of slot s, and the index into val/valf of entry e of slot s. */
static inline PetscInt BinBCSRLane(PetscInt s, PetscInt bw) { return s % bw; }
static inline PetscInt BinBCSRValueIndex(PetscInt s, PetscInt e, PetscInt bw, PetscInt bs2)
{
  const PetscInt l = s % bw;
  return (s - l) * bs2 + e * bw + l;
}

/* Filled by the second part of the implementation (binbcsr_ops.cpp); called at the end of
   MatCreate_SeqBinBCSR so both parts contribute to one ops table. */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRSetOps_Ops(Mat);

#endif
