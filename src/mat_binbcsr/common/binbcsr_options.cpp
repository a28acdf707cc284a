/* The -mat_binbcsr_* options, read for seq and mpi binbcsr alike (MatSetFromOptions of either type,
   and MatBinBCSRSetFromOptions): one place for each option's name, help string and manual page.

   Each option shows the matrix's current value as its default and, when given, is applied through
   the public setter, which dispatches to the type (an mpi matrix forwards it to its parts). To add an
   option: one line in MatBinBCSRReadOptions_Private with its public getter and setter (a helper
   below per value kind); both types then read it. */
#include "binbcsr_impl.h"

static PetscErrorCode OptionInt(PetscOptionItems *PetscOptionsObject, Mat A, const char *name,
                                const char *help, const char *man, PetscErrorCode (*get)(Mat, PetscInt *),
                                PetscErrorCode (*set)(Mat, PetscInt))
{
  PetscInt  v;
  PetscBool given;

  PetscFunctionBegin;
  PetscCall(get(A, &v));
  PetscCall(PetscOptionsInt(name, help, man, v, &v, &given));
  if (given) PetscCall(set(A, v));
  PetscFunctionReturn(0);
}

static PetscErrorCode OptionBool(PetscOptionItems *PetscOptionsObject, Mat A, const char *name,
                                 const char *help, const char *man, PetscErrorCode (*get)(Mat, PetscBool *),
                                 PetscErrorCode (*set)(Mat, PetscBool))
{
  PetscBool v, given;

  PetscFunctionBegin;
  PetscCall(get(A, &v));
  PetscCall(PetscOptionsBool(name, help, man, v, &v, &given));
  if (given) PetscCall(set(A, v));
  PetscFunctionReturn(0);
}

/* E: an enum with PETSc's list of names (e.g. MatBinBCSRPrecisions) */
template <class E>
static PetscErrorCode OptionEnum(PetscOptionItems *PetscOptionsObject, Mat A, const char *name,
                                 const char *help, const char *man, const char *const *list,
                                 PetscErrorCode (*get)(Mat, E *), PetscErrorCode (*set)(Mat, E))
{
  E         v;
  PetscBool given;

  PetscFunctionBegin;
  PetscCall(get(A, &v));
  PetscCall(PetscOptionsEnum(name, help, man, list, (PetscEnum)v, (PetscEnum *)&v, &given));
  if (given) PetscCall(set(A, v));
  PetscFunctionReturn(0);
}

PetscErrorCode MatBinBCSRReadOptions_Private(Mat A, PetscOptionItems *PetscOptionsObject)
{
  PetscFunctionBegin;
  PetscCall(OptionInt(PetscOptionsObject, A, "-mat_binbcsr_bin_width", "Rows (block rows) per bin",
                      "MatBinBCSRSetBinWidth", MatBinBCSRGetBinWidth, MatBinBCSRSetBinWidth));
  PetscCall(OptionEnum(PetscOptionsObject, A, "-mat_binbcsr_precision",
                       "Storage precision of the values (products accumulate in double)",
                       "MatBinBCSRSetPrecision", MatBinBCSRPrecisions, MatBinBCSRGetPrecision,
                       MatBinBCSRSetPrecision));
  PetscCall(OptionBool(
    PetscOptionsObject, A, "-mat_binbcsr_symmetric_storage",
    "Store the upper triangle only (symmetric matrices; the lower triangle given is ignored; on several ranks, of the diagonal part)",
    "MatBinBCSRSetSymmetricStorage", MatBinBCSRGetSymmetricStorage, MatBinBCSRSetSymmetricStorage));
  PetscCall(OptionBool(
    PetscOptionsObject, A, "-mat_binbcsr_coo_mirror",
    "COO entries of off-diagonal blocks also fill the transposed place (give one triangle of a symmetric matrix)",
    "MatBinBCSRSetCOOMirror", MatBinBCSRGetCOOMirror, MatBinBCSRSetCOOMirror));
  PetscCall(OptionInt(PetscOptionsObject, A, "-mat_binbcsr_streams",
                      "Runs of bins the product sweeps side by side (1, 2, 4, 8)", "MatBinBCSRSetStreams",
                      MatBinBCSRGetStreams, MatBinBCSRSetStreams));
  PetscCall(
    OptionInt(PetscOptionsObject, A, "-mat_binbcsr_prefetch",
              "Bytes ahead the products prefetch the values (0: none; a multiple of 64, at most 65536)",
              "MatBinBCSRSetPrefetch", MatBinBCSRGetPrefetch, MatBinBCSRSetPrefetch));
  PetscCall(
    OptionEnum(PetscOptionsObject, A, "-mat_binbcsr_xload",
               "How products read x for slot groups on consecutive columns (3x3 blocks, width 8, AVX-512)",
               "MatBinBCSRSetXLoad", MatBinBCSRXLoads, MatBinBCSRGetXLoad, MatBinBCSRSetXLoad));
  PetscCall(OptionEnum(PetscOptionsObject, A, "-mat_binbcsr_device",
                       "Device copy: none, reference (host executor), cuda (one process only)",
                       "MatBinBCSRSetDevice", MatBinBCSRDevices, MatBinBCSRGetDevice, MatBinBCSRSetDevice));
  PetscCall(OptionEnum(PetscOptionsObject, A, "-mat_binbcsr_kernel",
                       "Body set of the products (auto: the best this CPU has)", "MatBinBCSRSetKernel",
                       MatBinBCSRKernels, MatBinBCSRGetKernel, MatBinBCSRSetKernel));
  PetscCall(OptionEnum(
    PetscOptionsObject, A, "-mat_binbcsr_tune",
    "Time bin widths, stream counts and body sets on this machine at the layout build and keep the fastest (on several ranks, each rank its parts)",
    "MatBinBCSRSetTune", MatBinBCSRTunes, MatBinBCSRGetTune, MatBinBCSRSetTune));
  PetscCall(OptionBool(PetscOptionsObject, A, "-mat_binbcsr_tune_cache",
                       "Read and write the tuner's cache file ($XDG_CACHE_HOME/petscbinbcsr/tune.txt)",
                       "MatBinBCSRSetTuneCache", MatBinBCSRGetTuneCache, MatBinBCSRSetTuneCache));
  PetscFunctionReturn(0);
}
