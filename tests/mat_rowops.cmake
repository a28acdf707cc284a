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
# name, ranks, options of both runs, options of the binbcsr run
function(rowops_stock_ex4 name np opts extra)
  add_test(NAME mat_rowops_stock_ex4_${name}
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_its.sh 0 ${MPIEXEC_CMD} -n ${np}
                   -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 20 -n 20 ${opts} -dll_append ${PLUGIN}
                   -- -mat_type aij
                   -- -mat_type binbcsr ${extra})
  set(labels "mat_rowops;stock")
  if(np GREATER 1)
    set(labels "${labels};mpi")
  endif()
  set_tests_properties(mat_rowops_stock_ex4_${name} PROPERTIES LABELS "${labels}" PROCESSORS ${np} TIMEOUT 60)
endfunction()
set(ROWMAX -pc_type jacobi -pc_jacobi_type rowmax)
set(DIAGSCALE -ksp_diagonal_scale -ksp_diagonal_scale_fix -pc_type none)
rowops_stock_ex4(rowmax_np1 1 "${ROWMAX}" "")
rowops_stock_ex4(rowmax_sym_np2 2 "${ROWMAX}" -mat_binbcsr_symmetric_storage)
rowops_stock_ex4(diagscale_sym_np1 1 "${DIAGSCALE}" -mat_binbcsr_symmetric_storage)
rowops_stock_ex4(diagscale_np2 2 "${DIAGSCALE}" "")
