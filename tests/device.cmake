# The device library's tests (tests/device/, no PETSc): every operation on the reference executor
# against plain CSR arithmetic (CTest unit_device). Where nvcc is found, device_cuda_build compiles and
# links the same tests with the cuda executor by nvcc alone, as scripts/gpu_check does on a GPU machine
# (no GPU here: compiled, not run).
file(GLOB DEVICE_TEST_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/device/*.cpp)
add_executable(test_device ${DEVICE_TEST_SOURCES})
target_link_libraries(test_device PRIVATE binbcsr_device Catch2::Catch2)
add_test(NAME unit_device COMMAND test_device)
set_tests_properties(unit_device PROPERTIES LABELS "unit;device")
find_program(BINBCSR_NVCC_DEVICE nvcc PATHS /usr/local/cuda/bin)
if(BINBCSR_NVCC_DEVICE)
  add_test(NAME device_cuda_build
           COMMAND ${PROJECT_SOURCE_DIR}/scripts/gpu_check --build-only --out ${CMAKE_CURRENT_BINARY_DIR}/gpu_check)
  set_tests_properties(device_cuda_build PROPERTIES LABELS "cuda;device" TIMEOUT 900
                       ENVIRONMENT "NVCC=${BINBCSR_NVCC_DEVICE}")
endif()
