// STREAM triad a[i] = b[i] + s c[i], the reference memory bandwidth that SpMV figures are compared to.
// Under MPI every rank of comm runs the triad at the same time (barrier before each repetition) and
// the aggregate bandwidth = (ranks x bytes per rank) / (slowest rank's time) is reported.
// Bytes model as in McCalpin's STREAM: 3 x 8 bytes per element (two loads, one store; the
// write-allocate read of a[] is not counted).
#pragma once
#include <petscsys.h>

struct StreamResult {
  double   best_GBs          = 0; // aggregate over ranks, best repetition (as STREAM reports)
  double   median_GBs        = 0;
  PetscInt elements_per_rank = 0;
  PetscInt repeats           = 0;
  int      ranks             = 1;
};

// The arrays of one rank, for callers that interleave triad passes with other measurements (so that
// both see the same load from other processes).
struct TriadArrays {
  double  *a = nullptr, *b = nullptr, *c = nullptr;
  PetscInt n         = 0;     // elements per array on this rank
  double   bytes     = 0;     // bytes one pass moves, all ranks together
  bool     cpu_clock = false; // time passes with ProcessCpuSeconds instead of the wall clock
};
// n <= 0: the default size below. Allocates and first-touches.
PetscErrorCode TriadArraysCreate(MPI_Comm comm, PetscInt n, TriadArrays *t);
// One timed pass on every rank at once; *seconds = the slowest rank's time.
PetscErrorCode TriadArraysRun(MPI_Comm comm, TriadArrays *t, double *seconds);
PetscErrorCode TriadArraysDestroy(TriadArrays *t);

// elements_per_rank <= 0: each of the three arrays, summed over the ranks, is 4x the last-level
// cache (at least 32 Mi doubles in all), as STREAM's rules ask. repeats <= 0: 10.
PetscErrorCode MeasureStreamTriad(MPI_Comm comm, PetscInt elements_per_rank, PetscInt repeats,
                                  StreamResult *result);

// Same, sizes from options -stream_elements N and -stream_repeats R.
PetscErrorCode MeasureStreamTriadFromOptions(MPI_Comm comm, StreamResult *result);

// CPU seconds this process has used (CLOCK_PROCESS_CPUTIME_ID). On a machine shared with other work,
// a timing by this clock leaves out the time the process waited for a core (it still includes the
// cache and memory traffic of the others).
double ProcessCpuSeconds();

// Last-level cache in bytes as /sys/devices/system/cpu/cpu0/cache/ reports it (0 if unknown; not
// sysconf, whose CPUID-derived answer a virtual machine may get wrong).
size_t LastLevelCacheBytes();
// The largest power of two of bytes an array may have and still stay in the caches from one read pass
// to the next, measured (binbcsr::stays_in_cache; once per process), at most LastLevelCacheBytes():
// a virtual machine reports its host's cache, which its other guests share. 0 where nothing is known.
size_t ResidentCacheBytes();
