// The AVX-512 element batch body: element_batch_body.hpp compiled with AVX-512 flags in this translation
// unit alone (CMakeLists.txt), so a lane loop over a batch of 8 elements is one 512-bit vector per
// entry. A stub (no body) where the compiler cannot target AVX-512.
#define BINBCSR_ELEMENT_SET avx512
#include "physics/element_batch_body.hpp"

physics::ElementBatchBody physics::element_batch_avx512()
{
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
  return &kernels::batch::run_batches;
#else
  return nullptr;
#endif
}
