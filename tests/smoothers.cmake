# The smoothers' unit tests that need several ranks ("[mpi]": slab Gauss-Seidel on each rank's rows with
# its halo), on 2 and 3 ranks; unit_smoothers runs them on one rank (no halo).
foreach(np 2 3)
  add_test(NAME unit_smoothers_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_smoothers> "[mpi]")
  set_tests_properties(unit_smoothers_np${np} PROPERTIES LABELS "smoothers;mpi" PROCESSORS 2 TIMEOUT 60)
endforeach()
