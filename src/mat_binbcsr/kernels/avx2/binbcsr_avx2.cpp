/* The AVX2 + FMA body set: the portable drivers of the fixed shapes (bs 1 and 3, bin widths 4 to 32)
   compiled with -mavx2 -mfma in this translation unit alone (CMakeLists.txt), so GCC vectorises the
   lane loops with 256-bit gathers and FMAs. Built as a stub where the compiler cannot target AVX2. */
#define BINBCSR_BODY_SET avx2
#include "../binbcsr_bin_drivers.h"

bool binbcsr::bodies_avx2(const Shape &s, Body &b)
{
#if defined(__AVX2__) && defined(__FMA__)
  b.set = BodySet::AVX2;
  return drivers::bodies(s, b, true);
#else
  (void)s;
  (void)b;
  return false;
#endif
}
