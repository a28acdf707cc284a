# PCs that binbcsr serves through its own kernels (PCEISENSTAT) or its AIJ shadow (PCGAMG): the unit
# tests (collective, written for any communicator size) on 2 and 3 ranks; unit_pc runs them on one rank.
foreach(np 2 3)
  add_test(NAME unit_pc_np${np} COMMAND ${MPIEXEC_CMD} -n ${np} $<TARGET_FILE:test_pc>)
  set_tests_properties(unit_pc_np${np} PROPERTIES LABELS "pc;mpi" PROCESSORS 2 TIMEOUT 120)
endforeach()

# PETSc's stock ksp ex4 loaded with -dll_append: -pc_type eisenstat takes as many GMRES iterations with
# -mat_type binbcsr as with aij (one rank: PETSc 3.18's MPIAIJ fails Eisenstat on ex4's matrices, which
# have no inodes; the unit tests compare on more ranks where aij works).
binbcsr_stock_example(stock_ksp_ex4 ksp/ksp/tutorials/ex4.c)
foreach(bs 1 3)
  add_test(NAME pc_stock_ex4_eisenstat_bs${bs}
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_its.sh 0 env
                   -- $<TARGET_FILE:stock_ksp_ex4> -bs ${bs} -m 20 -n 20 -pc_type eisenstat -dll_append ${PLUGIN}
                   -- -mat_type aij
                   -- -mat_type binbcsr)
  set_tests_properties(pc_stock_ex4_eisenstat_bs${bs} PROPERTIES LABELS "pc;stock" TIMEOUT 60)
endforeach()

# -pc_type gamg on stock ksp ex4 (-m 30 -n 30, GMRES): binbcsr takes aij's iterations on 1, 2 and 3 ranks,
# bs 1 and 3 (the graph and the coarse operators come from binbcsr's AIJ shadow, level 0 smooths with
# binbcsr's own MatMult).
foreach(np 1 2 3)
  foreach(bs 1 3)
    add_test(NAME pc_stock_ex4_gamg_bs${bs}_np${np}
             COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_its.sh 0 ${MPIEXEC_CMD} -n ${np}
                     -- $<TARGET_FILE:stock_ksp_ex4> -bs ${bs} -m 30 -n 30 -pc_type gamg -dll_append ${PLUGIN}
                     -- -mat_type aij
                     -- -mat_type binbcsr)
    if(np GREATER 1)
      set_tests_properties(pc_stock_ex4_gamg_bs${bs}_np${np} PROPERTIES LABELS "pc;stock;mpi" PROCESSORS 2 TIMEOUT 60)
    else()
      set_tests_properties(pc_stock_ex4_gamg_bs${bs}_np${np} PROPERTIES LABELS "pc;stock" TIMEOUT 60)
    endif()
  endforeach()
endforeach()

# No PETSc object left behind by the products' contexts, the shadows or GAMG's levels: PETSc's own
# allocation dump at PetscFinalize must be empty.
add_test(NAME unit_pc_malloc_dump COMMAND test_pc)
set_tests_properties(unit_pc_malloc_dump PROPERTIES LABELS "pc" TIMEOUT 120
                     ENVIRONMENT "PETSC_OPTIONS=-malloc_debug -malloc_dump"
                     FAIL_REGULAR_EXPRESSION "[0-9]+ bytes [A-Za-z_0-9]+\\(\\) at")
