# PETSc's own DMDA programs with the matrix type chosen by -dm_mat_type: DMCreateMatrix preallocates
# through the AIJ interface and then inserts the stencil pattern with MatSetValuesLocal and a NULL
# value array (zeros), on one rank and on several (a NULL array crashed MATMPIBINBCSR before).
# Compared with the same program on aij. Label: stock, mat_ops (+ mpi). Budget: a few seconds.
binbcsr_stock_example(petsc_snes_ex5 snes/tutorials/ex5.c)
binbcsr_stock_example(petsc_ksp_ex45 ksp/ksp/tutorials/ex45.c)
binbcsr_stock_example(petsc_snes_ex19 snes/tutorials/ex19.c)

# snes ex5 (Bratu, 2-D DMDA, analytic Jacobian): Newton with CG + Jacobi
set(SNES_EX5 "@STOCK@/petsc_snes_ex5 -da_refine 3 -snes_converged_reason -ksp_converged_reason -snes_monitor_short -pc_type jacobi")
# ksp ex45 (3-D Laplacian on a DMDA, KSPSetComputeOperators): CG + Jacobi
set(KSP_EX45 "@STOCK@/petsc_ksp_ex45 -da_grid_x 13 -da_grid_y 11 -da_grid_z 9 -ksp_type cg -pc_type jacobi -ksp_converged_reason")

# snes ex19 (driven cavity, 4 unknowns per node: block size 4, the generic block path) has no Jacobian
# routine: SNES computes it by finite differences with a colouring (MatFDColoring, through the AIJ
# shadow, binbcsr_fdcoloring.cpp). The shadow is internal: -mat_view shows the binbcsr Jacobian, never
# the shadow or its per-rank parts (their unsynchronised views once interleaved with rank 0's lines)
set(SNES_EX19 "@STOCK@/petsc_snes_ex19 -da_refine 2 -snes_converged_reason -ksp_converged_reason -snes_monitor_short")
foreach(np 1 2 3)
  if(np EQUAL 1)
    set(run "")
    set(labels "stock;mat_ops")
  else()
    set(run "${MPIEXEC_LINE} -n ${np} ")
    set(labels "stock;mat_ops;mpi")
  endif()
  binbcsr_stock_case(snes_ex5_dmda_np${np}
    --keep "converged|SNES Function norm" --rtol 1e-8
    --ref "${run}${SNES_EX5} -dm_mat_type aij"
    --test "${run}${SNES_EX5} ${PLUGIN_ARGS} -dm_mat_type binbcsr")
  binbcsr_stock_case(ksp_ex45_dmda_np${np}
    --keep "converged|Residual norm" --rtol 1e-8
    --ref "${run}${KSP_EX45} -dm_mat_type aij"
    --test "${run}${KSP_EX45} ${PLUGIN_ARGS} -dm_mat_type binbcsr -mat_view ::ascii_info"
    --expect "type: (seq|mpi)binbcsr")
  binbcsr_stock_case(snes_ex19_fdcoloring_np${np}
    --keep "converged|SNES Function norm" --rtol 1e-6
    --ref "${run}${SNES_EX19} -pc_type jacobi -dm_mat_type aij"
    --test "${run}${SNES_EX19} -pc_type jacobi ${PLUGIN_ARGS} -dm_mat_type binbcsr -mat_view ::ascii_info"
    --expect "type: (seq|mpi)binbcsr" --reject "type: (seq|mpi)aij")
  set_tests_properties(stock_snes_ex5_dmda_np${np} stock_ksp_ex45_dmda_np${np} stock_snes_ex19_fdcoloring_np${np} PROPERTIES LABELS "${labels}")
endforeach()
# and with PETSc's default preconditioner (ILU(0), 4x4 blocks: baij's, through the seqbaij copy)
binbcsr_stock_case(snes_ex19_fdcoloring_ilu
  --keep "converged|SNES Function norm" --rtol 1e-6
  --ref "${SNES_EX19} -dm_mat_type baij"
  --test "${SNES_EX19} ${PLUGIN_ARGS} -dm_mat_type binbcsr")

# ksp ex25 (1-D DMDA, DM_BOUNDARY_NONE): on 2 and 3 ranks DMDA takes its generic 1-D AIJ path
# (DMCreateMatrix_DA_1d_MPIAIJ, through the AIJ preallocation answers) and binbcsr gives aij's
# iterations. On one rank DMDA writes an AIJ matrix's private data instead (README, limits): not run.
binbcsr_stock_example(petsc_ksp_ex25 ksp/ksp/tutorials/ex25.c)
set(KSP_EX25 "@STOCK@/petsc_ksp_ex25 -ksp_converged_reason")
foreach(np 2 3)
  binbcsr_stock_case(ksp_ex25_dmda1d_np${np}
    --keep "converged|Residual norm" --atol 1e-10
    --ref "${MPIEXEC_LINE} -n ${np} ${KSP_EX25} -dm_mat_type aij"
    --test "${MPIEXEC_LINE} -n ${np} ${KSP_EX25} ${PLUGIN_ARGS} -dm_mat_type binbcsr -mat_view ::ascii_info"
    --expect "type: mpibinbcsr")
  set_tests_properties(stock_ksp_ex25_dmda1d_np${np} PROPERTIES LABELS "stock;mat_ops;mpi" PROCESSORS 2)
endforeach()
