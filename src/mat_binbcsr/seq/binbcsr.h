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
        [ d . e f . ]        row  4   -> bin 2 (lane 1 phantom), longest 1 -> 2 slots
        [ . . . h . ]
        [ . . . . i ]

     bin_start = [0, 4, 10, 12]
     slot:  0  1  2  3 |  4  5  6  7  8  9 | 10 11
     col:   0  1  2  1 |  0  3  2  3  3  3 |  4  0
     val:   a  c  b  0 |  d  h  e  0  f  0 |  i  0
            k=0   k=1    k=0   k=1   k=2     k=0

   (row 1's slot k=1 and row 3's slots k=1,2 are padding: zero values, repeated last column; the
   phantom lane of bin 2 has no column, its padding reads column 0). The padding overhead is
   nslots / nz - 1 (here 12/8 - 1 = 50%; FEM matrices give a few %). tests/unit/mat_binbcsr/mat_core/layout.cpp
   checks this example.
*/
#ifndef BINBCSR_SEQ_H
#define BINBCSR_SEQ_H

#include "binbcsr_impl.h"
#include "../kernels/binbcsr_layout.h"
#include "../kernels/binbcsr_dispatch.h"
#include <petsc/private/matimpl.h>
#include <vector>

/* The COO value maps (coo_jmap, coo_perm) of a matrix and its duplicates: how many hold them. */
struct BinBCSRSharedCOO {
  int refs;
};

struct BinBCSRStaging; /* the pattern and values while the matrix is being filled for the first time
                          (private to binbcsr.cpp: per block row, sorted block columns and values) */

typedef struct {
  /* configuration */
  PetscInt            bw;           /* bin width: (block) rows per bin */
  PetscBool           bw_set;       /* set by the user; otherwise the layout build takes the default of
                                    its block size (BinBCSRDefaultBinWidth) */
  MatBinBCSRPrecision precision;    /* value storage; products accumulate in double */
  PetscInt            nonew;        /* 0: new nonzeros allowed (only before the layout exists);
                                    1: new locations silently ignored (MAT_NEW_NONZERO_LOCATIONS false);
                                   -1: error (MAT_NEW_NONZERO_LOCATION_ERR); -2: error beyond the
                                    preallocation (MAT_NEW_NONZERO_ALLOCATION_ERR). Once the layout
                                    exists a new location is an error unless nonew == 1. */
  PetscBool           roworiented;  /* MAT_ROW_ORIENTED for MatSetValues(Blocked) */
  PetscInt            streams;      /* MatBinBCSRSetStreams: runs of bins the product sweeps side by side */
  PetscBool           streams_set;  /* set by the user before the layout build: the tuner keeps it */
  PetscInt            prefetch;     /* MatBinBCSRSetPrefetch: bytes the products prefetch values ahead */
  PetscBool           prefetch_set; /* set by the user: the tuner keeps it */
  PetscInt            tune; /* MatBinBCSRTune; -1: not set (the option, else auto, at the layout build) */
  PetscInt            tune_cache; /* MatBinBCSRSetTuneCache: 1 on, 0 off, -1 not set (the option, else on) */
  char                tune_info[768]; /* what the tuner tried and chose at the last layout build (MatView) */
  MatBinBCSRKernel    kernel; /* MatBinBCSRSetKernel: the body set asked for (AUTO: the best the CPU has) */
  PetscBool kernel_tuned;     /* kernel is the tuner's choice, not the user's (a rebuild may change it) */
  PetscBool sym;              /* symmetric storage: only blocks with block column >= block row
                                      are stored; entries below the block diagonal are ignored. The
                                      slots of a bin are ordered by an edge colouring (below). */

  MatBinBCSRXLoad xload;     /* MatBinBCSRSetXLoad: loads where bin_xload allows, or gathers everywhere */
  PetscBool       xload_set; /* set by the user: the tuner keeps it */
  /* the trial of the first products (binbcsr_mult.cpp): products left (0: none), the tuner's choice,
     each mode's fastest product in seconds */
  PetscInt xload_trial, xload_chosen;
  double   xload_sec[2];
  /* with the layout: [2 nbins], made at the first product that can use it (BinMatrix::bin_xload): the
     hint for loads, then zeros for gather (every group gathers) */
  unsigned char *bin_xload;

  /* the bin layout: valid once built (first final assembly, MatSetPreallocationCOO, MatConvert) */
  PetscBool  built;
  PetscInt   bs, bs2;    /* block size and its square */
  PetscInt   mbs, nbs;   /* block rows, block columns */
  PetscInt   nbins;      /* ceil(mbs / bw) */
  PetscInt  *bin_start;  /* [nbins + 1]: first slot of each bin (a multiple of bw) */
  PetscInt  *row_nz;     /* [mbs]: stored blocks of each row, padding excluded */
  PetscInt  *diag_slot;  /* [mbs]: slot of the diagonal block, -1 if the row has none */
  PetscInt  *col;        /* [nslots]: block column of each slot (32-bit: PETSc here has 32-bit PetscInt) */
  PetscInt   nslots;     /* bin_start[nbins] */
  PetscInt   nz;         /* stored blocks (sum of row_nz) */
  PetscInt   max_row_nz; /* longest row, in blocks */
  PetscInt  *row_off;    /* symmetric storage only: [mbs + 1] offsets into real_slot, else NULL */
  PetscInt  *real_slot;  /* symmetric storage only: [nz] the slots of each row's real blocks in
                              ascending column order (the colouring scatters them over the bin) */
  PetscInt  *lower_off;  /* symmetric storage, built on demand (MatGetRow): [mbs + 1] offsets */
  PetscInt  *lower_slot; /* [2 * (off-diagonal blocks)]: for block row r, (slot, c) of each stored
                              block (c, r), c < r, in ascending c: row r's lower part, transposed */
  MatScalar *val;        /* [nslots * bs2] when precision is double, else NULL */
  float     *valf;       /* [nslots * bs2] when precision is single, else NULL */
  void      *val_mem;    /* the allocation val or valf lies in (MatSeqBinBCSRAllocValues_Private) */
  size_t     val_map;    /* bytes of val_mem when it is a mapping of its own (large arrays), else 0 */

  struct BinBCSRStaging *staging; /* non-NULL between MatSetUp/preallocation and the layout build */

  /* COO assembly. The stored values of real (non-padding) slots are numbered q = 0, 1, ... in row
     order: bin by bin, lane by lane, then point row i of the block, block k of the row, column j of
     the block (the order of a CSR row, so consecutive values gather from the same elements).
     Value q is the sum of the COO entries coo_perm[coo_jmap[q] .. coo_jmap[q+1]-1]; coo_jmap has
     nz*bs2 + 1 entries. 32-bit indices (checked at preallocation) halve the bytes of the refill. */
  PetscBool
    coo_mirror; /* MatBinBCSRSetCOOMirror: entries of off-diagonal blocks also fill their transposed place */
  PetscCount coo_n;
  PetscInt  *coo_jmap;
  PetscInt  *coo_perm;
  /* Non-NULL when coo_jmap and coo_perm are shared with duplicates (MatDuplicate): the maps depend on
     the pattern only, and a copy of linear_38k's took 12 MB of fresh memory (~30 ms of page faults on
     a VM) for a duplicate that is mostly refilled by MatCopy. Freed by the last holder. */
  struct BinBCSRSharedCOO *coo_shared;
  PetscInt
    *coo_perm_src; /* coo_perm composed with a caller's source map (MatSeqBinBCSRComposeCOO), or NULL */
  PetscBool coo_composed;
  /* When every stored block is a sum of whole COO blocks of the list (bs2 consecutive entries, row-major,
     or transposed as the COO mirror makes them), the refill sums blocks: slot s sums the source blocks
     coo_slot_src[coo_slot_ptr[s] .. coo_slot_ptr[s+1]-1], each the source index of its entry (0, 0)
     (transposed: -1 - index); padding has none. Built at preallocation (or the first refill), for the split n between
     the two sources it was called with (coo_slot_n); coo_slot_state 0: not tried, 1: built, -1: the
     list is not made of whole blocks (the refill goes value by value). */
  PetscInt       *coo_slot_ptr;
  PetscInt       *coo_slot_src;
  const PetscInt *coo_slot_perm; /* the value map it was built from (coo_perm or coo_perm_src) */
  PetscCount      coo_slot_n;
  PetscInt        coo_slot_state;

  /* scratch */
  PetscBool        getrowactive;
  PetscInt        *rowbuf_cols; /* [max_row_nz * bs] for MatGetRow */
  PetscScalar     *rowbuf_vals;
  MatScalar       *idiag;     /* [mbs * bs2] MatInvertBlockDiagonal result (column-major blocks, as BAIJ) */
  MatScalar       *sor_idiag; /* [mbs * bs2] (D + sor_shift I)^-1 for MatSOR, valid for sor_state */
  PetscObjectState sor_state; /* state of the matrix when sor_idiag was computed (0: never) */
  PetscReal        sor_shift;
} Mat_SeqBinBCSR;

/* Default bin width, measured on this project's AVX-512 machine (docs/mat_binbcsr.md): 8 block rows
   for blocks (3x3: 24 scalar rows per bin), 16 rows for scalars. */
static inline PetscInt BinBCSRDefaultBinWidth(PetscInt bs) { return bs == 1 ? 16 : 8; }

/* The product body for a's shape and body set (binbcsr_mult.cpp; the choice is select_body's). */
binbcsr::Body MatSeqBinBCSRSelectBody(const Mat_SeqBinBCSR *a);
/* Whether products of this shape read the x load (MatBinBCSRSetXLoad): whole storage, 3x3 blocks,
   width 8, the AVX-512 body */
static inline bool BinBCSRShapeReadsXLoad(PetscBool sym, PetscInt bs, PetscInt bw, binbcsr::BodySet set)
{
  return !sym && bs == 3 && bw == 8 && set == binbcsr::BodySet::AVX512;
}
/* The same for a's products with the body it selects now */
PETSC_INTERN PetscBool MatSeqBinBCSRReadsXLoad(const Mat_SeqBinBCSR *a);
/* the bins' hint, made now if the body uses one (the tuner: not in a timed product) */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRXLoadHint(Mat);
/* the x load trial of the first products (binbcsr_mult.cpp): products, the first untimed */
#define BINBCSR_XLOAD_TRIAL 9

/* The value array of nv entries in the given precision (val or valf; the other stays NULL), 64-byte
   aligned: PETSc's allocator aligns to PETSC_MEMALIGN (16 bytes here), and a value array at 16 bytes
   past a cache line makes every 64-byte load of the AVX-512 bodies touch two lines; what the product
   then costs depended on where malloc happened to put the array (on a Zen 4 core the 48^3 stencil
   took 9 or 20 ms with the same layout). zero: the entries start at zero. Frees the previous array. */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRAllocValues_Private(Mat_SeqBinBCSR *, MatBinBCSRPrecision, size_t nv,
                                                             PetscBool zero);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRFreeValues_Private(Mat_SeqBinBCSR *);
/* Frees a val_mem of map bytes (0: PetscMalloc'd), when the caller took it out of the matrix. */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRReleaseValues_Private(void *mem, size_t map);
/* An array of `bytes` (4 MiB and more) in a mapping of its own, its start 2 MiB-aligned and marked for
   transparent huge pages before any page is touched; reads as zero. NULL where the size is smaller, the
   system has no such hint or the mapping fails (then *base is NULL). *base and *length: what
   MatSeqBinBCSRUnmapHuge (or the value arrays' release) takes back. Why huge pages: see
   MatSeqBinBCSRAllocValues_Private (binbcsr_build.cpp). */
PETSC_INTERN void *MatSeqBinBCSRMapHuge(size_t bytes, void **base, size_t *length);
PETSC_INTERN void  MatSeqBinBCSRUnmapHuge(void *base, size_t length);

/* Lane of slot s, and the index into val/valf of entry e of slot s. */
static inline PetscInt BinBCSRLane(PetscInt s, PetscInt bw) { return s % bw; }
static inline PetscInt BinBCSRValueIndex(PetscInt s, PetscInt e, PetscInt bw, PetscInt bs2)
{
  return (PetscInt)binbcsr::value_index(s, (int)e, (int)bw, (int)bs2);
}
/* Slot of the k-th real block (ascending column) of block row r, k < row_nz[r]. With full storage
   it is entry k of the lane; with symmetric storage the colouring decides. */
static inline PetscInt BinBCSRSlot(const Mat_SeqBinBCSR *a, PetscInt r, PetscInt k)
{
  if (a->real_slot) return a->real_slot[a->row_off[r] + k];
  return (PetscInt)binbcsr::row_slot<PetscInt>(a->bin_start, a->bw, r, k);
}
/* Value at value index v, whatever the storage precision. */
static inline PetscScalar BinBCSRGetValue(const Mat_SeqBinBCSR *a, PetscInt v)
{
  return a->val ? a->val[v] : (PetscScalar)a->valf[v];
}
static inline void BinBCSRSetValue(Mat_SeqBinBCSR *a, PetscInt v, PetscScalar x)
{
  if (a->val) a->val[v] = x;
  else a->valf[v] = (float)x;
}

/* Symmetric storage: the slot order of bin [r0, r0 + bw) by edge colouring (binbcsr_colour.cpp).
   bi/bj: the block pattern (sorted rows; entries below the diagonal are skipped). Returns the bin's
   slot groups L; slot_col gets L * bw columns (slot k of lane l at k * bw + l, padding: the lane's own
   row, mbs - 1 for phantom lanes); entry_k gets, lane by lane, the slot group of each upper block in
   column order. colid: [nbs] scratch, all -1 on entry and on exit. */
PetscInt MatSeqBinBCSRColourBin(PetscInt bw, PetscInt r0, PetscInt mbs, const PetscInt bi[],
                                const PetscInt bj[], std::vector<PetscInt> &slot_col,
                                std::vector<PetscInt> &entry_k, std::vector<PetscInt> &colid);

/* Symmetric storage: builds lower_off/lower_slot if missing (pattern is frozen, so once). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRBuildLowerIndex(Mat_SeqBinBCSR *);
/* The blocks of full block row br in ascending column: with symmetric storage the stored blocks (c, br),
   c < br, transposed, then the row's own; f(bc, vb, transposed) with vb the value index of the block's
   entry 0 (entry e at vb + e * bw). A slot's lane is its row's place in the bin: no division per block.
   Symmetric storage needs MatSeqBinBCSRBuildLowerIndex first. */
template <class F> static inline void ForEachFullRowBlock(const Mat_SeqBinBCSR *a, PetscInt br, F &&f)
{
  const PetscInt bw = a->bw, bs2 = a->bs2, l = br % bw;
  if (a->sym) {
    for (PetscInt p = a->lower_off[br]; p < a->lower_off[br + 1]; p++) {
      const PetscInt s = a->lower_slot[2 * p], c = a->lower_slot[2 * p + 1], lc = c % bw;
      f(c, (s - lc) * bs2 + lc, true);
    }
    for (PetscInt k = 0; k < a->row_nz[br]; k++) {
      const PetscInt s = a->real_slot[a->row_off[br] + k];
      f(a->col[s], (s - l) * bs2 + l, false);
    }
    return;
  }
  const PetscInt s0 = a->bin_start[br / bw] + l;
  for (PetscInt k = 0; k < a->row_nz[br]; k++) {
    const PetscInt s = s0 + k * bw;
    f(a->col[s], (s - l) * bs2 + l, false);
  }
}

/* The value index of entry (i, j) of a block that ForEachFullRowBlock gives at vb: entry (j, i) of the
   stored block when it is transposed. */
static inline PetscInt FullRowEntry(PetscInt vb, bool t, PetscInt i, PetscInt j, PetscInt bs, PetscInt bw)
{
  return vb + (t ? j * bs + i : i * bs + j) * bw;
}
/* Refuses an operation that symmetric storage does not provide. */
#define BinBCSRCheckNotSym(a, opname)                                                                                     \
  PetscCheck(                                                                                                             \
    !(a)->sym, PETSC_COMM_SELF, PETSC_ERR_SUP,                                                                            \
    "%s is not available for MATSEQBINBCSR with symmetric storage (upper triangle only; -mat_binbcsr_symmetric_storage)", \
    opname)

/* Both built with the same bins, slots and columns (block size, bin width, storage): their value arrays
   line up slot by slot (the precisions may differ). */
PETSC_INTERN PetscBool MatSeqBinBCSRSameLayout(const Mat_SeqBinBCSR *, const Mat_SeqBinBCSR *);
/* Slot of block (brow, bcol), -1 if the pattern has no such block (binary search in the lane). */
PETSC_INTERN PetscInt MatSeqBinBCSRFindSlot(const Mat_SeqBinBCSR *, PetscInt brow, PetscInt bcol);

/* Builds (or rebuilds) the bin layout from a block CSR pattern: bi[mbs+1], bj sorted and unique in
   each row. Values are zero, in the current precision. Drops staging and any COO map; increases the
   nonzero state. Used by assembly, COO preallocation, MatConvert and available to MatLoad. */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRBuildLayout(Mat, const PetscInt bi[], const PetscInt bj[]);
/* A new MATSEQBINBCSR of A's sizes and block sizes (swapped when transposed) and A's bin width,
   precision and storage, laid out for the block pattern bi/bj with zero values (binbcsr_build.cpp):
   where an operation makes a matrix of another pattern (MatAXPY, MatTranspose). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRCreateWithPattern(Mat A, PetscBool transposed, const PetscInt bi[],
                                                           const PetscInt bj[], Mat *B);
/* Before a layout build from the final pattern bi/bj: chooses a->bw and a->streams where they were not
   set explicitly, by timing products of a sample on this machine, or from the tuning cache
   (binbcsr_tune.cpp). A no-op with tuning off. */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRTune(Mat, const PetscInt bi[], const PetscInt bj[]);
/* After a precision change of a built matrix: the stream count and body set the tuner chose, timed
   again in the new precision at the layout's bin width (binbcsr_tune.cpp). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRRetune(Mat);
/* Block size and block counts from the layouts (set up here); the check every entry point shares
   (binbcsr_assembly.cpp). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRSetSizes(Mat);
/* Sizes checked, any layout and staging dropped (binbcsr_assembly.cpp): where a layout build starts. */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRResetLayout(Mat);

/* Before the layout exists: zero the staged values, keeping the staged pattern (MatZeroEntries). */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRStagingZeroValues(Mat);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRStagingDropLower(Mat);

/* ASCII MatView (info formats and the default entry listing). */
PETSC_INTERN PetscErrorCode MatView_SeqBinBCSR_ASCII(Mat, PetscViewer);

/* Staging, preallocation, MatSetValues and assembly (binbcsr_assembly.cpp) */
PETSC_INTERN PetscErrorCode MatSetUp_SeqBinBCSR(Mat);
PETSC_INTERN PetscErrorCode MatSeqAIJSetPreallocation_SeqBinBCSR(Mat, PetscInt, const PetscInt[]);
PETSC_INTERN PetscErrorCode MatSeqBAIJSetPreallocation_SeqBinBCSR(Mat, PetscInt, PetscInt, const PetscInt[]);
PETSC_INTERN PetscErrorCode MatSetValues_SeqBinBCSR(Mat, PetscInt, const PetscInt[], PetscInt,
                                                    const PetscInt[], const PetscScalar[], InsertMode);
PETSC_INTERN PetscErrorCode MatSetValuesBlocked_SeqBinBCSR(Mat, PetscInt, const PetscInt[], PetscInt,
                                                           const PetscInt[], const PetscScalar[], InsertMode);
PETSC_INTERN PetscErrorCode MatGetValues_SeqBinBCSR(Mat, PetscInt, const PetscInt[], PetscInt,
                                                    const PetscInt[], PetscScalar[]);
PETSC_INTERN PetscErrorCode MatAssemblyEnd_SeqBinBCSR(Mat, MatAssemblyType);
/* The layout, the staging and the COO map freed (MatDestroy) */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRFreeStorage(Mat_SeqBinBCSR *);

/* Parts of the ops table (binbcsr.cpp) implemented in the other files of this folder. */
PETSC_INTERN PetscErrorCode MatMult_SeqBinBCSR(Mat, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultAdd_SeqBinBCSR(Mat, Vec, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultTranspose_SeqBinBCSR(Mat, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultTransposeAdd_SeqBinBCSR(Mat, Vec, Vec, Vec);
PETSC_INTERN PetscErrorCode MatMultDotLocal_SeqBinBCSR(Mat, Vec, Vec, PetscScalar *);
PETSC_INTERN PetscErrorCode MatGetDiagonal_SeqBinBCSR(Mat, Vec);
PETSC_INTERN PetscErrorCode MatInvertBlockDiagonal_SeqBinBCSR(Mat, const PetscScalar **);
PETSC_INTERN PetscErrorCode MatInvertVariableBlockDiagonal_SeqBinBCSR(Mat, PetscInt, const PetscInt *,
                                                                      PetscScalar *);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRInvertDiagonalBlocks(Mat, PetscReal shift, MatScalar *out,
                                                              PetscInt *zero_row);
PETSC_INTERN PetscErrorCode MatSOR_SeqBinBCSR(Mat, Vec, PetscReal, MatSORType, PetscReal, PetscInt, PetscInt,
                                              Vec);
PETSC_INTERN PetscErrorCode MatMultDiagonalBlock_SeqBinBCSR(Mat, Vec, Vec);
PETSC_INTERN PetscErrorCode MatSetPreallocationCOO_SeqBinBCSR(Mat, PetscCount, const PetscInt[],
                                                              const PetscInt[]);
PETSC_INTERN PetscErrorCode MatSetValuesCOO_SeqBinBCSR(Mat, const PetscScalar[], InsertMode);
PETSC_INTERN PetscErrorCode MatBinBCSRSetValuesCOOSingle_SeqBinBCSR(Mat, const float[], InsertMode);
PETSC_INTERN PetscErrorCode MatGetRow_SeqBinBCSR(Mat, PetscInt, PetscInt *, PetscInt **, PetscScalar **);
PETSC_INTERN PetscErrorCode MatRestoreRow_SeqBinBCSR(Mat, PetscInt, PetscInt *, PetscInt **, PetscScalar **);
PETSC_INTERN PetscErrorCode MatDuplicate_SeqBinBCSR(Mat, MatDuplicateOption, Mat *);
PETSC_INTERN PetscErrorCode MatCopy_SeqBinBCSR(Mat, Mat, MatStructure);
PETSC_INTERN PetscErrorCode MatConvertFrom_SeqBinBCSR(Mat, MatType, MatReuse, Mat *);
PETSC_INTERN PetscErrorCode MatConvert_SeqBinBCSR_SeqAIJ(Mat, MatType, MatReuse, Mat *);
PETSC_INTERN PetscErrorCode MatConvert_SeqBinBCSR_SeqBAIJ(Mat, MatType, MatReuse, Mat *);
PETSC_INTERN PetscErrorCode MatView_SeqBinBCSR(Mat, PetscViewer);
/* Block row br's pattern from a matrix of any type with MatGetRow: the block columns (column / bs) of
   its point rows br bs .. br bs + bs - 1 added to bcols, which is left sorted and unique (binbcsr_convert.cpp) */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRAddBlockRowPattern(Mat X, PetscInt br, PetscInt bs,
                                                            std::vector<PetscInt> &bcols);
/* Value maps to and from a seqaij matrix over the same point pattern (binbcsr_aijmap.cpp) */
PETSC_INTERN PetscErrorCode MatSeqBinBCSRAIJValueMap(Mat B, Mat T, std::vector<PetscInt> &map);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRAIJGather(Mat B, const std::vector<PetscInt> &map, Mat T);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRAIJScatter(Mat T, const std::vector<PetscInt> &map, Mat B);
PETSC_INTERN PetscErrorCode MatGetRowIJ_SeqBinBCSR(Mat, PetscInt, PetscBool, PetscBool, PetscInt *,
                                                   const PetscInt *[], const PetscInt *[], PetscBool *);
PETSC_INTERN PetscErrorCode MatRestoreRowIJ_SeqBinBCSR(Mat, PetscInt, PetscBool, PetscBool, PetscInt *,
                                                       const PetscInt *[], const PetscInt *[], PetscBool *);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRDestroyCOO(Mat_SeqBinBCSR *);
PETSC_INTERN PetscErrorCode MatSeqBinBCSRDuplicateStaging(Mat, Mat, PetscBool copyvalues);

#endif
