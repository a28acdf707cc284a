# Submatrices of binbcsr and the PCs that use them (PCASM, PCGASM, PCREDUNDANT, PCFIELDSPLIT): the
# unit tests (collective, written for any communicator size) on 2 and 3 ranks; unit_mat_sub runs them
# on one rank.
foreach(np 2 3)
  add_test(NAME unit_mat_sub_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_mat_sub>)
  set_tests_properties(unit_mat_sub_np${np} PROPERTIES LABELS "mat_sub;mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()
