# The device library (src/device/): no PETSc, no MPI. Built always with the reference executor; the
# cuda executor (cuda_executor.cu) is compiled by nvcc alone, where nvcc is found, in the compile
# check tests/device.cmake adds and by scripts/gpu_check on a GPU machine. The plug-in links the
# reference-only library (the cuda executor is not built into it: docs/gpu.md).
add_library(binbcsr_device STATIC src/device/reference.cpp src/device/host_bins.cpp src/device/executor.cpp)
target_include_directories(binbcsr_device PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/src)
