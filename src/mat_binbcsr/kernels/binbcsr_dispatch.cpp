/* select_body: the one function that chooses a product body (binbcsr_dispatch.h). */
#include "binbcsr_dispatch.h"

namespace binbcsr {

/* Whether the CPU runs the set (binbcsr_cpu.h) and this build compiled it (a stub's table is empty). */
static bool probe(BodySet set)
{
  Shape s = {3, 8, 1, false, false};
  Body  b = {};
  if (!cpu_runs(set)) return false;
  switch (set) {
  case BodySet::AVX2:
    return bodies_avx2(s, b);
  case BodySet::AVX512:
    return bodies_avx512(s, b);
  default:
    return true;
  }
}

bool body_set_available(BodySet set)
{
  static const bool avx2 = probe(BodySet::AVX2), avx512 = probe(BodySet::AVX512);
  switch (set) {
  case BodySet::AVX2:
    return avx2;
  case BodySet::AVX512:
    return avx512;
  default:
    return set == BodySet::Auto || set == BodySet::Portable;
  }
}

BodySet best_body_set()
{
  static const BodySet best = body_set_available(BodySet::AVX512) ? BodySet::AVX512
                              : body_set_available(BodySet::AVX2) ? BodySet::AVX2
                                                                  : BodySet::Portable;
  return best;
}

Body select_body(const Shape &s, BodySet want)
{
  Body b = {};
  if (want == BodySet::Auto || !body_set_available(want)) want = best_body_set();
  if (want == BodySet::AVX512 && bodies_avx512(s, b)) return b;
  if (want == BodySet::AVX2 && bodies_avx2(s, b)) return b;
  bodies_portable(s, b);
  return b;
}

} // namespace binbcsr
