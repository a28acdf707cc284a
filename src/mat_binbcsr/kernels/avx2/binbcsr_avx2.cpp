/* The AVX2 + FMA body set: the portable drivers of the fixed shapes (bs 1 and 3, bin widths 4 to 32)
   compiled with -mavx2 -mfma in this translation unit alone (CMakeLists.txt), so GCC vectorises the
   lane loops with 256-bit gathers and FMAs, with the hand-written bodies of binbcsr_avx2.h for 3x3
   blocks at bin widths 4, 8 and 16 (whole and symmetric storage). Built as a stub where the compiler
   cannot target AVX2. */
#define BINBCSR_BODY_SET avx2
#if defined(__AVX2__) && defined(__FMA__)
  #define BINBCSR_HAND_AVX2 1
#endif
#include "../binbcsr_bin_drivers.h"

#if defined(__AVX2__) && defined(__FMA__)
  #define BINBCSR_TARGETED true
#else
  #define BINBCSR_TARGETED false
#endif

bool binbcsr::bodies_avx2(const Shape &s, Body &b)
{
  return drivers::simd_bodies(s, b, BodySet::AVX2, BINBCSR_TARGETED);
}
