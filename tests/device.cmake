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

# The PETSc glue end to end on the reference executor (-mat_binbcsr_device reference), against the
# host path: the drivers' summaries agree, a stock PETSc program converges as with KSPCG, and a device
# that cannot be had is a clear error.
set(DEV_SAME ${CMAKE_CURRENT_SOURCE_DIR}/physics/summary_same.sh)
set(DEV_COMPARE ${CMAKE_CURRENT_SOURCE_DIR}/ksp_mcg/compare_its.sh)
set(DEV_SPD ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64)
binbcsr_stock_example(stock_ksp_ex4 ksp/ksp/tutorials/ex4.c)
binbcsr_stock_example(stock_ksp_ex72 ksp/ksp/tutorials/ex72.c)
set(DEV_CLOTH "$<TARGET_FILE:cloth> -cloth_n 12 -steps 30 -sphere -ksp_rtol 1e-12 -progress_every 1000 -mat_type binbcsr -ksp_type mcg")
add_test(NAME device_cloth_reference
         COMMAND ${DEV_SAME} "energy_final max_stretch contacts" 1e-6
                 "${DEV_CLOTH}" "${DEV_CLOTH} -mat_binbcsr_device reference"
                 "${DEV_CLOTH} -mat_binbcsr_device reference -mat_binbcsr_symmetric_storage"
                 "${DEV_CLOTH} -mat_binbcsr_device reference -mat_binbcsr_precision single -ksp_rtol 1e-6")
set(DEV_FEM "$<TARGET_FILE:fem> -mesh_box 1,0.1,0.1,8,2,2 -fix xmin -steps 3 -fem_quiet -mat_type binbcsr -ksp_type mcg -ksp_rtol 1e-10")
add_test(NAME device_fem_reference
         COMMAND ${DEV_SAME} "tip_dz centroid_dz kinetic elastic" 1e-6
                 "${DEV_FEM}" "${DEV_FEM} -mat_binbcsr_device reference"
                 "${DEV_FEM} -mat_binbcsr_device reference -ksp_mcg_fixed_iterations 200 -ksp_max_it 200")
set(DEV_ART "$<TARGET_FILE:articulated> -scene bridge -bridge_chains 6 -bridge_links 20 -bridge_tie_every 5 -bridge_sag 2 -steps 60 -ksp_rtol 1e-10 -progress_every 1000 -mat_type binbcsr -ksp_type mcg")
add_test(NAME device_articulated_reference
         COMMAND ${DEV_SAME} "energy_final joint_error_final loops" 1e-6
                 "${DEV_ART}" "${DEV_ART} -mat_binbcsr_device reference")
add_test(NAME device_stock_ex4_reference
         COMMAND ${DEV_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -mat_type binbcsr -mat_binbcsr_device reference -pc_type jacobi -dll_append ${PLUGIN})
add_test(NAME device_stock_ex72_reference
         COMMAND ${DEV_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex72> -f0 ${DEV_SPD} -matload_block_size 3 -mat_convert_type binbcsr -mat_binbcsr_device reference -pc_type jacobi -dll_append ${PLUGIN})
if(BINBCSR_CUDA) # the cuda executor linked in (cmake/device.cmake): on the GPU, or a clear error without one
  add_test(NAME device_cuda_plugin
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/device/cuda_plugin.sh ${DEV_COMPARE} $<TARGET_FILE:stock_ksp_ex4> ${PLUGIN})
  set(DEV_CUDA_TEST device_cuda_plugin)
else()
  add_test(NAME device_cuda_not_built
           COMMAND $<TARGET_FILE:stock_ksp_ex4> -bs 3 -mat_type binbcsr -mat_binbcsr_device cuda -ksp_type mcg -dll_append ${PLUGIN})
  set_tests_properties(device_cuda_not_built PROPERTIES PASS_REGULAR_EXPRESSION
                       "-mat_binbcsr_device cuda: the cuda executor is not built.*-DBINBCSR_CUDA=ON")
  set(DEV_CUDA_TEST device_cuda_not_built)
endif()
add_test(NAME device_mpi_refused
         COMMAND ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:stock_ksp_ex4> -bs 3 -mat_type binbcsr -mat_binbcsr_device reference -ksp_type mcg -dll_append ${PLUGIN})
set_tests_properties(device_mpi_refused PROPERTIES PASS_REGULAR_EXPRESSION "MATMPIBINBCSR \\(2 processes\\) has no device copy" PROCESSORS 2)
set_tests_properties(device_cloth_reference device_fem_reference device_articulated_reference device_stock_ex4_reference
                     device_stock_ex72_reference ${DEV_CUDA_TEST} device_mpi_refused PROPERTIES LABELS "device" TIMEOUT 120)
