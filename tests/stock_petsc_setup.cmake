# PETSc's own programs that build the matrix in ways the other stock cases do not: ksp ex2 preallocates
# with MatMPIAIJSetPreallocation and never sets a block size (an unset block size made the ghost
# columns' count negative on 2 ranks); ts ex2 sets the operator up before any value exists, so
# PCSetFromOptions asks for the factor of an unassembled matrix (refused before). Against aij.
# Label: stock, mat_ops (+ mpi). Budget: a few seconds.
binbcsr_stock_example(petsc_ksp_ex2 ksp/ksp/tutorials/ex2.c)
binbcsr_stock_example(petsc_ts_ex2 ts/tutorials/ex2.c)

set(KSP_EX2 "@STOCK@/petsc_ksp_ex2 -ksp_converged_reason")
foreach(np 2 3)
  binbcsr_stock_case(ksp_ex2_unset_block_size_np${np}
    --keep "converged|Norm of error" --rtol 1e-8
    --ref "${MPIEXEC_LINE} -n ${np} ${KSP_EX2} -mat_type aij"
    --test "${MPIEXEC_LINE} -n ${np} ${KSP_EX2} ${PLUGIN_ARGS} -mat_type binbcsr -mat_view ::ascii_info"
    --expect "type: mpibinbcsr")
  set_tests_properties(stock_ksp_ex2_unset_block_size_np${np} PROPERTIES LABELS "stock;mat_ops;mpi")
endforeach()

set(TS_EX2 "@STOCK@/petsc_ts_ex2 -ts_max_steps 5 -ts_monitor -snes_converged_reason -ksp_converged_reason")
binbcsr_stock_case(ts_ex2_factor_before_assembly_ilu
  --keep "TS dt|converged" --rtol 1e-8
  --ref "${TS_EX2} -mat_type aij"
  --test "${TS_EX2} ${PLUGIN_ARGS} -mat_type binbcsr")
binbcsr_stock_case(ts_ex2_factor_before_assembly_lu
  --keep "TS dt|converged" --rtol 1e-8
  --ref "${TS_EX2} -pc_type lu -mat_type aij"
  --test "${TS_EX2} ${PLUGIN_ARGS} -pc_type lu -mat_type binbcsr")
binbcsr_stock_case(ts_ex2_factor_before_assembly_mumps_np2
  --keep "TS dt|converged" --rtol 1e-8
  --ref "${MPIEXEC_LINE} -n 2 ${TS_EX2} -pc_type lu -pc_factor_mat_solver_type mumps -mat_type aij"
  --test "${MPIEXEC_LINE} -n 2 ${TS_EX2} ${PLUGIN_ARGS} -pc_type lu -pc_factor_mat_solver_type mumps -mat_type binbcsr")
set_tests_properties(stock_ts_ex2_factor_before_assembly_mumps_np2 PROPERTIES LABELS "stock;mat_ops;mpi")
