# Row, column and whole-matrix operations (tests/unit/mat_binbcsr/mat_rowops, written for any communicator size):
# unit_mat_rowops runs them on one rank (seqbinbcsr), these on 2 and 3 (mpibinbcsr).
foreach(np 2 3)
  add_test(NAME unit_mat_rowops_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_mat_rowops>)
  set_tests_properties(unit_mat_rowops_np${np} PROPERTIES LABELS "mat_rowops;mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()

# PETSc's stock ksp ex4 through -dll_append: -pc_jacobi_type rowmax (MatGetRowMaxAbs) and
# -ksp_diagonal_scale (MatDiagonalScale) take aij's iteration count with -mat_type binbcsr, full and
# symmetric storage, on 1 and 2 ranks (before these operations, binbcsr stopped with an error). The
# unit tests check the operations themselves (ex4's matrix has a constant diagonal).
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
rowops_stock_ex4(rowmax_sym_np2 2 "${ROWMAX}" -mat_binbcsr_symmetric_storage)
rowops_stock_ex4(diagscale_sym_np1 1 "${DIAGSCALE}" -mat_binbcsr_symmetric_storage)

# PETSc's own tests of these operations, unchanged, against aij: mat ex114 (MatGetRowMax/Min/MaxAbs and
# their columns; its 4 matrices: dense rows, sparse rows, empty ranks) and mat ex138 (MatGetColumnNorms,
# sums, means of the SPD data matrix, also as 3x3 blocks in symmetric storage).
binbcsr_stock_example(stock_mat_ex114 mat/tests/ex114.c)
binbcsr_stock_example(stock_mat_ex138 mat/tests/ex138.c)
# (tests/stock_compare.sh: same printed lines, numbers to 1e-10; "type:" lines dropped, the type differs)
set(ROWOPS_SPD ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64)
# (testcase 0 and 2 on one rank: dense and sparse rows; 0 and 1 on three: a stored zero tied with the
# implicit ones, whole rows on one rank)
foreach(case "1;0" "1;2" "3;0" "3;1")
  list(GET case 0 np)
  list(GET case 1 tc)
  set(prog "${MPIEXEC_LINE} -n ${np} $<TARGET_FILE:stock_mat_ex114> -testcase ${tc}")
  add_test(NAME mat_rowops_stock_mat_ex114_tc${tc}_np${np}
           COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/stock_compare.sh --drop "type:"
                   --ref "${prog} -mat_type aij" --test "${prog} -dll_append ${PLUGIN} -mat_type binbcsr")
  set_tests_properties(mat_rowops_stock_mat_ex114_tc${tc}_np${np} PROPERTIES LABELS "mat_rowops;stock;mpi" PROCESSORS 2 TIMEOUT 60)
endforeach()
foreach(np 2) # (1 rank: the same kernels)
  set(prog "${MPIEXEC_LINE} -n ${np} $<TARGET_FILE:stock_mat_ex138> -f ${ROWOPS_SPD} -viewer_binary_skip_info")
  add_test(NAME mat_rowops_stock_mat_ex138_np${np}
           COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/stock_compare.sh
                   --ref "${prog} -mat_type aij"
                   --test "${prog} -dll_append ${PLUGIN} -mat_type binbcsr -matload_block_size 3 -mat_binbcsr_symmetric_storage")
  set_tests_properties(mat_rowops_stock_mat_ex138_np${np} PROPERTIES LABELS "mat_rowops;stock;mpi" PROCESSORS 2 TIMEOUT 60)
endforeach()

# PETSc's own PCVPBJACOBI test (snes tests ex5: blocks of 1, 2, 2 rows set by MatSetVariableBlockSizes,
# one rank by design) with -mat_type binbcsr against aij (before MatInvertVariableBlockDiagonal binbcsr
# stopped there). The unit tests (whole_ops_test.cpp) compare the blocks and solves on 1-3 ranks.
binbcsr_stock_example(stock_snes_tests_ex5 snes/tests/ex5.c)
set(prog "$<TARGET_FILE:stock_snes_tests_ex5> -snes_monitor_short -snes_converged_reason")
add_test(NAME mat_rowops_stock_snes_ex5_vpbjacobi
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/stock_compare.sh --keep "SNES Function norm|converged|Norm of error" --rtol 1e-4
                 --ref "${prog} -mat_type aij" --test "${prog} -dll_append ${PLUGIN} -mat_type binbcsr -mat_view ::ascii_info"
                 --expect "BIN-CSR")
set_tests_properties(mat_rowops_stock_snes_ex5_vpbjacobi PROPERTIES LABELS "mat_rowops;stock" TIMEOUT 60)
