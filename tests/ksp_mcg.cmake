# KSPMCG: stock PETSc tutorials loaded with -dll_append converge with -ksp_type mcg in the same number
# of iterations as -ksp_type cg (+-1), serial and under MPI.
binbcsr_stock_example(stock_ksp_ex4 ksp/ksp/tutorials/ex4.c)
binbcsr_stock_example(stock_ksp_ex72 ksp/ksp/tutorials/ex72.c)

set(MCG_COMPARE ${CMAKE_CURRENT_SOURCE_DIR}/ksp_mcg/compare_its.sh)
set(MCG_SPD ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64)

# compare_its.sh SLACK LAUNCHER... -- PROGRAM ARGS...: runs the program with -ksp_type cg and with
# -ksp_type mcg, reads the iteration counts (-ksp_converged_reason) and compares.
add_test(NAME ksp_mcg_stock_ex4
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -pc_type jacobi -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex4_nopc
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -pc_type none -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex72
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex72> -f0 ${MCG_SPD} -pc_type jacobi -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex72_bjacobi
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex72> -f0 ${MCG_SPD} -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex4_np2
         COMMAND ${MCG_COMPARE} 1 ${MPIEXEC_CMD} -n 2 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -pc_type jacobi -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex72_np2
         COMMAND ${MCG_COMPARE} 1 ${MPIEXEC_CMD} -n 2 -- $<TARGET_FILE:stock_ksp_ex72> -f0 ${MCG_SPD} -pc_type jacobi -dll_append ${PLUGIN})
# the same with binbcsr storage (double and single values); the fused product is used by mcg
add_test(NAME ksp_mcg_stock_ex4_binbcsr
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -mat_type binbcsr -pc_type jacobi -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex4_binbcsr_single
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -mat_type binbcsr -mat_binbcsr_precision single -pc_type jacobi -dll_append ${PLUGIN})
add_test(NAME ksp_mcg_stock_ex72_binbcsr
         COMMAND ${MCG_COMPARE} 1 -- $<TARGET_FILE:stock_ksp_ex72> -f0 ${MCG_SPD} -matload_block_size 3 -mat_convert_type binbcsr -pc_type jacobi -dll_append ${PLUGIN})
# -ksp_converged_reason says when a solve stopped at the precision floor of single storage
add_test(NAME ksp_mcg_stock_ex4_binbcsr_single_floor
         COMMAND ${EXPECT_RUN} 0 "KSPMCG reached the precision floor of its operator: [^\\n]*single precision[^\\n]*\\n *Linear solve did not converge due to DIVERGED_BREAKDOWN"
                 -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -mat_type binbcsr -mat_binbcsr_precision single -pc_type jacobi -ksp_type mcg -ksp_rtol 1e-12 -ksp_converged_reason -dll_append ${PLUGIN})
set_tests_properties(ksp_mcg_stock_ex4 ksp_mcg_stock_ex4_nopc ksp_mcg_stock_ex4_binbcsr_single_floor ksp_mcg_stock_ex72 ksp_mcg_stock_ex72_bjacobi
                     ksp_mcg_stock_ex4_binbcsr ksp_mcg_stock_ex4_binbcsr_single ksp_mcg_stock_ex72_binbcsr PROPERTIES LABELS "ksp_mcg")
set_tests_properties(ksp_mcg_stock_ex4_np2 ksp_mcg_stock_ex72_np2 PROPERTIES LABELS "ksp_mcg;mpi" PROCESSORS 2)

# The unit tests are written for any communicator size: run them on two ranks as well.
add_test(NAME unit_ksp_mcg_np2 COMMAND ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:test_ksp_mcg>)
set_tests_properties(unit_ksp_mcg_np2 PROPERTIES LABELS "ksp_mcg;mpi" PROCESSORS 2)

# solve_bench is a benchmark program; this only checks that it runs end to end on a tiny grid.
add_test(NAME ksp_mcg_solve_bench_smoke
         COMMAND solve_bench -stencil_n 4 -repeats 1 -history_its 10 -csv solve_bench_smoke.csv -history_csv solve_bench_smoke_history.csv)
set_tests_properties(ksp_mcg_solve_bench_smoke PROPERTIES LABELS "ksp_mcg;bench")
