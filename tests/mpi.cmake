# MATMPIBINBCSR under MPI: the MPI unit tests (written for any communicator size) on 2 and 3 ranks,
# and PETSc's stock ksp ex4 loaded with -dll_append on 2 and 3 ranks: binbcsr + mcg must take the
# same number of iterations as aij + cg. (unit_mpi itself runs the unit tests on one rank.)
foreach(np 2 3)
  add_test(NAME unit_mpi_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_mpi>)
  set_tests_properties(unit_mpi_np${np} PROPERTIES LABELS "mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()

binbcsr_stock_example(stock_ksp_ex4 ksp/ksp/tutorials/ex4.c)
set(MPI_COMPARE_ITS ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_its.sh)
foreach(np 2 3)
  add_test(NAME mpi_stock_ex4_np${np}
           COMMAND ${MPI_COMPARE_ITS} 0 ${MPIEXEC_CMD} -n ${np}
                   -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 -pc_type jacobi -dll_append ${PLUGIN}
                   -- -mat_type aij -ksp_type cg
                   -- -mat_type binbcsr -ksp_type mcg)
  set_tests_properties(mpi_stock_ex4_np${np} PROPERTIES LABELS "mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()

# reorder_bench runs (tiny size; the figures belong to docs/mpi.md): the METIS row must appear.
add_test(NAME mpi_reorder_bench_smoke
         COMMAND ${EXPECT_RUN} 0 "shuffled\\+METIS\\+RCM +[0-9]+ +[0-9]+ +[0-9.]+" -- ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:reorder_bench> -n 6 -repeats 1 -min_batch_ms 1)
set_tests_properties(mpi_reorder_bench_smoke PROPERTIES LABELS "mpi;bench" PROCESSORS 2 TIMEOUT 60)
