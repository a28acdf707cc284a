/* The portable body set: the per-lane definition (binbcsr_kernels.h) through the bin drivers, for
   every shape, compiled for the build's baseline target. It is the reference the other sets are
   tested against (tests/unit/mat_core/bodies.cpp) and the fallback for shapes they do not cover. */
#define BINBCSR_BODY_SET portable
#include "../binbcsr_bin_drivers.h"

bool binbcsr::bodies_portable(const Shape &s, Body &b)
{
  b.set = BodySet::Portable;
  return drivers::bodies(s, b, false);
}
