# Row, column and whole-matrix operations (tests/unit/mat_rowops, written for any communicator size):
# unit_mat_rowops runs them on one rank (seqbinbcsr), these on 2 and 3 (mpibinbcsr).
foreach(np 2 3)
  add_test(NAME unit_mat_rowops_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_mat_rowops>)
  set_tests_properties(unit_mat_rowops_np${np} PROPERTIES LABELS "mat_rowops;mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()

# PETSc's stock ksp ex4 through -dll_append: -pc_jacobi_type rowmax (MatGetRowMaxAbs) and
# -ksp_diagonal_scale (MatDiagonalScale) take aij's iteration count with -mat_type binbcsr, full and
# symmetric storage, on 1 and 2 ranks (before these operations, binbcsr stopped with an error).
binbcsr_stock_example(stock_ksp_ex4 ksp/ksp/tutorials/ex4.c)
set(ROWOPS_EX4_CASES "rowmax\;-pc_type\;jacobi\;-pc_jacobi_type\;rowmax" "diagscale\;-ksp_diagonal_scale\;-ksp_diagonal_scale_fix\;-pc_type\;none")
foreach(np 1 2)
  foreach(case ${ROWOPS_EX4_CASES})
    list(GET case 0 name)
    list(SUBLIST case 1 -1 opts)
    foreach(storage full sym)
      set(extra "")
      if(storage STREQUAL "sym")
        set(extra -mat_binbcsr_symmetric_storage)
      endif()
      add_test(NAME mat_rowops_stock_ex4_${name}_${storage}_np${np}
               COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_its.sh 0 ${MPIEXEC_CMD} -n ${np}
                       -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 ${opts} -dll_append ${PLUGIN}
                       -- -mat_type aij
                       -- -mat_type binbcsr ${extra})
      set_tests_properties(mat_rowops_stock_ex4_${name}_${storage}_np${np} PROPERTIES LABELS "mat_rowops;stock;mpi" PROCESSORS ${np} TIMEOUT 60)
    endforeach()
  endforeach()
endforeach()
