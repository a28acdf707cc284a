# Label `extremes` (issue 7): the drivers at extreme settings must end in a defined state (no NaN,
# bounded energy, or a solver failure the driver reports). tests/check_extremes.sh does the checking.
# The driver helpers' own validation tests live in their areas; these are cross-driver stress runs.
set(EXTREMES_CHECK ${CMAKE_CURRENT_SOURCE_DIR}/check_extremes.sh)
set(EXTREMES_OPTS ${CMAKE_SOURCE_DIR}/options)

if(TARGET fem)
  # A 1 m x 0.1 m x 0.1 m P2 beam (10 kg) clamped at one end, falling from rest for 5 steps: kinetic +
  # elastic energy can never exceed m g L = 98 J.
  set(EXTREMES_BEAM -mesh_box 1,0.1,0.1,10,1,1 -fem_order 2 -fem_corotational 1 -young 1e7 -poisson 0.3
      -density 1000 -dt 0.01 -steps 5 -gravity 0,0,-9.81 -fix xmin:0.001 -mat_type binbcsr -ksp_type mcg
      -ksp_rtol 1e-6 -ksp_max_it 2000 -fem_quiet)
  foreach(case "young_1e3;-young;1e3" "young_1e12;-young;1e12" "poisson_0.49;-poisson;0.49"
               "poisson_0.499;-poisson;0.499" "dt_1e-5;-dt;1e-5" "dt_0.1;-dt;0.1")
    list(GET case 0 name)
    list(GET case 1 opt)
    list(GET case 2 value)
    add_test(NAME extremes_fem_${name}
             COMMAND ${EXTREMES_CHECK} -energy_max 98.1 $<TARGET_FILE:fem> ${EXTREMES_BEAM} ${opt} ${value})
    set_tests_properties(extremes_fem_${name} PROPERTIES LABELS "extremes;bench" TIMEOUT 120)
  endforeach()
endif()

if(TARGET articulated)
  # Link masses from 1e2 down to 1e-2 (ratio 1e4) and a 1000-link chain: no NaN, energy not growing
  # by more than 1%; unconverged joint solves are allowed when reported.
  add_test(NAME extremes_articulated_mass_ratio_1e4
           COMMAND ${EXTREMES_CHECK} -energy_growth 0.01 $<TARGET_FILE:articulated> -options_file ${EXTREMES_OPTS}/mass_ratio.opts
                   -chain_mass_first 1e2 -chain_mass_last 1e-2 -steps 60)
  add_test(NAME extremes_articulated_chain_1000
           COMMAND ${EXTREMES_CHECK} -energy_growth 0.01 $<TARGET_FILE:articulated> -options_file ${EXTREMES_OPTS}/chain.opts
                   -chain_links 1000 -steps 3)
  set_tests_properties(extremes_articulated_mass_ratio_1e4 extremes_articulated_chain_1000
                       PROPERTIES LABELS "extremes;bench" TIMEOUT 120)
endif()

if(TARGET test_ksp_mcg)
  # Single-precision storage on a system with condition number ~1e8 (the Catch2 case tagged
  # [extremes] in tests/unit/ksp_mcg/precision_floor.cpp, hidden from unit_ksp_mcg): KSPMCG must not
  # claim rtol 1e-10 (KSPCG does, with b - A x ~ 0.1 against the double values), must stop with
  # KSP_DIVERGED_BREAKDOWN at its precision floor and report a residual norm not below the true one.
  add_test(NAME extremes_single_storage_ill_conditioned COMMAND test_ksp_mcg "[extremes]")
  add_test(NAME extremes_single_storage_ill_conditioned_np2 COMMAND ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:test_ksp_mcg> "[extremes]")
  set_tests_properties(extremes_single_storage_ill_conditioned PROPERTIES LABELS "extremes;ksp_mcg" TIMEOUT 60)
  set_tests_properties(extremes_single_storage_ill_conditioned_np2 PROPERTIES LABELS "extremes;ksp_mcg;mpi" PROCESSORS 2 TIMEOUT 60)
endif()
