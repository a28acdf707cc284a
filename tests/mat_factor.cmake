# MATSEQBINBCSR factorisations (ICC/Cholesky through seqsbaij, ILU/LU through seqbaij): the unit tests'
# block-Jacobi case on 2 ranks, where each rank's ICC/ILU block is the seqbinbcsr diagonal part of a
# MATMPIBINBCSR. (unit_mat_factor runs all cases on one rank.)
add_test(NAME unit_mat_factor_np2 COMMAND ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:test_mat_factor> "[mpi]")
set_tests_properties(unit_mat_factor_np2 PROPERTIES LABELS "mat_factor;mpi" PROCESSORS 2 TIMEOUT 120)
