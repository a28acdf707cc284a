# The composed-function check of unit_mat_core on two ranks (the mpi type's list; one rank checks the
# seq type's).
add_test(NAME unit_mat_core_composed_np2 COMMAND ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:test_mat_core> "[composed]")
set_tests_properties(unit_mat_core_composed_np2 PROPERTIES LABELS "unit;mat_core;mpi" TIMEOUT 120)
