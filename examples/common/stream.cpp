#include "common/stream.h"

#include <algorithm>
#include <unistd.h>
#include <vector>

size_t LastLevelCacheBytes()
{
  long bytes = 0;
#ifdef _SC_LEVEL3_CACHE_SIZE
  bytes = sysconf(_SC_LEVEL3_CACHE_SIZE);
#endif
#ifdef _SC_LEVEL2_CACHE_SIZE
  if (bytes <= 0) bytes = sysconf(_SC_LEVEL2_CACHE_SIZE);
#endif
  return bytes > 0 ? (size_t)bytes : 0;
}

namespace {

// Kept out of line so the compiler cannot fuse or drop repetitions.
__attribute__((noinline)) void Triad(double *__restrict a, const double *__restrict b, const double *__restrict c, double s, PetscInt n)
{
  for (PetscInt i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}

} // namespace

PetscErrorCode MeasureStreamTriad(MPI_Comm comm, PetscInt n, PetscInt repeats, StreamResult *result)
{
  PetscMPIInt size;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (n <= 0) {
    const size_t llc   = LastLevelCacheBytes();
    const size_t total = std::max<size_t>(4 * llc / sizeof(double), (size_t)32 << 20); // elements per array, all ranks
    n = (PetscInt)(total / (size_t)size);
  }
  if (repeats <= 0) repeats = 10;

  double *a, *b, *c;
  PetscCall(PetscMalloc3(n, &a, n, &b, n, &c));
  for (PetscInt i = 0; i < n; ++i) { // first touch by the rank that uses the pages
    a[i] = 0.0;
    b[i] = 1.0;
    c[i] = 2.0;
  }
  Triad(a, b, c, 3.0, n); // warm-up: page faults and TLB out of the timings

  std::vector<double> seconds((size_t)repeats);
  for (PetscInt r = 0; r < repeats; ++r) {
    PetscCallMPI(MPI_Barrier(comm));
    const double t0 = MPI_Wtime();
    Triad(a, b, c, 3.0, n);
    double t = MPI_Wtime() - t0;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, comm));
    seconds[(size_t)r] = t;
  }
  // Keeps the stores observable.
  volatile double sink = a[n / 2];
  (void)sink;
  PetscCall(PetscFree3(a, b, c));

  std::sort(seconds.begin(), seconds.end());
  const double bytes = 3.0 * sizeof(double) * (double)n * size;
  result->best_GBs          = bytes / seconds.front() * 1e-9;
  result->median_GBs        = bytes / seconds[seconds.size() / 2] * 1e-9;
  result->elements_per_rank = n;
  result->repeats           = repeats;
  result->ranks             = size;
  PetscFunctionReturn(0);
}

PetscErrorCode MeasureStreamTriadFromOptions(MPI_Comm comm, StreamResult *result)
{
  PetscInt n = 0, repeats = 0;

  PetscFunctionBegin;
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-stream_elements", &n, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-stream_repeats", &repeats, nullptr));
  PetscCall(MeasureStreamTriad(comm, n, repeats, result));
  PetscFunctionReturn(0);
}
