#include "sim/read_bw.h"
#include "sim/stream.h"
#include <algorithm>
#include <immintrin.h>
#include <mpi.h>

namespace {

volatile double sink; // keeps every sum observable

// Kept out of line so the compiler cannot fuse passes or drop them.
__attribute__((noinline)) double SumPlain(const double *__restrict a, PetscInt n)
{
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  for (PetscInt i = 0; i < n; i += 4) {
    s0 += a[i];
    s1 += a[i + 1];
    s2 += a[i + 2];
    s3 += a[i + 3];
  }
  return s0 + s1 + s2 + s3;
}

// K parts of n / K doubles; chunk c of part p (8 doubles, one cache line) is read in the order
// c = 0: parts 0..K-1, c = 1: parts 0..K-1, ...
template <int K> __attribute__((noinline)) double SumInterleaved(const double *__restrict a, PetscInt n)
{
  const PetscInt part = n / K;
  double         s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (PetscInt c = 0; c < part; c += 8)
    for (int p = 0; p < K; p++) {
      const double *q = a + (PetscInt)p * part + c;
      for (int j = 0; j < 8; j++) s[j] += q[j];
    }
  return s[0] + s[1] + s[2] + s[3] + s[4] + s[5] + s[6] + s[7];
}

__attribute__((noinline, target("avx512f"))) double SumAVX512(const double *__restrict a, PetscInt n)
{
  __m512d s0 = _mm512_setzero_pd(), s1 = s0, s2 = s0, s3 = s0;
  for (PetscInt i = 0; i < n; i += 32) {
    s0 = _mm512_add_pd(s0, _mm512_load_pd(a + i));
    s1 = _mm512_add_pd(s1, _mm512_load_pd(a + i + 8));
    s2 = _mm512_add_pd(s2, _mm512_load_pd(a + i + 16));
    s3 = _mm512_add_pd(s3, _mm512_load_pd(a + i + 24));
  }
  return _mm512_reduce_add_pd(_mm512_add_pd(_mm512_add_pd(s0, s1), _mm512_add_pd(s2, s3)));
}

__attribute__((noinline, target("avx2"))) double SumAVX2(const double *__restrict a, PetscInt n)
{
  __m256d s0 = _mm256_setzero_pd(), s1 = s0, s2 = s0, s3 = s0;
  for (PetscInt i = 0; i < n; i += 16) {
    s0 = _mm256_add_pd(s0, _mm256_load_pd(a + i));
    s1 = _mm256_add_pd(s1, _mm256_load_pd(a + i + 4));
    s2 = _mm256_add_pd(s2, _mm256_load_pd(a + i + 8));
    s3 = _mm256_add_pd(s3, _mm256_load_pd(a + i + 12));
  }
  alignas(32) double t[4];
  _mm256_store_pd(t, _mm256_add_pd(_mm256_add_pd(s0, s1), _mm256_add_pd(s2, s3)));
  return t[0] + t[1] + t[2] + t[3];
}

double Pass(const ReadPattern &p, const double *a, PetscInt n)
{
  if (p.simd == 512) return SumAVX512(a, n);
  if (p.simd == 256) return SumAVX2(a, n);
  switch (p.streams) {
  case 2:
    return SumInterleaved<2>(a, n);
  case 4:
    return SumInterleaved<4>(a, n);
  case 8:
    return SumInterleaved<8>(a, n);
  default:
    return SumPlain(a, n);
  }
}

} // namespace

PetscErrorCode ReadArrayCreate(MPI_Comm comm, double bytes_per_rank, ReadArray *r)
{
  PetscMPIInt size;

  PetscFunctionBegin;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (bytes_per_rank <= 0) bytes_per_rank = std::max(8.0 * (double)LastLevelCacheBytes(), 256.0 * (1 << 20));
  r->n = (PetscInt)(bytes_per_rank / sizeof(double)) / 64 * 64;
  PetscCall(PetscMalloc1(r->n, &r->a));              // PetscMalloc aligns to 64 bytes here (PETSC_MEMALIGN)
  for (PetscInt i = 0; i < r->n; i++) r->a[i] = 1.0; // first touch by the rank that reads it
  r->bytes = (double)r->n * sizeof(double) * size;
  r->patterns.clear();
  r->patterns.push_back({"1 stream", 1, 0});
  for (int k : {2, 4, 8}) r->patterns.push_back({std::to_string(k) + " streams", k, 0});
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) r->patterns.push_back({"avx512 sum", 1, 512});
  if (__builtin_cpu_supports("avx2")) r->patterns.push_back({"avx2 sum", 1, 256});
  sink = SumPlain(r->a, r->n); // warm-up: TLB
  PetscFunctionReturn(0);
}

PetscErrorCode ReadArrayRun(MPI_Comm comm, ReadArray *r, size_t p, double *GBs)
{
  PetscFunctionBegin;
  PetscCallMPI(MPI_Barrier(comm));
  const double t0 = r->cpu_clock ? ProcessCpuSeconds() : MPI_Wtime();
  sink            = Pass(r->patterns[p], r->a, r->n);
  double t        = (r->cpu_clock ? ProcessCpuSeconds() : MPI_Wtime()) - t0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, comm));
  *GBs                    = r->bytes / t * 1e-9;
  r->patterns[p].best_GBs = std::max(r->patterns[p].best_GBs, *GBs);
  PetscFunctionReturn(0);
}

PetscErrorCode ReadArrayMeasureAll(MPI_Comm comm, ReadArray *r, PetscInt repeats)
{
  double g;

  PetscFunctionBegin;
  for (PetscInt k = 0; k < repeats; k++)
    for (size_t p = 0; p < r->patterns.size(); p++) PetscCall(ReadArrayRun(comm, r, p, &g));
  PetscFunctionReturn(0);
}

size_t ReadArrayBest(const ReadArray *r)
{
  size_t b = 0;
  for (size_t p = 1; p < r->patterns.size(); p++)
    if (r->patterns[p].best_GBs > r->patterns[b].best_GBs) b = p;
  return b;
}

PetscErrorCode ReadArrayDestroy(ReadArray *r)
{
  PetscFunctionBegin;
  PetscCall(PetscFree(r->a));
  r->n = 0;
  PetscFunctionReturn(0);
}
