# The multigrid unit tests that need several ranks ("[mpi]": GAMG's coarse space refitted on each
# rank's rows of MPIAIJ prolongators), on 2 and 3 ranks; unit_multigrid runs them on one rank.
foreach(np 2 3)
  add_test(NAME unit_multigrid_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_multigrid> "[mpi]")
  set_tests_properties(unit_multigrid_np${np} PROPERTIES LABELS "multigrid;mpi" PROCESSORS 2 TIMEOUT 60)
endforeach()
