# The tuner's cache file under concurrent writers: four processes tune matrices of several classes at
# once on one cache folder (each rewrites the file through a temporary file and a rename), then a
# fifth checks that the file is whole and well-formed and that a build reads it. Each writer has an
# Open MPI temporary directory base of its own (OMPI_MCA_orte_tmpdir_base): four singletons starting
# together race on one (tests/CMakeLists.txt, open-mpi/ompi#8510), which failed this test about one run
# in twenty.
set(TUNE_CONCURRENT_DIR ${CMAKE_BINARY_DIR}/test-cache/concurrent)
add_test(NAME tune_cache_concurrent
         COMMAND sh -c "rm -rf '${TUNE_CONCURRENT_DIR}' && mkdir -p '${TUNE_CONCURRENT_DIR}' && export XDG_CACHE_HOME='${TUNE_CONCURRENT_DIR}' && pids= && for i in 1 2 3 4; do OMPI_MCA_orte_tmpdir_base=\"$OMPI_MCA_orte_tmpdir_base/w$i\" '$<TARGET_FILE:test_tune>' '[.cache_writer]' > /dev/null & pids=\"$pids $!\"; done && for p in $pids; do wait $p || exit 1; done && '$<TARGET_FILE:test_tune>' '[.cache_check]'")
set_tests_properties(tune_cache_concurrent PROPERTIES LABELS "unit;tune" TIMEOUT 120)
