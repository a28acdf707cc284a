/*
   petscbinbcsr.h: public interface of the binbcsr plug-in for PETSc 3.18.

   Types
     MATBINBCSR ("binbcsr")   BIN-CSR (block size 1) / BIN-BCSR (block size 3) sparse matrix;
                              picks MATSEQBINBCSR or MATMPIBINBCSR by communicator size.
     KSPMCG     ("mcg")       merged (single-reduction) preconditioned conjugate gradient.

   Use from a program linked against libpetscbinbcsr:  PetscCall(PetscBinBCSRRegisterAll());
   Use from any stock PETSc program:  -dll_append /path/to/libpetscbinbcsr.so
*/
#ifndef PETSCBINBCSR_H
#define PETSCBINBCSR_H

#include <petscmat.h>
#include <petscksp.h>

#define MATBINBCSR    "binbcsr"
#define MATSEQBINBCSR "seqbinbcsr"
#define MATMPIBINBCSR "mpibinbcsr"
#define KSPMCG        "mcg"

/* How matrix values are stored. Products always accumulate in double. */
typedef enum {
  MAT_BINBCSR_PRECISION_DOUBLE = 0,
  MAT_BINBCSR_PRECISION_SINGLE = 1
} MatBinBCSRPrecision;
PETSC_EXTERN const char *const MatBinBCSRPrecisions[];

/* Registers MATBINBCSR, MATSEQBINBCSR, MATMPIBINBCSR and KSPMCG (idempotent). */
PETSC_EXTERN PetscErrorCode PetscBinBCSRRegisterAll(void);
/* Entry point that PETSc's -dll_append / -dll_prepend loader calls. */
PETSC_EXTERN PetscErrorCode PetscDLLibraryRegister_petscbinbcsr(void);

/* Rows (block rows) per bin; options: -mat_binbcsr_bin_width. Set before the first final assembly.
   No-op on matrices of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetBinWidth(Mat, PetscInt);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetBinWidth(Mat, PetscInt *);
/* Value storage; option -mat_binbcsr_precision double|single. May be changed at any time
   (values are converted). No-op on matrices of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetPrecision(Mat, MatBinBCSRPrecision);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetPrecision(Mat, MatBinBCSRPrecision *);
/* Symmetric storage: only blocks on or above the block diagonal are stored (about half the bytes);
   values given below it (MatSetValues, COO) are ignored, as sbaij does with
   MAT_IGNORE_LOWER_TRIANGULAR; implies MAT_SYMMETRIC and MAT_SYMMETRY_ETERNAL. Square matrices
   only; set before the layout is built. Option -mat_binbcsr_symmetric_storage. The setter is a no-op
   and the getter answers PETSC_FALSE on matrices of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetSymmetricStorage(Mat, PetscBool);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetSymmetricStorage(Mat, PetscBool *);
/* COO mirror: every COO entry (i, j) whose block row and block column differ also adds its value at
   (j, i) (scalar (r, c) of block (I, J) lands at (c, r) of block (J, I)), so the caller of
   MatSetPreallocationCOO/MatSetValuesCOO lists one triangle of a symmetric matrix (plus the diagonal
   blocks in full) and the whole matrix is filled. Entries are summed as usual: a block listed in both
   triangles gets both its own and its twin's values. Square matrices; takes effect at the next
   MatSetPreallocationCOO. Option -mat_binbcsr_coo_mirror. The setter is a no-op and the getter
   answers PETSC_FALSE on matrices of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetCOOMirror(Mat, PetscBool);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetCOOMirror(Mat, PetscBool *);
/* MatSetValuesCOO() with the values in single precision (one float per COO entry, in the order of
   MatSetPreallocationCOO()): for a caller that fills a single-precision matrix, whose values are
   rounded to float on storage anyway; it writes and the refill reads half the bytes. Entries that sum
   into one value are summed in double, as MatSetValuesCOO() does. MATBINBCSR only (an error on other
   types); on MATMPIBINBCSR the entries sent to other ranks travel as PetscScalar. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetValuesCOOSingle(Mat, const float[], InsertMode);
/* Streams: the product y = A x (block size 1 or 3, bin width 4, 8, 16 or 32; whole or symmetric storage) sweeps
   this many runs of consecutive bins side by side, so one core streams the values from that many
   places at once (the hardware prefetcher keeps more cache lines in flight for several streams):
   1, 2, 4 or 8, default 4. A traversal order only: the layout, the results and every other
   operation are the same for any value, and it may change at any time. Option
   -mat_binbcsr_streams. The setter is a no-op and the getter answers 1 on matrices of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetStreams(Mat, PetscInt);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetStreams(Mat, PetscInt *);
/* Prefetch: how many bytes ahead of the slot group being multiplied the products (block size 1 or 3,
   bin width 4, 8, 16 or 32) prefetch the values in software; 0 turns the software prefetch off. A
   multiple of 64 in [0, 65536], default 4096, chosen by the tuner when not set. Results are the same for
   any value. Option -mat_binbcsr_prefetch. The setter is a no-op and the getter answers 0 on matrices
   of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetPrefetch(Mat, PetscInt);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetPrefetch(Mat, PetscInt *);
/* XLoad: how the whole-storage product of 3x3 blocks at bin width 8 with the AVX-512 body reads x_c
   for a slot group (8 lanes). LOADS (the default): in the bins where at least half of the groups'
   lanes read consecutive block columns, those groups load x with three vector loads and split it
   into components, the other groups (and every group of the other bins) gather; GATHER: every group
   gathers. The same x_c either way, so the same results; which is faster depends on the machine and
   the matrix (on a Zen 5 core the 48^3 stencil in double ran about 10% faster gathering, in single
   1.4x slower), so where it is not set the tuner times both and the matrix's first products
   decide again. Option -mat_binbcsr_xload loads|gather.
   Other shapes and bodies ignore it. The setter is a no-op and the getter answers LOADS on matrices
   of other types. */
typedef enum {
  MAT_BINBCSR_XLOAD_LOADS  = 0,
  MAT_BINBCSR_XLOAD_GATHER = 1
} MatBinBCSRXLoad;
PETSC_EXTERN const char *const MatBinBCSRXLoads[];
PETSC_EXTERN PetscErrorCode    MatBinBCSRSetXLoad(Mat, MatBinBCSRXLoad);
PETSC_EXTERN PetscErrorCode    MatBinBCSRGetXLoad(Mat, MatBinBCSRXLoad *);
/* Tuning on this machine (option -mat_binbcsr_tune auto|off, default auto): when the layout is built
   from the final pattern (first final assembly, COO preallocation, conversion, load), the bin width
   and the stream count, body set, prefetch distance and x load that were not set explicitly are
   chosen by timing products of a sample of the matrix with the candidates (widths 4, 8, 16, and 32 for
   block size 1; streams 1, 2, 4, 8; the body sets the CPU has; 0, 1024 and 4096 bytes; loads or
   gathers where MatBinBCSRSetXLoad applies), within about 40
   products or 50 ms of product time. Set before the layout is built. Matrices with under 512 KiB of
   values keep the defaults. -mat_view ::ascii_info says what was tried and chosen; log event BinBCSRTune.
   The setters are no-ops and the getters answer off / PETSC_FALSE on matrices of other types. */
typedef enum {
  MAT_BINBCSR_TUNE_OFF  = 0,
  MAT_BINBCSR_TUNE_AUTO = 1
} MatBinBCSRTune;
PETSC_EXTERN const char *const MatBinBCSRTunes[];
PETSC_EXTERN PetscErrorCode    MatBinBCSRSetTune(Mat, MatBinBCSRTune);
PETSC_EXTERN PetscErrorCode    MatBinBCSRGetTune(Mat, MatBinBCSRTune *);
/* The tuner's choices are kept per machine (CPU model, cores, kernel bodies) and matrix class (block
   size, precision, storage, size, row lengths) in $XDG_CACHE_HOME/petscbinbcsr/tune.txt (else
   ~/.cache/petscbinbcsr/tune.txt), so a later run takes them without timing. Option
   -mat_binbcsr_tune_cache (default true); false neither reads nor writes the file. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetTuneCache(Mat, PetscBool);
PETSC_EXTERN PetscErrorCode MatBinBCSRGetTuneCache(Mat, PetscBool *);

/* The body set that runs the products (the same results up to rounding; speed differs by CPU). */
typedef enum {
  MAT_BINBCSR_KERNEL_AUTO     = 0, /* the best set this CPU has (the default) */
  MAT_BINBCSR_KERNEL_PORTABLE = 1, /* plain C++ compiled for the build's baseline target: the reference */
  MAT_BINBCSR_KERNEL_AVX2     = 2, /* AVX2 + FMA */
  MAT_BINBCSR_KERNEL_AVX512   = 3  /* AVX-512, with hand-written bodies for 3x3 blocks at bin width 8 */
} MatBinBCSRKernel;
PETSC_EXTERN const char *const MatBinBCSRKernels[];
/*@
   MatBinBCSRSetKernel - Chooses the body set of the products of a MATBINBCSR matrix.

   Logically collective

   Input Parameters:
+  A - the matrix (a no-op on matrices of other types)
-  kernel - MAT_BINBCSR_KERNEL_AUTO (the best this CPU has), _PORTABLE, _AVX2 or _AVX512

   Options Database Key:
.  -mat_binbcsr_kernel <auto,portable,avx2,avx512> - the body set

   Notes:
   A set the CPU (or this build) lacks is an error. A set without a specialised body for the matrix's
   shape (block size, bin width, streams) runs the portable body there; MatBinBCSRGetKernel() and
   -mat_view ::ascii_info name the set in use. May change at any time: the layout is not touched.

   Level: advanced

.seealso: MatBinBCSRGetKernel(), MatBinBCSRSetStreams(), MatBinBCSRSetBinWidth()
@*/
PETSC_EXTERN PetscErrorCode MatBinBCSRSetKernel(Mat, MatBinBCSRKernel);
/*@
   MatBinBCSRGetKernel - The body set that runs the products of a MATBINBCSR matrix now (AUTO
   resolved; the portable set where the chosen one has no body for the matrix's shape).

   Not collective

   Input Parameter:
.  A - the matrix

   Output Parameter:
.  kernel - the set in use (MAT_BINBCSR_KERNEL_PORTABLE on matrices of other types)

   Level: advanced

.seealso: MatBinBCSRSetKernel()
@*/
PETSC_EXTERN PetscErrorCode MatBinBCSRGetKernel(Mat, MatBinBCSRKernel *);
/* Whether this build and CPU can run a body set (AUTO and PORTABLE: always). */
PETSC_EXTERN PetscErrorCode MatBinBCSRKernelAvailable(MatBinBCSRKernel, PetscBool *);
/* The -mat_binbcsr_* options of the options database (under the matrix's prefix) applied to a matrix
   whose type the program chose with MatSetType: MatSetFromOptions would also let -mat_type replace
   that type. A no-op on matrices of other types. */
PETSC_EXTERN PetscErrorCode MatBinBCSRSetFromOptions(Mat);

/* y = A x and *xdoty = the local (this rank's rows, unreduced) part of x^T y, in one pass over A when
   the matrix type provides it (composed "MatMultDotLocal_C"), otherwise MatMult and a local dot.
   The caller reduces the dot across ranks, typically together with other dots. */
PETSC_EXTERN PetscErrorCode MatMultDotLocal(Mat, Vec, Vec, PetscScalar *);

/* Device copy of a MATSEQBINBCSR (the device library, docs/gpu.md): NONE (default), REFERENCE (the
   host executor the GPU one is tested against), CUDA (an NVIDIA GPU; an error where this build has no
   cuda executor or the machine no GPU, never a silent fallback). After each final assembly or
   MatSetValuesCOO the device copy is refreshed (COO: the COO values are uploaded and gathered on the
   device); MatMult on host vectors copies x in and y out (slow: event BinBCSRDevMult); KSPMCG with
   PCJACOBI or PCNONE runs the whole solve on the device. One process only: MATMPIBINBCSR refuses a
   device. Option -mat_binbcsr_device none|reference|cuda. A no-op on matrices of other types. */
typedef enum {
  MAT_BINBCSR_DEVICE_NONE      = 0,
  MAT_BINBCSR_DEVICE_REFERENCE = 1,
  MAT_BINBCSR_DEVICE_CUDA      = 2
} MatBinBCSRDevice;
PETSC_EXTERN const char *const MatBinBCSRDevices[];
PETSC_EXTERN PetscErrorCode    MatBinBCSRSetDevice(Mat, MatBinBCSRDevice);
PETSC_EXTERN PetscErrorCode    MatBinBCSRGetDevice(Mat, MatBinBCSRDevice *);

/* KSPMCG: run exactly n iterations per solve, computing no norm (n = 0: off, use the tolerances).
   Option -ksp_mcg_fixed_iterations n. */
PETSC_EXTERN PetscErrorCode KSPMCGSetFixedIterations(KSP, PetscInt);
PETSC_EXTERN PetscErrorCode KSPMCGGetFixedIterations(KSP, PetscInt *);

/* KSPMCG: the last solve's precision floor u ||A|| ||x|| (2-norm of b - A x; 0: none, the operator's
   products are not rounded below double) and whether the solve stopped there before its tolerance
   (KSP_DIVERGED_BREAKDOWN). 0 and PETSC_FALSE on solvers of other types. */
PETSC_EXTERN PetscErrorCode KSPMCGGetPrecisionFloor(KSP, PetscReal *, PetscBool *);

/* KSPMCG's other settings (each a no-op on other solvers; the getters give PETSC_FALSE or 0 there):
   the fused preconditioner (-ksp_mcg_fused_pc), the check on the true residual before claiming
   convergence (-ksp_mcg_verify_residual), the factor each restart must shrink it by
   (-ksp_mcg_stagnation, in (0, 1]) and the relative rounding of the precision floor
   (-ksp_mcg_precision_floor: -1 from the matrix, 0 off, or in (0, 1)). */
PETSC_EXTERN PetscErrorCode KSPMCGSetFusedPC(KSP, PetscBool);
PETSC_EXTERN PetscErrorCode KSPMCGGetFusedPC(KSP, PetscBool *);
PETSC_EXTERN PetscErrorCode KSPMCGSetVerifyResidual(KSP, PetscBool);
PETSC_EXTERN PetscErrorCode KSPMCGGetVerifyResidual(KSP, PetscBool *);
PETSC_EXTERN PetscErrorCode KSPMCGSetStagnation(KSP, PetscReal);
PETSC_EXTERN PetscErrorCode KSPMCGGetStagnation(KSP, PetscReal *);
PETSC_EXTERN PetscErrorCode KSPMCGSetPrecisionFloorRounding(KSP, PetscReal);
PETSC_EXTERN PetscErrorCode KSPMCGGetPrecisionFloorRounding(KSP, PetscReal *);

#endif
