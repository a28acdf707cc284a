// STREAM triad a[i] = b[i] + s c[i], the reference memory bandwidth that SpMV figures are compared to.
// Under MPI every rank of comm runs the triad at the same time (barrier before each repetition) and
// the aggregate bandwidth = (ranks x bytes per rank) / (slowest rank's time) is reported.
// Bytes model as in McCalpin's STREAM: 3 x 8 bytes per element (two loads, one store; the
// write-allocate read of a[] is not counted).
#pragma once
#include <petscsys.h>

struct StreamResult {
  double   best_GBs   = 0; // aggregate over ranks, best repetition (as STREAM reports)
  double   median_GBs = 0;
  PetscInt elements_per_rank = 0;
  PetscInt repeats   = 0;
  int      ranks     = 1;
};

// elements_per_rank <= 0: each of the three arrays, summed over the ranks, is 4x the last-level
// cache (at least 32 Mi doubles in all), as STREAM's rules ask. repeats <= 0: 10.
PetscErrorCode MeasureStreamTriad(MPI_Comm comm, PetscInt elements_per_rank, PetscInt repeats, StreamResult *result);

// Same, sizes from options -stream_elements N and -stream_repeats R.
PetscErrorCode MeasureStreamTriadFromOptions(MPI_Comm comm, StreamResult *result);

// Last-level cache in bytes as the OS reports it (0 if unknown).
size_t LastLevelCacheBytes();
