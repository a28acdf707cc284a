/*
   The per-machine tuning of MATSEQBINBCSR (seq/binbcsr_tune.cpp) and its cache file
   (binbcsr_tune_cache.cpp). The tuner runs when a layout is built from a final pattern: it times
   products of a sample of the matrix for the candidate bin widths, stream counts, body sets and
   software prefetch distances (and x loads or gathers), keeps the fastest, and remembers the choice per machine and matrix
   class in a small text file under $XDG_CACHE_HOME/petscbinbcsr/ (~/.cache/petscbinbcsr/), so the next
   run starts tuned.
*/
#ifndef BINBCSR_TUNE_H
#define BINBCSR_TUNE_H

#include <petscmat.h>
#include <string>

/* What the tuner runs with (seq/binbcsr_tune.cpp reads it: the value set by MatBinBCSRSetTune*, else
   the options database under the matrix's prefix, else the default). */
struct BinBCSRTuneSettings {
  PetscBool tune         = PETSC_TRUE; /* -mat_binbcsr_tune auto|off */
  PetscBool cache        = PETSC_TRUE; /* -mat_binbcsr_tune_cache */
  size_t    min_bytes    = 0;          /* -mat_binbcsr_tune_min_kib: smaller matrices keep the defaults */
  size_t    sample_bytes = 0;          /* -mat_binbcsr_tune_sample_mib; 0: the default sample */
  double    budget       = 0;          /* seconds of product time (-mat_binbcsr_tune_budget_ms) */
  PetscInt  products     = 0;          /* at most this many timed products (no limit with a budget set) */
};
PETSC_INTERN PetscErrorCode BinBCSRTuneSettingsGet(Mat, BinBCSRTuneSettings *);

/* One choice of the tuner; what the cache file stores per key. */
struct BinBCSRTuneChoice {
  PetscInt bw       = 0;
  PetscInt streams  = 0;
  PetscInt kernel   = 0; /* MatBinBCSRKernel; AUTO: the dispatch's default */
  PetscInt prefetch = 0; /* bytes ahead (MatBinBCSRSetPrefetch) */
  PetscInt xload    = 0; /* MatBinBCSRXLoad */
};

/* The machine part of a cache key: CPU model string, online cores, the kernel bodies compiled in. */
PETSC_INTERN const std::string &BinBCSRTuneMachineKey(void);
/* The cache file's path ($XDG_CACHE_HOME, else $HOME/.cache, + /petscbinbcsr/tune.txt); empty when
   neither variable is set. */
PETSC_INTERN std::string BinBCSRTuneCachePath(void);
/* The entry for key (machine key + tab + matrix class), found or not. A file that cannot be read is
   a miss; a corrupt one (a line that does not parse, values out of range) is ignored as a whole, with
   one line on stderr the first time (and PetscInfo). Never an error. */
PETSC_INTERN PetscErrorCode BinBCSRTuneCacheLookup(const std::string &key, BinBCSRTuneChoice *c,
                                                   PetscBool *found);
/* Adds or replaces the entry for key: the file is rewritten into a temporary file of this process
   and renamed over the old one (atomic on POSIX), so concurrent writers leave one of their files,
   never a mixture. Failures are reported with PetscInfo only. */
PETSC_INTERN PetscErrorCode BinBCSRTuneCacheStore(const std::string &key, const BinBCSRTuneChoice &c);

#endif
