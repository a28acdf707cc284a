# Smoke runs of the benchmark programs (tiny sizes; they check that the programs run and report,
# not how fast anything is: timings belong to scripts/bench).
set(BENCH_CHECK ${CMAKE_CURRENT_SOURCE_DIR}/check_spmv_table.sh)

add_test(NAME bench_spmv_smoke
         COMMAND ${BENCH_CHECK} ${CMAKE_CURRENT_BINARY_DIR}/bench_spmv_smoke.csv
                 $<TARGET_FILE:spmv_bench> -stencil_sizes 3,5 -repeats 2 -min_batch_ms 1 -stream_elements 200000)
set_tests_properties(bench_spmv_smoke PROPERTIES LABELS "bench" TIMEOUT 60)

add_test(NAME bench_spmv_smoke_file
         COMMAND ${BENCH_CHECK} ${CMAKE_CURRENT_BINARY_DIR}/bench_spmv_smoke_file.csv
                 $<TARGET_FILE:spmv_bench> -stencil_sizes 0 -f ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64
                 -matload_block_size 3 -repeats 2 -min_batch_ms 1 -stream_elements 200000)
set_tests_properties(bench_spmv_smoke_file PROPERTIES LABELS "bench" TIMEOUT 60)

add_test(NAME bench_spmv_smoke_mpi
         COMMAND ${BENCH_CHECK} ${CMAKE_CURRENT_BINARY_DIR}/bench_spmv_smoke_mpi.csv
                 ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:spmv_bench> -stencil_sizes 4 -repeats 2 -min_batch_ms 1 -stream_elements 200000)
set_tests_properties(bench_spmv_smoke_mpi PROPERTIES LABELS "bench;mpi" TIMEOUT 60)
