/* The body sets of the project and the one CPU query behind every runtime pick between them. A body set
   is code compiled once per instruction set in its own translation unit (CMakeLists.txt gives each its
   flags: BINBCSR_AVX2_FLAGS, BINBCSR_AVX512_FLAGS); the library itself stays at the x86-64-v2 baseline
   and runs anywhere. The product bodies (mat_binbcsr/kernels/binbcsr_dispatch.h) and the element batch
   bodies (physics/element_batch.hpp) both ask cpu_runs() here, so they can never disagree on what this
   CPU has. Plain C++, header only: the physics library does not link the plug-in. */
#ifndef BINBCSR_CPU_H
#define BINBCSR_CPU_H

namespace binbcsr {

/* The body sets, in the order of MatBinBCSRKernel (include/petscbinbcsr.h). */
enum class BodySet : int {
  Auto     = 0,
  Portable = 1,
  AVX2     = 2,
  AVX512   = 3
};

/* "auto", "portable", "avx2", "avx512" */
inline const char *body_set_name(BodySet set)
{
  switch (set) {
  case BodySet::Auto:
    return "auto";
  case BodySet::Portable:
    return "portable";
  case BodySet::AVX2:
    return "avx2";
  case BodySet::AVX512:
    return "avx512";
  }
  return "unknown";
}

/* Whether this CPU (and its operating system, which must save the wider registers) runs the
   instructions the set's translation units are compiled with: AVX2 + FMA, or AVX-512 F, VL, BW and DQ.
   Whether the build compiled the set at all is each dispatch's own question (a stub where the compiler
   could not target it). Auto and Portable: always. */
inline bool cpu_runs(BodySet set)
{
  if (set == BodySet::Auto || set == BodySet::Portable) return true;
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init(); /* may run before the constructors that usually do it */
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (set == BodySet::AVX2) return avx2;
  return set == BodySet::AVX512 && avx2 && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512dq");
#else
  return false;
#endif
}

} // namespace binbcsr

#endif
