// The physical limit of an SpMV on one core (and per rank): the read bandwidth of one large array,
// measured with several access patterns, of which the best is the figure a bandwidth-bound kernel
// that only reads its matrix can at most reach.
//   "1 stream"       a plain sum over the array (the compiler's vectorisation)
//   "K streams"      64-byte chunks taken from K equal parts of the array in turn (K = 2, 4, 8), as a
//                    product sweeping K runs of bins side by side reads its values
//   "avx512 sum", "avx2 sum"  explicit vector sums with four accumulators (where the CPU has them)
// Under MPI every rank reads its own array at the same time (a barrier before each pass); the
// bandwidth is the aggregate (ranks x bytes) / slowest rank's time, as for the triad (stream.h).
#pragma once
#include <petscsys.h>
#include <string>
#include <vector>

struct ReadPattern {
  std::string name;
  int         streams  = 1; // K of the interleaved pattern; 1 for the sums
  int         simd     = 0; // 0: plain C++, 512 / 256: explicit AVX-512 / AVX2
  double      best_GBs = 0;
};

struct ReadArray {
  double                  *a         = nullptr;
  PetscInt                 n         = 0; // doubles on this rank (a multiple of 64)
  double                   bytes     = 0; // one pass, all ranks together
  bool                     cpu_clock = false;
  std::vector<ReadPattern> patterns; // those this CPU can run, with their best so far
};

// bytes_per_rank <= 0: max(8 x the last-level cache, 256 MiB). Allocates and first-touches.
PetscErrorCode ReadArrayCreate(MPI_Comm comm, double bytes_per_rank, ReadArray *r);
// One timed pass of pattern p on every rank at once; updates patterns[p].best_GBs, returns the GB/s.
PetscErrorCode ReadArrayRun(MPI_Comm comm, ReadArray *r, size_t p, double *GBs);
// repeats passes of every pattern (interleaved, so all see the same load from other processes).
PetscErrorCode ReadArrayMeasureAll(MPI_Comm comm, ReadArray *r, PetscInt repeats);
// The best pattern so far (index) and its bandwidth.
size_t         ReadArrayBest(const ReadArray *r);
PetscErrorCode ReadArrayDestroy(ReadArray *r);
