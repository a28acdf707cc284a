/* The public functions of MATBINBCSR (include/petscbinbcsr.h) and the type's manual page. Each
   dispatches to the composed implementation of the actual type (seq/ or mpi/) and does nothing on
   other types, so user code can call them unconditionally. */
#include "binbcsr_impl.h"
#include <petsc/private/matimpl.h>

/*MC
   MATBINBCSR - "binbcsr": the BIN-CSR (block size 1) and BIN-BCSR (block size 3) sparse matrix, a
   format whose products and updates read memory the way SIMD lanes and GPU warps want it. Picks
   `MATSEQBINBCSR` on one process and `MATMPIBINBCSR` on several.

   Options Database Keys:
+  -mat_type binbcsr                        - the type (the block size from `MatSetBlockSize()` or -mat_block_size)
.  -mat_binbcsr_bin_width <bw>              - rows (block rows) per bin, see `MatBinBCSRSetBinWidth()`
.  -mat_binbcsr_precision <double,single>   - value storage, see `MatBinBCSRSetPrecision()`
.  -mat_binbcsr_symmetric_storage           - upper block triangle only, see `MatBinBCSRSetSymmetricStorage()`
.  -mat_binbcsr_coo_mirror                  - COO entries fill their transposed place, see `MatBinBCSRSetCOOMirror()`
.  -mat_binbcsr_streams <k>                 - runs of bins the product sweeps side by side, see `MatBinBCSRSetStreams()`
.  -mat_binbcsr_prefetch <bytes>            - software prefetch distance of the products, see `MatBinBCSRSetPrefetch()`
.  -mat_binbcsr_xload <loads,gather>        - how products read x for consecutive columns, see `MatBinBCSRSetXLoad()`
-  -mat_mpibinbcsr_inner_type <type>        - type of the parts of `MATMPIBINBCSR` (default seqbinbcsr)

   Level: beginner

   Notes:
   Rows (block rows of bs x bs blocks) are grouped into bins of bw consecutive rows; each row of a bin
   is a lane. A bin is padded to its own longest row, and entry k of every lane lies side by side:
   entry k of lane l of bin b is slot bin_start[b] + k bw + l, so one sweep over k feeds all lanes
   from contiguous memory and no lane needs a reduction. Each slot has one block column; padding
   slots hold zero values and a valid column (the lane's last real one), so the kernels have no
   branches. The bs^2 values of the slots of one k are stored entry by entry: entry e of slot s is
   val[(s - l) bs^2 + e bw + l], l = s mod bw.

   The 5x5 matrix below with bw = 2 and scalar entries (bs = 1):
.vb
   [ a . b . . ]   bin 0: rows 0,1  longest row 2 -> 2 x 2 slots
   [ . c . . . ]   bin 1: rows 2,3  longest row 3 -> 3 x 2 slots
   [ d . e f . ]   bin 2: row 4 (+ a phantom lane) -> 1 x 2 slots
   [ . . . h . ]
   [ . . . . i ]        bin_start = [0, 4, 10, 12]

   slot :  0  1  2  3 |  4  5  6  7  8  9 | 10 11
   lane :  0  1  0  1 |  0  1  0  1  0  1 |  0  1
   col  :  0  1  2  1 |  0  3  2  3  3  3 |  4  0
   value:  a  c  b  0 |  d  h  e  0  f  0 |  i  0
           k=0   k=1     k=0   k=1   k=2     k=0
.ve
   The padding overhead is slots / stored blocks - 1 (here 12/8 - 1 = 50%; FEM matrices give a few
   percent). The layout is frozen at the first final assembly (or `MatSetPreallocationCOO()`, a
   conversion or a load): a later new nonzero location is an error unless `MAT_NEW_NONZERO_LOCATIONS`
   is false. `MATMPIBINBCSR` stores each process's rows as a diagonal and an off-diagonal part, both
   `MATSEQBINBCSR`, and overlaps the ghost exchange of `MatMult()` with the diagonal-part product.
   Operations the format does not do natively (submatrices, factorisations by external packages,
   graphs for `PCGAMG`, finite-difference colouring) go through an AIJ copy kept in step with the
   matrix. src/mat_binbcsr/seq/binbcsr.h defines the layout; docs/mat_binbcsr.md describes it.

.seealso: `MatCreate()`, `MatSetType()`, `MatBinBCSRSetBinWidth()`, `MatBinBCSRSetPrecision()`,
          `MatBinBCSRSetSymmetricStorage()`, `MatBinBCSRSetCOOMirror()`, `MatBinBCSRSetStreams()`,
          `MatBinBCSRSetFromOptions()`, `MatMultDotLocal()`, `KSPMCG`, `MATBAIJ`, `MATSELL`
M*/

/*@
   MatBinBCSRSetFromOptions - Applies the `-mat_binbcsr_*` options of the options database (under the
   matrix's prefix) to a `MATBINBCSR` matrix whose type the program chose

   Collective

   Input Parameter:
.  A - the matrix

   Options Database Keys:
+  -mat_binbcsr_bin_width <bw>       - rows (block rows) per bin, see `MatBinBCSRSetBinWidth()`
.  -mat_binbcsr_precision <double,single> - value storage, see `MatBinBCSRSetPrecision()`
.  -mat_binbcsr_symmetric_storage    - upper triangle only, see `MatBinBCSRSetSymmetricStorage()`
.  -mat_binbcsr_coo_mirror           - COO entries fill their transposed place, see `MatBinBCSRSetCOOMirror()`
.  -mat_binbcsr_streams <k>          - runs of bins swept side by side, see `MatBinBCSRSetStreams()`
.  -mat_binbcsr_prefetch <bytes>     - software prefetch distance, see `MatBinBCSRSetPrefetch()`
-  -mat_binbcsr_xload <loads,gather> - how products read x for consecutive columns, see `MatBinBCSRSetXLoad()`

   Level: beginner

   Note:
   `MatSetFromOptions()` reads the same options but also lets `-mat_type` replace the type the program
   set with `MatSetType()`. A no-op on matrices of other types.

.seealso: `MATBINBCSR`, `MatSetFromOptions()`
@*/
PetscErrorCode MatBinBCSRSetFromOptions(Mat A)
{
  PetscErrorCode (*is_binbcsr)(Mat, PetscInt) = nullptr;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscCall(PetscObjectQueryFunction((PetscObject)A, "MatBinBCSRSetBinWidth_C", &is_binbcsr));
  if (!is_binbcsr || !A->ops->setfromoptions) PetscFunctionReturn(0);
  /* a bad value is an error the caller may handle: the options block (a scope of its own) is ended
     either way, so that its strings are not left behind */
  PetscErrorCode ierr;
  PetscObjectOptionsBegin((PetscObject)A);
  ierr = (*A->ops->setfromoptions)(A, PetscOptionsObject);
  PetscOptionsEnd();
  PetscCall(ierr);
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRSetBinWidth - Sets the number of rows (block rows) per bin of a `MATBINBCSR` matrix

   Logically Collective

   Input Parameters:
+  A  - the matrix
-  bw - rows (block rows) per bin, in [1, 1024]; on one process `PETSC_DEFAULT` restores the default

   Options Database Key:
.  -mat_binbcsr_bin_width <bw> - sets the bin width

   Level: intermediate

   Notes:
   Without it the tuner times the candidate widths on this machine and matrix (`MatBinBCSRSetTune()`);
   with the tuner off the default is 8 block rows for block size 3 and 16 rows for block size 1
   (docs/mat_binbcsr.md). A width set here is never changed by the tuner. Set it before the layout is built: the first final
   assembly, `MatSetPreallocationCOO()`, a conversion or a load. A no-op on matrices of other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetBinWidth()`
@*/
BINBCSR_TRY_SETTER(MatBinBCSRSetBinWidth, Mat, MAT_CLASSID, PetscInt, PetscValidLogicalCollectiveInt)

/*@
   MatBinBCSRGetBinWidth - Gets the number of rows (block rows) per bin of a `MATBINBCSR` matrix

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  bw - the bin width the layout has or will have; 0 on matrices of other types

   Level: intermediate

.seealso: `MATBINBCSR`, `MatBinBCSRSetBinWidth()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetBinWidth, Mat, MAT_CLASSID, PetscInt, PetscAssertPointer, 0)

/*@
   MatBinBCSRSetPrecision - Sets the storage precision of the values of a `MATBINBCSR` matrix

   Logically Collective

   Input Parameters:
+  A - the matrix
-  p - `MAT_BINBCSR_PRECISION_DOUBLE` (default) or `MAT_BINBCSR_PRECISION_SINGLE`

   Options Database Key:
.  -mat_binbcsr_precision <double,single> - sets the precision

   Level: intermediate

   Notes:
   Products always accumulate in double; single storage halves the bytes a product streams. The
   precision may be changed at any time: the stored values are converted. A no-op on matrices of
   other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetPrecision()`, `MatBinBCSRPrecision`
@*/
BINBCSR_TRY_SETTER(MatBinBCSRSetPrecision, Mat, MAT_CLASSID, MatBinBCSRPrecision,
                   PetscValidLogicalCollectiveEnum)

/*@
   MatBinBCSRGetPrecision - Gets the storage precision of the values of a `MATBINBCSR` matrix

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  p - the precision; `MAT_BINBCSR_PRECISION_DOUBLE` on matrices of other types

   Level: intermediate

.seealso: `MATBINBCSR`, `MatBinBCSRSetPrecision()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetPrecision, Mat, MAT_CLASSID, MatBinBCSRPrecision, PetscAssertPointer,
                   MAT_BINBCSR_PRECISION_DOUBLE)

/*@
   MatBinBCSRSetSymmetricStorage - Stores only the blocks on and above the block diagonal of a
   symmetric `MATBINBCSR` matrix

   Logically Collective

   Input Parameters:
+  A   - the matrix, square
-  flg - `PETSC_TRUE` for symmetric storage

   Options Database Key:
.  -mat_binbcsr_symmetric_storage - sets symmetric storage

   Level: intermediate

   Notes:
   About half the bytes of whole storage. Values given below the block diagonal (`MatSetValues()`,
   COO) are ignored, as `MATSBAIJ` does with `MAT_IGNORE_LOWER_TRIANGULAR`; the matrix is marked
   `MAT_SYMMETRIC` and `MAT_SYMMETRY_ETERNAL`. The product scatters the transposed blocks without
   atomics, by an edge colouring of each bin. On several processes the diagonal part is stored this
   way and the off-diagonal part stays whole. Set before the layout is built. A no-op on matrices of
   other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetSymmetricStorage()`, `MatBinBCSRSetCOOMirror()`
@*/
BINBCSR_TRY_SETTER(MatBinBCSRSetSymmetricStorage, Mat, MAT_CLASSID, PetscBool,
                   PetscValidLogicalCollectiveBool)

/*@
   MatBinBCSRGetSymmetricStorage - Tells whether a `MATBINBCSR` matrix stores only its upper block triangle

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  flg - `PETSC_TRUE` for symmetric storage; `PETSC_FALSE` on matrices of other types

   Level: intermediate

.seealso: `MATBINBCSR`, `MatBinBCSRSetSymmetricStorage()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetSymmetricStorage, Mat, MAT_CLASSID, PetscBool, PetscAssertPointer,
                   PETSC_FALSE)

/*@
   MatBinBCSRSetCOOMirror - Makes every COO entry of an off-diagonal block also add its value at the
   transposed place, so that the caller lists one triangle of a symmetric matrix

   Logically Collective

   Input Parameters:
+  A   - the matrix, square
-  flg - `PETSC_TRUE` to mirror

   Options Database Key:
.  -mat_binbcsr_coo_mirror - sets the mirror

   Level: advanced

   Notes:
   Entry (r, c) of block (I, J), I != J, also lands at (c, r) of block (J, I); the diagonal blocks are
   listed in full. Entries are summed as usual: a block listed in both triangles gets both its own and
   its twin's values. Takes effect at the next `MatSetPreallocationCOO()`. A no-op on matrices of other
   types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetCOOMirror()`, `MatSetPreallocationCOO()`, `MatSetValuesCOO()`
@*/
BINBCSR_TRY_SETTER(MatBinBCSRSetCOOMirror, Mat, MAT_CLASSID, PetscBool, PetscValidLogicalCollectiveBool)

/*@
   MatBinBCSRGetCOOMirror - Tells whether COO entries of a `MATBINBCSR` matrix are mirrored

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  flg - `PETSC_TRUE` if mirrored; `PETSC_FALSE` on matrices of other types

   Level: advanced

.seealso: `MATBINBCSR`, `MatBinBCSRSetCOOMirror()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetCOOMirror, Mat, MAT_CLASSID, PetscBool, PetscAssertPointer, PETSC_FALSE)

/*@
   MatBinBCSRSetValuesCOOSingle - `MatSetValuesCOO()` with the values in single precision

   Collective

   Input Parameters:
+  A     - a `MATBINBCSR` matrix preallocated with `MatSetPreallocationCOO()`
.  v     - one value per COO entry, in the order of the preallocation (may be `NULL`: zeros)
-  imode - `INSERT_VALUES` or `ADD_VALUES`

   Level: advanced

   Notes:
   For a program that fills a matrix stored in single precision (`MatBinBCSRSetPrecision()`) from
   values it computes every step: they are rounded to float on storage in any case, so the program can
   write them as floats, and it writes and the refill reads half the bytes (a 3x3-block scene of 93,000
   listed blocks: 3.4 instead of 6.7 MB per refill). The entries that sum into one stored value are
   summed in double, as `MatSetValuesCOO()` sums them, so a float list of the values a double list
   holds rounded gives the same matrix as that double list. A double-precision matrix takes the floats
   as they are.

   On `MATMPIBINBCSR` the parts read the floats as the sequential type does; the entries other ranks
   own travel as `PetscScalar` (parts of another inner type get every value widened). Matrices of other
   types have no such entry point: an error.

.seealso: `MATBINBCSR`, `MatSetValuesCOO()`, `MatSetPreallocationCOO()`, `MatBinBCSRSetPrecision()`,
          `MatBinBCSRSetCOOMirror()`
@*/
PetscErrorCode MatBinBCSRSetValuesCOOSingle(Mat A, const float v[], InsertMode imode)
{
  PetscErrorCode (*f)(Mat, const float[], InsertMode) = nullptr;

  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidType(A, 1);
  MatCheckPreallocated(A, 1);
  PetscValidLogicalCollectiveEnum(A, imode, 3);
  PetscCall(PetscObjectQueryFunction((PetscObject)A, "MatBinBCSRSetValuesCOOSingle_C", &f));
  PetscCheck(f, PetscObjectComm((PetscObject)A), PETSC_ERR_SUP,
             "MatBinBCSRSetValuesCOOSingle: matrices of type %s take MatSetValuesCOO()",
             ((PetscObject)A)->type_name);
  /* what MatSetValuesCOO() does around the type's refill */
  PetscCall(PetscLogEventBegin(MAT_SetVCOO, A, 0, 0, 0));
  PetscCall((*f)(A, v, imode));
  PetscCall(PetscLogEventEnd(MAT_SetVCOO, A, 0, 0, 0));
  PetscCall(PetscObjectStateIncrease((PetscObject)A));
  PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRSetStreams - Sets how many runs of consecutive bins the product y = A x sweeps side by side

   Logically Collective

   Input Parameters:
+  A       - the matrix
-  streams - 1, 2, 4 or 8 (default 4)

   Options Database Key:
.  -mat_binbcsr_streams <k> - sets the number of runs

   Level: advanced

   Notes:
   One core then streams the values from that many places at once, which the hardware prefetcher
   serves faster than one stream (block size 1 or 3; bin width 4, 8, 16 or 32; whole or symmetric
   storage). A traversal order only: the layout, the results and every other operation are the same
   for any value, and it may change at any time. A no-op on matrices of other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetStreams()`
@*/
PetscErrorCode MatBinBCSRSetStreams(Mat A, PetscInt streams)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveInt(A, streams, 2);
  PetscCheck(streams == 1 || streams == 2 || streams == 4 || streams == 8, PetscObjectComm((PetscObject)A),
             PETSC_ERR_ARG_OUTOFRANGE, "Streams %" PetscInt_FMT ": must be 1, 2, 4 or 8", streams);
  PetscTryMethod(A, "MatBinBCSRSetStreams_C", (Mat, PetscInt), (A, streams));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRGetStreams - Gets how many runs of bins the product of a `MATBINBCSR` matrix sweeps side by side

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  streams - the number of runs; 1 on matrices of other types

   Level: advanced

.seealso: `MATBINBCSR`, `MatBinBCSRSetStreams()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetStreams, Mat, MAT_CLASSID, PetscInt, PetscAssertPointer, 1)

/*@
   MatBinBCSRSetPrefetch - Sets how many bytes ahead of the values being multiplied the products of a
   `MATBINBCSR` matrix prefetch them in software

   Logically Collective

   Input Parameters:
+  A     - the matrix
-  bytes - a multiple of 64 in [0, 65536]; 0 turns the software prefetch off (default 4096)

   Options Database Key:
.  -mat_binbcsr_prefetch <bytes> - sets the distance

   Level: advanced

   Notes:
   One core reading the values out of memory is limited by the cache lines it has in flight; a
   software prefetch far enough ahead keeps more of them in flight on some machines and gets in the
   hardware prefetcher's way on others (4096 bytes ran the 48^3 stencil at 93% of the read bandwidth on
   a Sapphire Rapids core and 1.7x slower than no prefetch on a Zen 5 VM in some minutes). Where it is
   not set, the tuner (`MatBinBCSRSetTune()`) times 0, 1024 and 4096 at the chosen width and streams.
   Applies to the vectorised products (block size 1 or 3, bin width 4, 8, 16 or 32, whole or symmetric
   storage); results are the same for any value, and it may change at any time. A no-op on matrices of
   other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetPrefetch()`, `MatBinBCSRSetStreams()`
@*/
PetscErrorCode MatBinBCSRSetPrefetch(Mat A, PetscInt bytes)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveInt(A, bytes, 2);
  PetscCheck(bytes >= 0 && bytes <= 65536 && bytes % 64 == 0, PetscObjectComm((PetscObject)A),
             PETSC_ERR_ARG_OUTOFRANGE,
             "Prefetch distance %" PetscInt_FMT ": must be a multiple of 64 in [0, 65536]", bytes);
  PetscTryMethod(A, "MatBinBCSRSetPrefetch_C", (Mat, PetscInt), (A, bytes));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRGetPrefetch - Gets how many bytes ahead the products of a `MATBINBCSR` matrix prefetch the values

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  bytes - the distance (0: no software prefetch); 0 on matrices of other types

   Level: advanced

.seealso: `MATBINBCSR`, `MatBinBCSRSetPrefetch()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetPrefetch, Mat, MAT_CLASSID, PetscInt, PetscAssertPointer, 0)

const char *const MatBinBCSRXLoads[] = {"loads", "gather", "MatBinBCSRXLoad", "MAT_BINBCSR_XLOAD_", nullptr};

/*@
   MatBinBCSRSetXLoad - Sets how the products of a `MATBINBCSR` matrix read x for a slot group whose
   lanes read consecutive block columns: vector loads where the bin's hint allows, or gathers

   Logically Collective

   Input Parameters:
+  A     - the matrix
-  xload - `MAT_BINBCSR_XLOAD_LOADS` (default) or `MAT_BINBCSR_XLOAD_GATHER`

   Options Database Key:
.  -mat_binbcsr_xload <loads,gather> - sets it

   Level: advanced

   Notes:
   Applies to the whole-storage product of 3x3 blocks at bin width 8 with the AVX-512 body; other
   shapes and bodies ignore it. With loads, the bins where at least half of the slot groups read
   consecutive block columns load x for those groups (three vector loads, six permutes) and every other
   group reads it lane by lane (one masked load per lane and a transpose); with gather every group
   gathers (three gather instructions). Both read the same x, so the results are the same. Which is
   faster depends on the machine and the matrix: on a Zen 5 core the 48^3 stencil's product in double
   ran about 10% faster gathering and in single 1.4x slower, and its gathers lost to the lane loads
   on FE matrices. Where it is not set, the tuner (`MatBinBCSRSetTune()`) times both on a sample and
   the matrix's first products (after an untimed one, eight alternating) decide again; setting it ends
   that. It may change at any time. A no-op on matrices of other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetXLoad()`, `MatBinBCSRSetTune()`
@*/
PetscErrorCode MatBinBCSRSetXLoad(Mat A, MatBinBCSRXLoad xload)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveEnum(A, xload, 2);
  PetscCheck(xload == MAT_BINBCSR_XLOAD_LOADS || xload == MAT_BINBCSR_XLOAD_GATHER,
             PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_OUTOFRANGE,
             "Unknown x load %d: MAT_BINBCSR_XLOAD_LOADS or MAT_BINBCSR_XLOAD_GATHER", (int)xload);
  PetscTryMethod(A, "MatBinBCSRSetXLoad_C", (Mat, MatBinBCSRXLoad), (A, xload));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRGetXLoad - Gets how the products of a `MATBINBCSR` matrix read x for consecutive columns

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  xload - `MAT_BINBCSR_XLOAD_LOADS` or `MAT_BINBCSR_XLOAD_GATHER` (set, or chosen by the tuner);
           `MAT_BINBCSR_XLOAD_LOADS` on matrices of other types

   Level: advanced

.seealso: `MATBINBCSR`, `MatBinBCSRSetXLoad()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetXLoad, Mat, MAT_CLASSID, MatBinBCSRXLoad, PetscAssertPointer,
                   MAT_BINBCSR_XLOAD_LOADS)
