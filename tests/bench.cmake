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

# The benchmark programs refuse settings they cannot measure with (each one divided by zero, printed
# NaN or an unset minimum, or ran out of memory before).
foreach(case
    "tune_bs0|-bs must be 1 or 3|binbcsr_tune|-stencil_n 8 -bs 0"
    "tune_repeats0|-repeats and -batch must be >= 1|binbcsr_tune|-stencil_n 8 -repeats 0"
    "tune_streams3|-streams must be 1, 2, 4 or 8|binbcsr_tune|-stencil_n 8 -streams 3"
    "tune_huge|entries exceed PETSc's index range|binbcsr_tune|-stencil_n 1300"
    "solve_repeats0|-repeats and -timed_its must be >= 1|solve_bench|-stencil_n 6 -repeats 0"
    "solve_timed_its0|-repeats and -timed_its must be >= 1|solve_bench|-stencil_n 6 -timed_its 0"
    "spmv_huge|entries exceed PETSc's index range|spmv_bench|-stencil_sizes 2000"
    "spmv_negative|is no grid size|spmv_bench|-stencil_sizes -5"
    "spmv_bs0|-bs must be >= 1|spmv_bench|-stencil_sizes 0 -bs 0"
    "tune_streams_list|-streams takes at most 4 stream counts|binbcsr_tune|-stencil_n 8 -streams 1,2,4,8,1"
    "tune_sweep_confirm|-sweep_confirm must be >= 0|binbcsr_tune|-sweep -stencil_sizes 4 -sweep_confirm -1"
    "tune_sweep_n_and_sizes|give the stencils by -stencil_sizes or -stencil_n, not both|binbcsr_tune|-sweep -stencil_n 4 -stencil_sizes 6"
    "tune_sweep_nx|its stencils are cubes given by -stencil_sizes|binbcsr_tune|-sweep -stencil_nx 4"
    "spmv_n_and_sizes|give the stencils by -stencil_sizes or -stencil_n, not both|spmv_bench|-stencil_n 4 -stencil_sizes 6"
    "spmv_shift|its stencils are cubes given by -stencil_sizes|spmv_bench|-stencil_shift 2"
    "spmv_sizes_list|-stencil_sizes takes at most 16 sizes|spmv_bench|-stencil_sizes 1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17"
    "tune_file_without_sweep|-f FILE is swept with -sweep|binbcsr_tune|-stencil_n 4 -f no_such_file.bin"
    "solve_rtol_nan|-rtol must be in .0, 1., not nan|solve_bench|-stencil_n 4 -rtol nan"
    "reorder_min_batch_nan|-min_batch_ms must be positive and finite, not nan|reorder_bench|-n 4 -repeats 1 -min_batch_ms nan"
    "reorder_min_batch0|-min_batch_ms must be positive and finite, not 0|reorder_bench|-n 4 -repeats 1 -min_batch_ms 0"
    "reorder_n_negative|-n must be >= 1 .nodes a side., not -1|reorder_bench|-n -1 -repeats 1 -min_batch_ms 1"
    "reorder_n0|-n must be >= 1 .nodes a side., not 0|reorder_bench|-n 0 -repeats 1 -min_batch_ms 1"
    "reorder_repeats0|-repeats must be >= 1, not 0|reorder_bench|-n 4 -repeats 0 -min_batch_ms 1"
    "spmv_min_batch_nan|-min_batch_ms must be positive and finite, not nan|spmv_bench|-stencil_sizes 2 -min_batch_ms nan"
    "spmv_stream_elements0|-stream_elements must be >= 1, not 0|spmv_bench|-stencil_sizes 2 -stream_elements 0"
    "spmv_stream_elements_negative|-stream_elements must be >= 1, not -5|spmv_bench|-stencil_sizes 2 -stream_elements -5"
    "spmv_formats_empty|-formats .,. is an empty list|spmv_bench|-stencil_sizes 2 -formats ,"
    "spmv_files_empty|-f .,. is an empty list|spmv_bench|-stencil_sizes 2 -f ,"
    "pc_setup_repeats0|-repeats must be >= 1, not 0|pc_setup_bench|-stencil_n 3 -repeats 0"
    "pc_setup_refills_negative|-refills must be >= 1, not -1|pc_setup_bench|-stencil_n 3 -refills -1"
    "pc_setup_pcs_empty|-pcs .,. is an empty list|pc_setup_bench|-stencil_n 3 -pcs ,"
    "mat_ops_repeats0|-repeats must be >= 1, not 0|mat_ops_bench|-stencil_n 3 -repeats 0"
    "solve_formats_empty|-formats .,. is an empty list|solve_bench|-stencil_n 4 -formats ,"
    "solve_solvers_empty|-solvers .,. is an empty list|solve_bench|-stencil_n 4 -solvers ,"
    "tune_timer|-timer cpu.wall, not foo|binbcsr_tune|-stencil_n 4 -timer foo"
    "tune_sweep_files_empty|-f .,. is an empty list|binbcsr_tune|-sweep -stencil_sizes 0 -f ,"
    "spmv_nothing|nothing to measure: -stencil_sizes 0 and no -f FILE|spmv_bench|-stencil_sizes 0"
    "tune_sweep_nothing|nothing to sweep: -stencil_sizes 0 and no -f FILE|binbcsr_tune|-sweep -stencil_sizes 0")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 regex)
  list(GET parts 2 prog)
  list(GET parts 3 args)
  separate_arguments(args)
  add_test(NAME bench_bad_${name} COMMAND ${EXPECT_RUN} nonzero "${regex}" -- $<TARGET_FILE:${prog}> ${args})
  set_tests_properties(bench_bad_${name} PROPERTIES LABELS "bench" TIMEOUT 60)
endforeach()
# A matrix file whose first row length is -3 (PETSc's MatLoad took it and the matrix then crashed
# MatIsSymmetric): spmv_bench checks the file and names the row.
add_test(NAME bench_bad_matrix_file
         COMMAND ${EXPECT_RUN} nonzero "corrupt_matrix.bin: row 0 has length -3"
                 -- sh -c "cp ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64 corrupt_matrix.bin && chmod u+w corrupt_matrix.bin && printf '\\377\\377\\377\\375' | dd of=corrupt_matrix.bin bs=1 seek=16 conv=notrunc 2>/dev/null && $<TARGET_FILE:spmv_bench> -stencil_sizes 0 -f corrupt_matrix.bin -repeats 1")
set_tests_properties(bench_bad_matrix_file PROPERTIES LABELS "bench" TIMEOUT 60)
# The same file with its first value NaN (spmv_bench printed NaN errors for every format), and with its
# first column -7 for binbcsr_tune -sweep (PETSc's MatLoad dropped the entry and the sweep timed another
# matrix): both benchmarks check files through src/sim/matrix_file.h.
add_test(NAME bench_bad_matrix_file_nan
         COMMAND ${EXPECT_RUN} nonzero "nan_matrix.bin: entry 0 is not finite"
                 -- sh -c "cp ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64 nan_matrix.bin && chmod u+w nan_matrix.bin && printf '\\177\\370\\000\\000\\000\\000\\000\\000' | dd of=nan_matrix.bin bs=1 seek=248 conv=notrunc 2>/dev/null && $<TARGET_FILE:spmv_bench> -stencil_sizes 0 -f nan_matrix.bin -repeats 1")
add_test(NAME bench_bad_matrix_file_sweep
         COMMAND ${EXPECT_RUN} nonzero "column_matrix.bin: entry 0 has column -7"
                 -- sh -c "cp ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64 column_matrix.bin && chmod u+w column_matrix.bin && printf '\\377\\377\\377\\371' | dd of=column_matrix.bin bs=1 seek=64 conv=notrunc 2>/dev/null && $<TARGET_FILE:binbcsr_tune> -sweep -stencil_sizes 0 -repeats 1 -f column_matrix.bin")
set_tests_properties(bench_bad_matrix_file_nan bench_bad_matrix_file_sweep PROPERTIES LABELS "bench" TIMEOUT 60)
# An overflowing shift: every solve meets Inf (DIVERGED_NANORINF). Those are not timed, and the targets
# say they were not measured (the speed-up column printed NaN beside the reason).
add_test(NAME bench_solve_overflow_not_timed
         COMMAND ${EXPECT_RUN} 0 "mcg +binbcsr +n/a +\\(not timed: the solve ended DIVERGED_NANORINF\\).*target: mcg\\+binbcsr per iteration vs cg\\+baij: not measured"
                 -- $<TARGET_FILE:solve_bench> -stencil_n 6 -stencil_shift 1e300 -repeats 1)
set_tests_properties(bench_solve_overflow_not_timed PROPERTIES LABELS "bench" TIMEOUT 60)

# -stencil_n N is the one stencil both benchmarks time (they ignored it for their default sizes)
add_test(NAME bench_spmv_stencil_n
         COMMAND ${EXPECT_RUN} 0 "== stencil5: 375 rows" "\\A(?!.*== stencil(16|32|48))"
                 -- $<TARGET_FILE:spmv_bench> -stencil_n 5 -repeats 1)
set_tests_properties(bench_spmv_stencil_n PROPERTIES LABELS "bench" TIMEOUT 120)
add_test(NAME bench_tune_sweep_stencil_n
         COMMAND ${EXPECT_RUN} 0 "\\nstencil5 +whole +double best" "\\nstencil5 +symmetric +single best"
                 -- $<TARGET_FILE:binbcsr_tune> -sweep -stencil_n 5 -repeats 1 -batch 1 -sweep_confirm 0)
set_tests_properties(bench_tune_sweep_stencil_n PROPERTIES LABELS "bench" TIMEOUT 120)

# mat_ops_bench times the sequential types on PETSC_COMM_SELF: under mpiexec every rank printed its
# own table, interleaved; it refuses more than one rank.
add_test(NAME bench_bad_mat_ops_mpi
         COMMAND ${EXPECT_RUN} nonzero "mat_ops_bench times the sequential matrix types on one process"
                 -- ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:mat_ops_bench> -stencil_n 3 -repeats 1)
set_tests_properties(bench_bad_mat_ops_mpi PROPERTIES LABELS "bench;mpi" PROCESSORS 2 TIMEOUT 60)
# reorder_bench preallocated 27 blocks per row, which PETSc refuses where a rank holds fewer block
# columns: grids of 1 node a side on one rank and 3 a side on two failed.
add_test(NAME bench_reorder_small_grid
         COMMAND ${EXPECT_RUN} 0 "shuffled\\+ND +0 +0 +[0-9.]+ +[0-9.]+ +[0-9.]+"
                 -- $<TARGET_FILE:reorder_bench> -n 1 -repeats 1 -min_batch_ms 1)
set_tests_properties(bench_reorder_small_grid PROPERTIES LABELS "bench" TIMEOUT 60)
add_test(NAME bench_reorder_small_grid_mpi
         COMMAND ${EXPECT_RUN} 0 "shuffled\\+METIS\\+RCM +[0-9]+ +[0-9]+ +[0-9.]+"
                 -- ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:reorder_bench> -n 3 -repeats 1 -min_batch_ms 1)
set_tests_properties(bench_reorder_small_grid_mpi PROPERTIES LABELS "bench;mpi" PROCESSORS 2 TIMEOUT 60)
# A 0 x 0 matrix file: spmv_bench printed a NaN error for every format (and a NaN average row length
# in the CSV) with status ok; it skips the matrix with a line.
add_test(NAME bench_spmv_empty_matrix
         COMMAND ${EXPECT_RUN} 0 "== empty_matrix.bin: 0 x 0 matrix, nothing to multiply: skipped" "\\A(?!.*nan)"
                 -- sh -c "printf '\\000\\022\\173\\120\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000' > empty_matrix.bin && $<TARGET_FILE:spmv_bench> -stencil_sizes 0 -f empty_matrix.bin -stats_only")
# binbcsr_tune -sweep on files: a size that is not whole blocks of -bs is named with the file (MatLoad's
# message named neither), a rectangular matrix is skipped (its symmetric storage case aborted the run),
# and so is a 0 x 0 one.
add_test(NAME bench_bad_tune_sweep_block_size
         COMMAND ${EXPECT_RUN} nonzero "one_matrix.bin is 1 x 1, not whole 3x3 blocks"
                 -- sh -c "printf '\\000\\022\\173\\120\\000\\000\\000\\001\\000\\000\\000\\001\\000\\000\\000\\001\\000\\000\\000\\001\\000\\000\\000\\000\\100\\000\\000\\000\\000\\000\\000\\000' > one_matrix.bin && $<TARGET_FILE:binbcsr_tune> -sweep -stencil_sizes 0 -repeats 1 -batch 1 -f one_matrix.bin")
add_test(NAME bench_tune_sweep_skips
         COMMAND ${EXPECT_RUN} 0 "rect_matrix.bin +symmetric double +skipped: 3 x 6 is not square" "empty_matrix0.bin +skipped: 0 x 0 matrix"
                 -- sh -c "printf '\\000\\022\\173\\120\\000\\000\\000\\003\\000\\000\\000\\006\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000' > rect_matrix.bin && printf '\\000\\022\\173\\120\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000\\000' > empty_matrix0.bin && $<TARGET_FILE:binbcsr_tune> -sweep -stencil_sizes 0 -repeats 1 -batch 1 -sweep_confirm 0 -f rect_matrix.bin,empty_matrix0.bin")
set_tests_properties(bench_spmv_empty_matrix bench_bad_tune_sweep_block_size bench_tune_sweep_skips PROPERTIES LABELS "bench" TIMEOUT 60)
