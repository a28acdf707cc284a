# MATBINBCSR symmetric storage (-mat_binbcsr_symmetric_storage) in programs: the FEM driver must give
# the trajectory of full storage (the figures below are the full-storage run's: binbcsr + mcg, same
# options, equal to 5-6 digits; the solver tolerance, not the storage, limits the agreement), on one
# and two ranks; PETSc's ksp ex4 -bs 3 through -dll_append must give aij's residual history.
set(SYM_FEM_ARGS -mesh_box 1,0.1,0.1,8,2,2 -fix xmin -steps 3 -fem_quiet -mat_type binbcsr -ksp_type mcg
                 -mat_binbcsr_symmetric_storage)
set(SYM_FEM_REGEX "tip_dz=-0\\.0059606[0-9]* .*centroid_dz=-0\\.0046223[0-9]* kinetic=0\\.30240[0-9]* .*status=ok")
add_test(NAME mat_sym_fem_trajectory COMMAND ${EXPECT_RUN} 0 "mat_type=seqbinbcsr .*${SYM_FEM_REGEX}" -- $<TARGET_FILE:fem> ${SYM_FEM_ARGS})
set_tests_properties(mat_sym_fem_trajectory PROPERTIES LABELS "mat_sym;fem" TIMEOUT 60 WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME mat_sym_fem_trajectory_np2
         COMMAND ${EXPECT_RUN} 0 "mat_type=mpibinbcsr .*${SYM_FEM_REGEX}" -- ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:fem> ${SYM_FEM_ARGS})
set_tests_properties(mat_sym_fem_trajectory_np2 PROPERTIES LABELS "mat_sym;fem;mpi" PROCESSORS 2 TIMEOUT 60
                     WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})

binbcsr_stock_example(petsc_ksp_ex4 ksp/ksp/tutorials/ex4.c)
set(SYM_EX4 "${CMAKE_BINARY_DIR}/stock/petsc_ksp_ex4 -bs 3 -m 9 -n 7 -ksp_type cg -pc_type jacobi -ksp_monitor_short")
add_test(NAME mat_sym_stock_ksp_ex4_bs3
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/stock_compare.sh --keep "Norm of error|Residual norm" --atol 1e-12
                 --expect "symmetric storage: upper triangle"
                 --ref "${SYM_EX4} -mat_type aij"
                 --test "${SYM_EX4} -dll_append $<TARGET_FILE:petscbinbcsr> -mat_type binbcsr -mat_binbcsr_symmetric_storage -mat_view ::ascii_info")
set_tests_properties(mat_sym_stock_ksp_ex4_bs3 PROPERTIES LABELS "mat_sym;stock" TIMEOUT 120)
