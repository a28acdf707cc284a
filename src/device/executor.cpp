/* make_executor: the executor by name. BINBCSR_DEVICE_HAVE_CUDA is defined where the cuda executor is
   compiled into the library (CMake's BINBCSR_CUDA=ON, cmake/device.cmake; scripts/gpu_check). */
#include "reference.h"

namespace binbcsr {
namespace device {

bool cuda_built()
{
#if defined(BINBCSR_DEVICE_HAVE_CUDA)
  return true;
#else
  return false;
#endif
}

std::unique_ptr<Executor> make_executor(const std::string &name, std::string *why)
{
  std::string dummy;
  if (!why) why = &dummy;
  if (name == "reference") return make_reference_executor();
  if (name == "cuda") {
#if defined(BINBCSR_DEVICE_HAVE_CUDA)
    return make_cuda_executor(why);
#else
    *why =
      "the cuda executor is not built into this library (configure with -DBINBCSR_CUDA=ON to link it into the plug-in; docs/gpu.md)";
    return nullptr;
#endif
  }
  *why = "unknown executor \"" + name + "\" (reference, cuda)";
  return nullptr;
}

} // namespace device
} // namespace binbcsr
