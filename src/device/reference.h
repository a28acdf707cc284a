/* Executor factories behind make_executor (executor.cpp). */
#ifndef BINBCSR_DEVICE_REFERENCE_H
#define BINBCSR_DEVICE_REFERENCE_H
#include "device.h"
namespace binbcsr {
namespace device {
std::unique_ptr<Executor> make_reference_executor();
/* nullptr and *why when there is no usable CUDA device (cuda_executor.cu; only in builds with CUDA) */
std::unique_ptr<Executor> make_cuda_executor(std::string *why);
} // namespace device
} // namespace binbcsr
#endif
