# The lane kernels of src/mat_binbcsr/kernels/binbcsr_kernels.h compiled as CUDA device code (tests/cuda/):
# a compile check that the header stays callable from a CUDA backend. No GPU here, so nothing runs on
# one. Added only where nvcc is found (Debian 12's PETSc has no CUDA; the toolkit is optional).
find_program(BINBCSR_NVCC nvcc PATHS /usr/local/cuda/bin)
if(BINBCSR_NVCC)
  add_test(NAME cuda_kernels_compile
           COMMAND ${BINBCSR_NVCC} -std=c++17 -arch=sm_90 -Werror all-warnings -I${PROJECT_SOURCE_DIR}/src
                   -c ${CMAKE_CURRENT_SOURCE_DIR}/cuda/kernels_device.cu -o ${CMAKE_CURRENT_BINARY_DIR}/kernels_device.o)
  set_tests_properties(cuda_kernels_compile PROPERTIES LABELS "cuda;mat_core" TIMEOUT 300)
else()
  message(STATUS "nvcc not found: CTest case cuda_kernels_compile (CUDA compile check of the kernels) not added")
endif()
if(BINBCSR_NVCC)
  # The GPU benchmark (examples/gpu/, run by scripts/gpu_bench on a machine with a GPU) and the CUDA
  # kernels it drives (src/mat_binbcsr/cuda/): built and linked against cuSPARSE and cuBLAS with warnings
  # as errors, so the CUDA code cannot rot where no GPU runs it. Running it needs a GPU (docs/gpu.md).
  add_test(NAME cuda_gpu_bench_build
           COMMAND ${BINBCSR_NVCC} -std=c++17 -O1 -arch=sm_90 -I${PROJECT_SOURCE_DIR}/src
                   -Xcompiler -Wall,-Wextra,-Wno-unknown-pragmas -Werror all-warnings
                   ${PROJECT_SOURCE_DIR}/examples/gpu/binbcsr_gpu_bench.cu -o ${CMAKE_CURRENT_BINARY_DIR}/binbcsr_gpu_bench -lcusparse -lcublas)
  set_tests_properties(cuda_gpu_bench_build PROPERTIES LABELS "cuda;mat_core" TIMEOUT 300)
endif()
