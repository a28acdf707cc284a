# Submatrices of binbcsr and the PCs that use them (PCASM, PCGASM, PCREDUNDANT, PCFIELDSPLIT): the
# unit tests (collective, written for any communicator size) on 2 and 3 ranks; unit_mat_sub runs them
# on one rank.
foreach(np 2 3)
  add_test(NAME unit_mat_sub_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_mat_sub>)
  set_tests_properties(unit_mat_sub_np${np} PROPERTIES LABELS "mat_sub;mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()

# PETSc's stock ksp ex4 (-bs 3) loaded with -dll_append on 2 ranks: each PC that works through
# submatrices (the unit tests cover the others) or an external factor takes as many CG iterations with -mat_type binbcsr as with aij.
# (SuperLU_DIST only here, one factor per process: see tests/unit/mat_binbcsr/mat_sub/submatrices.cpp.)
binbcsr_stock_example(stock_ksp_ex4 ksp/ksp/tutorials/ex4.c)
set(MAT_SUB_PCS
    "asm_ov1|-pc_type asm -pc_asm_overlap 1"
    "lu_superlu_dist|-pc_type lu -pc_factor_mat_solver_type superlu_dist"
    "cholesky_mumps|-pc_type cholesky -pc_factor_mat_solver_type mumps")
foreach(entry ${MAT_SUB_PCS})
  string(FIND "${entry}" "|" bar)
  string(SUBSTRING "${entry}" 0 ${bar} name)
  math(EXPR bar "${bar} + 1")
  string(SUBSTRING "${entry}" ${bar} -1 opts)
  separate_arguments(parts UNIX_COMMAND "${opts}")
  add_test(NAME mat_sub_stock_ex4_${name}_np2
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_its.sh 0 ${MPIEXEC_CMD} -n 2
                   -- $<TARGET_FILE:stock_ksp_ex4> -bs 3 -m 12 -n 12 -ksp_type cg ${parts} -dll_append ${PLUGIN}
                   -- -mat_type aij
                   -- -mat_type binbcsr)
  set_tests_properties(mat_sub_stock_ex4_${name}_np2 PROPERTIES LABELS "mat_sub;mpi;stock" PROCESSORS 2 TIMEOUT 60)
endforeach()

# No PETSc object left behind (the AIJ shadow, value maps and submatrices go with their matrices; a
# reference from the shadow back to its own matrix once kept every matrix alive): PETSc's own
# allocation dump at PetscFinalize must be empty.
add_test(NAME unit_mat_sub_malloc_dump COMMAND test_mat_sub)
set_tests_properties(unit_mat_sub_malloc_dump PROPERTIES LABELS "mat_sub" TIMEOUT 120
                     ENVIRONMENT "PETSC_OPTIONS=-malloc_debug -malloc_dump"
                     FAIL_REGULAR_EXPRESSION "[0-9]+ bytes [A-Za-z_0-9]+\\(\\) at")
