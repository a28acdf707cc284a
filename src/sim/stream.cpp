#include "sim/stream.h"
#include "mat_binbcsr/common/binbcsr_machine.h"

#include <algorithm>
#include <ctime>
#include <unistd.h>
#include <vector>

size_t LastLevelCacheBytes() { return (size_t)binbcsr::last_level_cache_bytes(); }
size_t ResidentCacheBytes() { return binbcsr::resident_cache_bytes(LastLevelCacheBytes()); }

double ProcessCpuSeconds()
{
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

namespace {

// Kept out of line so the compiler cannot fuse or drop repetitions.
__attribute__((noinline)) void Triad(double *__restrict a, const double *__restrict b,
                                     const double *__restrict c, double s, PetscInt n)
{
  for (PetscInt i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}

} // namespace

PetscErrorCode TriadArraysCreate(MPI_Comm comm, PetscInt n, TriadArrays *t)
{
  PetscMPIInt size;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (n <= 0) {
    const size_t llc = LastLevelCacheBytes();
    const size_t total =
      std::max<size_t>(4 * llc / sizeof(double), (size_t)32 << 20); // elements per array, all ranks
    n = (PetscInt)(total / (size_t)size);
  }
  PetscCall(PetscMalloc3(n, &t->a, n, &t->b, n, &t->c));
  for (PetscInt i = 0; i < n; ++i) { // first touch by the rank that uses the pages
    t->a[i] = 0.0;
    t->b[i] = 1.0;
    t->c[i] = 2.0;
  }
  Triad(t->a, t->b, t->c, 3.0, n); // warm-up: page faults and TLB out of the timings
  t->n     = n;
  t->bytes = 3.0 * sizeof(double) * (double)n * size;
  PetscFunctionReturn(0);
}

PetscErrorCode TriadArraysRun(MPI_Comm comm, TriadArrays *t, double *seconds)
{
  PetscFunctionBegin;
  PetscCallMPI(MPI_Barrier(comm));
  const double t0 = t->cpu_clock ? ProcessCpuSeconds() : MPI_Wtime();
  Triad(t->a, t->b, t->c, 3.0, t->n);
  double s = (t->cpu_clock ? ProcessCpuSeconds() : MPI_Wtime()) - t0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_MAX, comm));
  *seconds = s;
  PetscFunctionReturn(0);
}

PetscErrorCode TriadArraysDestroy(TriadArrays *t)
{
  PetscFunctionBegin;
  if (t->a) {
    volatile double sink = t->a[t->n / 2]; // keeps the stores observable
    (void)sink;
  }
  PetscCall(PetscFree3(t->a, t->b, t->c));
  t->n = 0;
  PetscFunctionReturn(0);
}

PetscErrorCode MeasureStreamTriad(MPI_Comm comm, PetscInt n, PetscInt repeats, StreamResult *result)
{
  PetscMPIInt size;
  TriadArrays t;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (repeats <= 0) repeats = 10;
  PetscCall(TriadArraysCreate(comm, n, &t));
  std::vector<double> seconds((size_t)repeats);
  for (PetscInt r = 0; r < repeats; ++r) PetscCall(TriadArraysRun(comm, &t, &seconds[(size_t)r]));
  std::sort(seconds.begin(), seconds.end());
  result->best_GBs          = t.bytes / seconds.front() * 1e-9;
  result->median_GBs        = t.bytes / seconds[seconds.size() / 2] * 1e-9;
  result->elements_per_rank = t.n;
  result->repeats           = repeats;
  result->ranks             = size;
  PetscCall(TriadArraysDestroy(&t));
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
