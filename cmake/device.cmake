# The device library (src/device/): no PETSc, no MPI. Built always with the reference executor; the
# cuda executor (cuda_executor.cu) is compiled by nvcc alone, where nvcc is found, in the compile
# check tests/device.cmake adds and by scripts/gpu_check on a GPU machine.
#
# BINBCSR_CUDA=ON (off by default) also compiles the cuda executor into this library, and so into the
# plug-in, which then needs the CUDA runtime (libcudart) to load: `-mat_binbcsr_device cuda` from PETSc
# runs the refill, the products and KSPMCG's iterations on the GPU (docs/gpu.md). Without a GPU that
# option is a PETSc error naming why. CMAKE_CUDA_ARCHITECTURES picks the GPUs (default 90: H100/H200).
option(BINBCSR_CUDA "Link the cuda executor into the plug-in (-mat_binbcsr_device cuda; needs nvcc and libcudart)" OFF)
add_library(binbcsr_device STATIC src/device/reference.cpp src/device/host_bins.cpp src/device/executor.cpp)
target_include_directories(binbcsr_device PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/src)
if(BINBCSR_CUDA)
  if(NOT CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX} AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
    set(CMAKE_CUDA_ARCHITECTURES 90 CACHE STRING "GPU architectures of the cuda executor (90: H100/H200)")
  endif()
  enable_language(CUDA)
  find_package(CUDAToolkit REQUIRED)
  target_sources(binbcsr_device PRIVATE src/device/cuda_executor.cu)
  # (the target exists already, so its CUDA properties are set here, not through CMAKE_CUDA_*)
  set_target_properties(binbcsr_device PROPERTIES CUDA_ARCHITECTURES "${CMAKE_CUDA_ARCHITECTURES}"
                        CUDA_STANDARD 17 CUDA_STANDARD_REQUIRED ON)
  target_compile_definitions(binbcsr_device PRIVATE BINBCSR_DEVICE_HAVE_CUDA)
  # the host compiler's warnings are errors in the cuda executor, as in scripts/gpu_check
  set_source_files_properties(src/device/cuda_executor.cu PROPERTIES COMPILE_OPTIONS
    "-Xcompiler=-Wall,-Wextra,-Wno-unknown-pragmas;-Werror=all-warnings")
  target_link_libraries(binbcsr_device PUBLIC CUDA::cudart)
  message(STATUS "binbcsr: the cuda executor is linked into the plug-in (CUDA architectures ${CMAKE_CUDA_ARCHITECTURES})")
endif()
