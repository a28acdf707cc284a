/* The public functions of MATBINBCSR's tuner (include/petscbinbcsr.h): whether the layout build times
   its candidates on this machine, and whether the choices are kept in the cache file. The tuner
   itself is src/mat_binbcsr/seq/binbcsr_tune.cpp; docs/tuning.md describes it. */
#include "binbcsr_impl.h"

/*@
   MatBinBCSRSetTune - Sets whether the layout build of a `MATBINBCSR` matrix times the candidate bin
   widths, stream counts, body sets and prefetch distances on this machine and keeps the fastest

   Logically Collective

   Input Parameters:
+  A - the matrix
-  t - `MAT_BINBCSR_TUNE_AUTO` (the default) or `MAT_BINBCSR_TUNE_OFF` (the defaults, untimed)

   Options Database Keys:
+  -mat_binbcsr_tune <auto,off>          - sets the mode
.  -mat_binbcsr_tune_budget_ms <ms>      - the product time the trials may take (default about 50 ms or 40 products)
.  -mat_binbcsr_tune_min_kib <kib>       - smaller matrices take the defaults untimed (default 512)
-  -mat_binbcsr_tune_sample_mib <mib>    - the size of the slab of block rows the trials time

   Level: intermediate

   Notes:
   A bin width, stream count, body set, prefetch distance or x load set explicitly (by a call or an
   option) is never changed; the tuner chooses among the others. Set the mode before the layout is
   built. The choice and what was tried are shown by `MatView()` with `PETSC_VIEWER_ASCII_INFO`, and
   logged in the event BinBCSRTune; docs/tuning.md describes the trials. A no-op on matrices of
   other types.

.seealso: `MATBINBCSR`, `MatBinBCSRGetTune()`, `MatBinBCSRSetTuneCache()`, `MatBinBCSRSetBinWidth()`,
          `MatBinBCSRSetStreams()`, `MatBinBCSRSetKernel()`
@*/
PetscErrorCode MatBinBCSRSetTune(Mat A, MatBinBCSRTune t)
{
  PetscFunctionBegin;
  PetscValidHeaderSpecific(A, MAT_CLASSID, 1);
  PetscValidLogicalCollectiveEnum(A, t, 2);
  PetscCheck(t == MAT_BINBCSR_TUNE_OFF || t == MAT_BINBCSR_TUNE_AUTO, PetscObjectComm((PetscObject)A),
             PETSC_ERR_ARG_OUTOFRANGE,
             "Unknown tuning mode %d: MAT_BINBCSR_TUNE_OFF or MAT_BINBCSR_TUNE_AUTO", (int)t);
  PetscTryMethod(A, "MatBinBCSRSetTune_C", (Mat, MatBinBCSRTune), (A, t));
  PetscFunctionReturn(0);
}

/*@
   MatBinBCSRGetTune - Gets whether the layout build of a `MATBINBCSR` matrix tunes its bin width and
   stream count on this machine

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  t - the tuning mode; `MAT_BINBCSR_TUNE_OFF` on matrices of other types

   Level: advanced

.seealso: `MATBINBCSR`, `MatBinBCSRSetTune()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetTune, Mat, MAT_CLASSID, MatBinBCSRTune, PetscAssertPointer,
                   MAT_BINBCSR_TUNE_OFF)

/*@
   MatBinBCSRSetTuneCache - Sets whether the tuner of a `MATBINBCSR` matrix reads and writes its cache
   file of choices

   Logically Collective

   Input Parameters:
+  A   - the matrix
-  flg - `PETSC_TRUE` (the default) to look a matrix's class up before timing and to keep new choices

   Options Database Key:
.  -mat_binbcsr_tune_cache <bool> - sets it

   Level: advanced

   Notes:
   The file is $XDG_CACHE_HOME/petscbinbcsr/tune.txt, else ~/.cache/petscbinbcsr/tune.txt, one line
   per machine (CPU model, cores, body sets) and matrix class (block size, precision, storage, size
   and row-length spread). A second run of the same scene then starts tuned without timing. A file
   that cannot be read or is not a regular file of at most 1 MiB is ignored with a one-line warning;
   writes go to a temporary file renamed into place. Set it before the layout is built.

.seealso: `MATBINBCSR`, `MatBinBCSRGetTuneCache()`, `MatBinBCSRSetTune()`
@*/
BINBCSR_TRY_SETTER(MatBinBCSRSetTuneCache, Mat, MAT_CLASSID, PetscBool, PetscValidLogicalCollectiveBool)

/*@
   MatBinBCSRGetTuneCache - Gets whether the tuner of a `MATBINBCSR` matrix reads and writes its cache file

   Not Collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  flg - `PETSC_TRUE` if it uses the cache; `PETSC_FALSE` on matrices of other types

   Level: advanced

.seealso: `MATBINBCSR`, `MatBinBCSRSetTuneCache()`
@*/
BINBCSR_TRY_GETTER(MatBinBCSRGetTuneCache, Mat, MAT_CLASSID, PetscBool, PetscAssertPointer, PETSC_FALSE)
