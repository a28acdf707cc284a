/* The AVX-512 body set: the fixed shapes' drivers compiled with AVX-512 flags in this translation unit
   alone (CMakeLists.txt), with the hand-written bodies of binbcsr_avx512.h for 3x3 blocks at bin
   width 8 (whole and symmetric storage). Built as a stub where the compiler cannot target AVX-512. */
#define BINBCSR_BODY_SET avx512
#if defined(__AVX512F__) && defined(__AVX512VL__)
  #define BINBCSR_HAND_AVX512 1
#endif
#include "../binbcsr_bin_drivers.h"

bool binbcsr::bodies_avx512(const Shape &s, Body &b)
{
#if defined(BINBCSR_HAND_AVX512)
  b.set = BodySet::AVX512;
  return drivers::bodies(s, b, true);
#else
  (void)s;
  (void)b;
  return false;
#endif
}
