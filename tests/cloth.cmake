# Cloth driver: small scenes run to their physical checks (summary line), every matrix type and MPI give
# the same motion, bad input is a clear error.
set(CLOTH $<TARGET_FILE:cloth>)
set(SUMMARY_CHECK ${CMAKE_CURRENT_SOURCE_DIR}/physics/summary_check.sh)
set(SUMMARY_SAME ${CMAKE_CURRENT_SOURCE_DIR}/physics/summary_same.sh)
set(OPTS ${CMAKE_SOURCE_DIR}/options)

add_test(NAME cloth_drape_sphere
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && max_stretch<1.3 && contacts>0 && unknowns==1200 && late_ms_per_step>0 && late_cg_its>0"
                 -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 20 -steps 60 -progress_every 1000)
# The scene as options/cloth.opts sets it (strain limit 5%), at a resolution a test affords: every stretch
# spring stays within a few percent of its rest length over 30 steps that hang it from its corners and
# drop it on the sphere (the thesis's setting, options/cloth_thesis.opts, stretches the corners far).
add_test(NAME cloth_scene_stretch_bounded
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && max_stretch<1.08 && contacts>0 && diverged_solves==0 && limit_sweeps>=1 && limit_capped_steps==0 && limit_ms>0"
                 -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 40 -steps 30 -progress_every 1000)
# The summary says when the limiting ran out of sweeps (one allowed: in most steps, and the bound is
# exceeded) and reports none without a limit.
add_test(NAME cloth_strain_limit_capped_reported
         COMMAND ${SUMMARY_CHECK} "nan==0 && limit_sweeps==1 && limit_capped_steps>=10 && max_stretch>1.1"
                 -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 40 -steps 30 -progress_every 1000
                    -cloth_strain_limit_sweeps 1)
add_test(NAME cloth_strain_limit_off_reported
         COMMAND ${SUMMARY_CHECK} "nan==0 && limit_sweeps==0 && limit_capped_steps==0"
                 -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 40 -steps 30 -progress_every 1000
                    -cloth_strain_limit 0)
# At 80 x 80 a region of springs lands on the sphere over the bound at once: the scene's over-relaxed
# sweeps (omega 1.9, 150 at most) keep every stretch spring within 6% over 40 steps (1.058 measured),
# where Provot's plain sweeps reach their cap of 200 at 1.114.
add_test(NAME cloth_scene_stretch_bounded_80
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && max_stretch<1.07 && contacts>0"
                 -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 80 -steps 40 -progress_every 1000)
add_test(NAME cloth_stiff_dt30
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && max_stretch<1.1"
                 -- ${CLOTH} -cloth_n 10 -cloth_k_stretch 1e6 -cloth_k_shear 1e5 -cloth_k_bend 1e4 -dt 0.0333333 -steps 30
                    -ksp_rtol 1e-8 -ksp_max_it 5000 -progress_every 1000)
set(CLOTH_SAME "${CLOTH} -cloth_n 12 -steps 30 -sphere -ksp_rtol 1e-12 -progress_every 1000")
add_test(NAME cloth_same_result_mat_types
         COMMAND ${SUMMARY_SAME} "energy_final:1e-9 max_stretch:1e-9 contacts:0" 1e-6
                 "${CLOTH_SAME} -mat_type aij" "${CLOTH_SAME} -mat_type baij" "${CLOTH_SAME} -mat_type aij -ksp_type pipecg"
                 "${CLOTH_SAME} -mat_type binbcsr" "${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg"
                 "${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg -mat_binbcsr_symmetric_storage"
                 "${CLOTH_SAME} -mat_type aij -pc_type mg -grid_mg_coarse_nodes 10"
                 "${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg -mat_binbcsr_symmetric_storage -pc_type mg -grid_mg_coarse_nodes 10 -rows_group_window 64"
                 "${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg -pc_type mg -grid_mg_coarse_nodes 10 -grid_mg_galerkin pcmg")
# The scene's geometric multigrid (options/cloth.opts) at 32 x 32 over 30 steps: a few V-cycles per step
# (5.5 measured; pbjacobi needs 270), and the motion of a tight solve (pbjacobi to 1e-10): rms position
# difference 1.0e-4 m measured, final energy 8e-5 apart. rtol 1e-2 fails both (1.7e-3 m, 0.5%).
set(CLOTH_MG "${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 32 -steps 30 -progress_every 1000")
add_test(NAME cloth_mg_converges_like_tight
         COMMAND sh -c "${CLOTH_MG} -pc_type pbjacobi -ksp_rtol 1e-10 -write_positions cloth_mg_ref.txt >/dev/null && ${SUMMARY_CHECK} 'cg_its<=10 && unconverged_steps==0 && diverged_solves==0 && rms_position_diff<5e-4' -- ${CLOTH_MG} -reference_positions cloth_mg_ref.txt")
add_test(NAME cloth_mg_energy_as_tight
         COMMAND ${SUMMARY_SAME} "energy_final:0" 1e-3 "${CLOTH_MG} -pc_type pbjacobi -ksp_rtol 1e-10" "${CLOTH_MG}")
# A grid of at most -grid_mg_coarse_nodes particles is one level, solved directly: one iteration per step.
# The smoothers on double operators (the scene sweeps single-precision copies): the same few V-cycles.
add_test(NAME cloth_mg_double_smoothers_converge_like_tight
         COMMAND sh -c "${CLOTH_MG} -pc_type pbjacobi -ksp_rtol 1e-10 -write_positions cloth_mg_ref_double.txt >/dev/null && ${SUMMARY_CHECK} 'cg_its<=10 && unconverged_steps==0 && diverged_solves==0 && rms_position_diff<5e-4' -- ${CLOTH_MG} -grid_mg_smoother_precision double -reference_positions cloth_mg_ref_double.txt")
# Slab Gauss-Seidel (the default on one rank) against binbcsr's SOR: the same symmetric block
# Gauss-Seidel in another row order, so about the same V-cycles (32 x 32, 30 steps: 5.27 and 5.6
# measured) and the same motion.
add_test(NAME cloth_mg_sor_smoothers_converge_like_tight
         COMMAND sh -c "${CLOTH_MG} -pc_type pbjacobi -ksp_rtol 1e-10 -write_positions cloth_mg_ref_sor.txt >/dev/null && ${SUMMARY_CHECK} 'cg_its<=10 && unconverged_steps==0 && diverged_solves==0 && rms_position_diff<5e-4' -- ${CLOTH_MG} -grid_mg_smoother sor -reference_positions cloth_mg_ref_sor.txt")
add_test(NAME cloth_mg_slab_smoothers_named
         COMMAND ${EXPECT_RUN} 0 "slab Gauss-Seidel sweeps" -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 32 -steps 1 -progress_every 1000)
# -mat_view shows the system matrix only: the block graph, the grid's interpolation and the Galerkin
# coarse matrices have prefixes of their own (-grid_mg_interp_mat_view, -grid_mg_coarse_mat_view)
add_test(NAME cloth_mat_view_system_only
         COMMAND ${EXPECT_RUN} 0 "\\A(?!.*Mat Object.*Mat Object).*Mat Object: 1 MPI process\\n  type: seqbinbcsr" -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 20 -steps 1 -progress_every 1000 -mat_view ::ascii_info)
# With PCMG's products (more ranks) slab Gauss-Seidel smooths each rank's fine rows only; their couplings
# to the other rank go to the residual Richardson forms on the whole operator. Sweeping from the guess
# without them made the V-cycle nonsymmetric (DIVERGED_INDEFINITE_MAT at the second step); now the
# motion of a tight solve, as on one rank. 48 x 48: at 32 x 32 (three levels) the old sweeps still
# converged.
add_test(NAME cloth_mg_slab_smoothers_np2_converge_like_tight
         COMMAND sh -c "${CLOTH_MG} -cloth_n 48 -pc_type pbjacobi -ksp_rtol 1e-10 -write_positions cloth_mg_ref_np2.txt >/dev/null && ${SUMMARY_CHECK} 'cg_its<=10 && unconverged_steps==0 && diverged_solves==0 && rms_position_diff<5e-4' -- ${MPIEXEC_LINE} -n 2 ${CLOTH_MG} -cloth_n 48 -reference_positions cloth_mg_ref_np2.txt")
# On more ranks the coarse levels (but the coarsest) sweep slabs too, from each rank's diagonal part of
# the AIJ levels, with the distributed block products (the default) or PCMG's; the PC view names them.
add_test(NAME cloth_mg_slab_smoothers_each_rank
         COMMAND ${EXPECT_RUN} 0 "slab Gauss-Seidel on this rank's rows of the level's AIJ operator" -- ${MPIEXEC_CMD} -n 2 ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 96 -steps 1 -progress_every 1000 -ksp_view)
add_test(NAME cloth_mg_slab_smoothers_each_rank_with_pcmg
         COMMAND ${EXPECT_RUN} 0 "slab Gauss-Seidel on this rank's rows of the level's AIJ operator" -- ${MPIEXEC_CMD} -n 2 ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 96 -steps 1 -progress_every 1000 -ksp_view -grid_mg_galerkin pcmg)
# The distributed block products (each rank's share of W^T A W from its own rows, summed by COO) are
# PCMG's MatPtAP in other rounding: the same CG iterations and energy (96 x 96, 10 steps: 4.5 and
# -0.0777096 both, measured), on the cut of METIS as on the strips.
add_test(NAME cloth_mg_distributed_blocks_as_matptap
         COMMAND ${SUMMARY_SAME} "cg_its:0 energy_final:0" 1e-5 "${MPIEXEC_LINE} -n 2 ${CLOTH_MG} -cloth_n 96 -steps 10 -grid_mg_galerkin pcmg" "${MPIEXEC_LINE} -n 2 ${CLOTH_MG} -cloth_n 96 -steps 10" "${MPIEXEC_LINE} -n 2 ${CLOTH_MG} -cloth_n 96 -steps 10 -rows_partition metis")
# ... and the V-cycle with them still gives the motion of a tight solve (96 x 96, 10 steps: 4.5 CG iterations
# per step, rms position difference 1.1e-6 m measured).
add_test(NAME cloth_mg_coarse_slabs_np2_converge_like_tight
         COMMAND sh -c "${CLOTH_MG} -cloth_n 96 -steps 10 -pc_type pbjacobi -ksp_rtol 1e-10 -write_positions cloth_mg_ref_np2_96.txt >/dev/null && ${SUMMARY_CHECK} 'cg_its<=10 && unconverged_steps==0 && diverged_solves==0 && rms_position_diff<5e-4' -- ${MPIEXEC_LINE} -n 2 ${CLOTH_MG} -cloth_n 96 -steps 10 -reference_positions cloth_mg_ref_np2_96.txt")
# On 3 ranks the middle one has halos on both sides (96 x 96, 10 steps: 4.6 iterations, rms 5.7e-7 m
# measured).
add_test(NAME cloth_mg_coarse_slabs_np3_converge_like_tight
         COMMAND sh -c "${CLOTH_MG} -cloth_n 96 -steps 10 -pc_type pbjacobi -ksp_rtol 1e-10 -write_positions cloth_mg_ref_np3_96.txt >/dev/null && ${SUMMARY_CHECK} 'cg_its<=10 && unconverged_steps==0 && diverged_solves==0 && rms_position_diff<5e-4' -- ${MPIEXEC_LINE} -n 3 ${CLOTH_MG} -cloth_n 96 -steps 10 -reference_positions cloth_mg_ref_np3_96.txt")
# Where a rank's rows of a coarse level cannot be swept in slabs (a coupling a slab or more away: here a
# grid too small for 8 slabs of whole couplings) all ranks keep SOR on that level and say so.
add_test(NAME cloth_mg_coarse_slabs_fall_back_to_sor
         COMMAND ${EXPECT_RUN} 0 "keeps SOR" -- ${MPIEXEC_CMD} -n 2 ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 32 -steps 2 -progress_every 1000 -info :pc)
set_tests_properties(cloth_mg_slab_smoothers_np2_converge_like_tight cloth_mg_slab_smoothers_each_rank_with_pcmg
                     cloth_mg_slab_smoothers_each_rank cloth_mg_distributed_blocks_as_matptap
                     cloth_mg_coarse_slabs_np2_converge_like_tight cloth_mg_coarse_slabs_fall_back_to_sor
                     cloth_mg_coarse_slabs_np3_converge_like_tight
                     PROPERTIES LABELS "cloth;mpi" PROCESSORS 2 TIMEOUT 90)
add_test(NAME cloth_mg_single_smoothers_need_binbcsr
         COMMAND ${EXPECT_RUN} nonzero "needs a binbcsr fine operator" -- ${CLOTH} -cloth_n 8 -steps 1 -mat_type aij -pc_type mg -grid_mg_coarse_nodes 10 -grid_mg_smoother sor -grid_mg_smoother_precision single)
add_test(NAME cloth_mg_single_smoothers_only_with_blocks
         COMMAND ${EXPECT_RUN} 0 "coarse operators by MatPtAP, smoothers on the operators" -- ${CLOTH} -cloth_n 8 -steps 1 -mat_type binbcsr -pc_type mg -grid_mg_coarse_nodes 10 -grid_mg_galerkin pcmg -grid_mg_smoother_precision single)
add_test(NAME cloth_mg_bad_smoother_precision
         COMMAND ${EXPECT_RUN} nonzero "half" -- ${CLOTH} -cloth_n 8 -steps 1 -pc_type mg -grid_mg_smoother_precision half)
add_test(NAME cloth_mg_single_level_direct
         COMMAND ${SUMMARY_CHECK} "cg_its<=1.01 && unconverged_steps==0" -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 8 -steps 5 -progress_every 1000)
add_test(NAME cloth_mg_bad_coarse_nodes
         COMMAND ${EXPECT_RUN} nonzero "grid_mg_coarse_nodes must be at least 4" -- ${CLOTH} -cloth_n 8 -pc_type mg -grid_mg_coarse_nodes 2)
add_test(NAME cloth_mg_distributed_blocks_named
         COMMAND ${EXPECT_RUN} 0 "coarse operators by blocks" -- ${MPIEXEC_CMD} -n 2 ${CLOTH} -cloth_n 8 -pc_type mg -steps 1)
add_test(NAME cloth_bad_rows_partition
         COMMAND ${EXPECT_RUN} nonzero "rows_partition" -- ${CLOTH} -cloth_n 8 -pc_type mg -steps 1 -rows_partition stripes)
set_tests_properties(cloth_mg_converges_like_tight cloth_mg_energy_as_tight cloth_mg_single_level_direct cloth_mg_bad_coarse_nodes cloth_bad_rows_partition
                     cloth_mg_double_smoothers_converge_like_tight cloth_mg_single_smoothers_need_binbcsr
                     cloth_mg_single_smoothers_only_with_blocks cloth_mg_bad_smoother_precision
                     cloth_mg_sor_smoothers_converge_like_tight cloth_mg_slab_smoothers_named cloth_mat_view_system_only
                     PROPERTIES LABELS "cloth" TIMEOUT 60)
set_tests_properties(cloth_mg_distributed_blocks_named PROPERTIES LABELS "cloth;mpi" PROCESSORS 2 TIMEOUT 60)
# A failed preconditioner is named with its reason (src/sim/pc_failure.h; every LU pivot counts as zero).
add_test(NAME cloth_pc_failure_named
         COMMAND ${EXPECT_RUN} nonzero "DIVERGED_PC_FAILED, preconditioner: FACTOR_NUMERIC_ZEROPIVOT[;)]"
                 -- ${CLOTH} -cloth_n 8 -steps 2 -mat_type aij -ksp_type cg -pc_type lu -pc_factor_zeropivot 1e300)
set_tests_properties(cloth_pc_failure_named PROPERTIES LABELS "cloth" TIMEOUT 60)
add_test(NAME cloth_bad_dt COMMAND ${EXPECT_RUN} nonzero "time step must be positive" -- ${CLOTH} -cloth_n 4 -dt 0)
add_test(NAME cloth_bad_n COMMAND ${EXPECT_RUN} nonzero "at least 2 x 2" -- ${CLOTH} -cloth_n 1)
add_test(NAME cloth_bad_pins COMMAND ${EXPECT_RUN} nonzero "unknown -cloth_pins elbows" -- ${CLOTH} -cloth_n 4 -cloth_pins elbows)
add_test(NAME cloth_bad_stiffness COMMAND ${EXPECT_RUN} nonzero "non-negative" -- ${CLOTH} -cloth_n 4 -cloth_k_bend -5)
add_test(NAME cloth_bad_strain_limit_omega COMMAND ${EXPECT_RUN} nonzero "over-relaxation must be in"
                                                  -- ${CLOTH} -cloth_n 4 -cloth_strain_limit 0.05 -cloth_strain_limit_omega 2)
# Sizes past PETSc's 32-bit indices (the allocation used to abort with std::bad_alloc), an infinite
# stiffness, a sphere with a NaN centre (it switched the sphere off): refused with a reason.
add_test(NAME cloth_bad_huge_n COMMAND ${EXPECT_RUN} nonzero "-cloth_n 100000: .*exceed PETSc's index range"
                                      -- ${CLOTH} -cloth_n 100000 -steps 1)
add_test(NAME cloth_bad_infinite_stiffness COMMAND ${EXPECT_RUN} nonzero "stiffness non-negative, both finite"
                                                  -- ${CLOTH} -cloth_n 4 -cloth_k_stretch inf)
add_test(NAME cloth_bad_sphere_centre COMMAND ${EXPECT_RUN} nonzero "sphere needs a finite centre"
                                             -- ${CLOTH} -cloth_n 4 -sphere -sphere_centre nan,0,0)
# PETSc reads at most as many numbers as the array holds and drops the rest without a word
add_test(NAME cloth_bad_sphere_centre_count COMMAND ${EXPECT_RUN} nonzero "-sphere_centre needs 3 numbers, got 4"
                                                   -- ${CLOTH} -cloth_n 4 -sphere -sphere_centre 0,-0.5,0,7)
set_tests_properties(cloth_drape_sphere cloth_scene_stretch_bounded cloth_strain_limit_capped_reported cloth_strain_limit_off_reported cloth_scene_stretch_bounded_80 cloth_stiff_dt30 cloth_same_result_mat_types cloth_bad_dt cloth_bad_n cloth_bad_pins
                     cloth_bad_stiffness cloth_bad_strain_limit_omega cloth_bad_huge_n cloth_bad_infinite_stiffness
                     cloth_bad_sphere_centre cloth_bad_sphere_centre_count PROPERTIES LABELS "cloth" TIMEOUT 60)

add_test(NAME cloth_mpi_np2
         COMMAND ${SUMMARY_SAME} "energy_final:1e-9 max_stretch:1e-9 contacts:0" 1e-6
                 "${CLOTH_SAME}" "${MPIEXEC_LINE} -n 2 ${CLOTH_SAME}" "${MPIEXEC_LINE} -n 2 ${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg"
                 "${MPIEXEC_LINE} -n 2 ${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg -mat_binbcsr_symmetric_storage"
                 "${MPIEXEC_LINE} -n 2 ${CLOTH_SAME} -mat_type sbaij"
                 "${MPIEXEC_LINE} -n 2 ${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg -mat_binbcsr_coo_mirror"
                 "${MPIEXEC_LINE} -n 2 ${CLOTH_SAME} -mat_type binbcsr -ksp_type mcg -mat_binbcsr_symmetric_storage -pc_type mg -grid_mg_coarse_nodes 10")
set_tests_properties(cloth_mpi_np2 PROPERTIES LABELS "cloth;mpi" TIMEOUT 60)

# The error measure of bench/tradeoff.sh: a run against its own positions differs by exactly 0, against a
# loosely converged run by more; a reference of another size is an error.
add_test(NAME cloth_reference_positions
         COMMAND sh -c "${CLOTH} -cloth_n 6 -steps 3 -progress_every 10 -ksp_rtol 1e-10 -write_positions cloth_ref_positions.txt >/dev/null && ${SUMMARY_CHECK} 'rms_position_diff==0 && max_position_diff==0' -- ${CLOTH} -cloth_n 6 -steps 3 -progress_every 10 -ksp_rtol 1e-10 -reference_positions cloth_ref_positions.txt && ${SUMMARY_CHECK} 'rms_position_diff>1e-5' -- ${CLOTH} -cloth_n 6 -steps 3 -progress_every 10 -ksp_rtol 1e-2 -reference_positions cloth_ref_positions.txt && ${CLOTH} -cloth_n 7 -steps 1 -reference_positions cloth_ref_positions.txt 2>&1 | grep -q 'this run has 49 positions'")
set_tests_properties(cloth_reference_positions PROPERTIES LABELS "cloth" TIMEOUT 60)
add_test(NAME cloth_vtk_dump
         COMMAND sh -c "rm -rf cloth_out && mkdir cloth_out && ${CLOTH} -cloth_n 6 -steps 2 -sphere -vtk cloth_out/c -dump_matrix cloth_out/A.bin -progress_every 10 && grep -q 'NumberOfCells=\"50\"' cloth_out/c_00002.vtu && grep -q c_00001.vtu cloth_out/c.pvd && test -s cloth_out/A.bin")
# a -vtk prefix in a folder that does not exist yet: made (as the fem driver makes it)
add_test(NAME cloth_vtk_new_folder
         COMMAND sh -c "rm -rf cloth_out_new && ${CLOTH} -cloth_n 6 -steps 1 -vtk cloth_out_new/a/c -progress_every 10 && test -s cloth_out_new/a/c_00001.vtu")
set_tests_properties(cloth_vtk_dump cloth_vtk_new_folder PROPERTIES LABELS "cloth" TIMEOUT 60)

# When the physics or the solver breaks the run says so (src/sim/run_guard.h). Springs of
# 1e12 N/m (energy 2.9e8 J from 0 in 5 steps) and a time step of 1 s (a spring at 1108 x its rest
# length) are `unstable` with a warning; -on_unstable stop ends the run with exit code 4. A linear solve
# that fails (here: 2 iterations allowed, at the scene's tolerance) stops the run with exit code 2.
add_test(NAME cloth_stiff_springs_unstable
         COMMAND ${EXPECT_RUN} 0 "warning: unstable at step [0-9]+: energy grew.*ended=completed status=unstable"
                 -- ${CLOTH} -cloth_n 20 -cloth_k_stretch 1e12 -steps 5 -progress_every 1000 -health_energy_runaway -1)
# ... and by default such a run stops where it has run away: 9.9e3 J after the first step, more than 100
# x the 19.6 J the scene allows.
add_test(NAME cloth_stiff_springs_runaway
         COMMAND ${EXPECT_RUN} 4 "error: step 1 ran away: energy grew by 9939 J .*ended=runaway@step1 status=unstable"
                 -- ${CLOTH} -cloth_n 20 -cloth_k_stretch 1e12 -steps 5 -progress_every 1000)
add_test(NAME cloth_stiff_springs_stop
         COMMAND ${EXPECT_RUN} 4 "error: unstable at step [0-9]+: .*ended=unstable@step[0-9]+ status=unstable"
                 -- ${CLOTH} -cloth_n 20 -cloth_k_stretch 1e12 -steps 5 -progress_every 1000 -on_unstable stop)
add_test(NAME cloth_large_dt_stop
         COMMAND ${EXPECT_RUN} 4 "error: unstable at step [0-9]+: .*ended=unstable@step[0-9]+ status=unstable"
                 -- ${CLOTH} -cloth_n 20 -dt 1 -steps 5 -progress_every 1000 -on_unstable stop)
add_test(NAME cloth_large_dt_stop_np2
         COMMAND ${EXPECT_RUN} 4 "ranks=2 .*ended=unstable@step[0-9]+ status=unstable"
                 -- ${MPIEXEC_CMD} -n 2 ${CLOTH} -cloth_n 20 -dt 1 -steps 5 -progress_every 1000 -on_unstable stop)
# Any failed solve (a breakdown, an indefinite preconditioner, the iteration limit) stops the run with
# the solver's reason. The iteration limit fails the same way on every PETSc version, where a given
# preconditioner's breakdown does not (GAMG with its smoothed-aggregation eigenvalue estimate broke
# down on this cloth with PETSc 3.18 and not with 3.22).
add_test(NAME cloth_solver_failure_stop
         COMMAND ${EXPECT_RUN} 2 "error: the linear solve of step [0-9]+ failed \\(DIVERGED_ITS\\).*ended=solver_failure@step[0-9]+ status=solver_failed"
                 -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 20 -ksp_max_it 2 -steps 6 -progress_every 1000)
add_test(NAME cloth_drape_completes
         COMMAND ${EXPECT_RUN} 0 "ended=completed status=ok" -- ${CLOTH} -options_file ${OPTS}/cloth.opts -cloth_n 20 -steps 20 -progress_every 1000)
set_tests_properties(cloth_stiff_springs_unstable cloth_stiff_springs_runaway cloth_stiff_springs_stop cloth_large_dt_stop cloth_solver_failure_stop cloth_drape_completes
                     PROPERTIES LABELS "cloth" TIMEOUT 120)
set_tests_properties(cloth_large_dt_stop_np2 PROPERTIES LABELS "cloth;mpi" PROCESSORS 2 TIMEOUT 60)
