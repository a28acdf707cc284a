// The AVX2 + FMA element batch body: element_batch_body.hpp compiled with -mavx2 -mfma in this
// translation unit alone (CMakeLists.txt), so the lane loops run on 256-bit vectors with FMAs. A stub
// (no body) where the compiler cannot target AVX2.
#define BINBCSR_ELEMENT_SET avx2
#include "physics/element_batch_body.hpp"

physics::ElementBatchBody physics::element_batch_avx2()
{
#if defined(__AVX2__) && defined(__FMA__)
  return &kernels::batch::run_batches;
#else
  return nullptr;
#endif
}
