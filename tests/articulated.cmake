# Articulated driver: scenes run to their physical checks (summary line), every matrix type gives the same
# motion, bad input is a clear error, and MPI runs match serial ones.
set(ART $<TARGET_FILE:articulated>)
set(SUMMARY_CHECK ${CMAKE_CURRENT_SOURCE_DIR}/physics/summary_check.sh)
set(SUMMARY_SAME ${CMAKE_CURRENT_SOURCE_DIR}/physics/summary_same.sh)
set(OPTS ${CMAKE_SOURCE_DIR}/options)

add_test(NAME articulated_chain
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && energy_growth_max<0.01*(-energy_initial) && corrections_per_step<3"
                 -- ${ART} -options_file ${OPTS}/chain.opts -progress_every 1000)
add_test(NAME articulated_loop
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && loops==1"
                 -- ${ART} -options_file ${OPTS}/loop.opts -progress_every 1000)
# Warm-started: the last step's corrections were a guess 6e4 times worse than zero at step 2
# (DIVERGED_DTOL before the first iteration) and the run stopped; such a start is solved again from zero.
add_test(NAME articulated_loop_warm_start
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && solver_failures==0 && steps==200"
                 -- ${ART} -options_file ${OPTS}/loop.opts -joint_warm_start -steps 200 -progress_every 1000)
# ... but a warm start that only runs out of iterations is kept, not solved a second time from zero:
# one solve per stabilisation and per correction
add_test(NAME articulated_warm_start_max_it_solved_once
         COMMAND ${SUMMARY_CHECK} "steps==20 && solves<=steps*(1+corrections_per_step)"
                 -- ${ART} -options_file ${OPTS}/chain.opts -joint_warm_start -ksp_max_it 3 -steps 20
                    -on_solver_failure continue -progress_every 1000)
add_test(NAME articulated_mass_ratio_1e4
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6"
                 -- ${ART} -options_file ${OPTS}/mass_ratio.opts -chain_mass_first 1e2 -chain_mass_last 1e-2 -steps 240 -progress_every 1000)
add_test(NAME articulated_mass_ratio_1e8_finite
         COMMAND ${SUMMARY_CHECK} "nan==0" -- ${ART} -options_file ${OPTS}/mass_ratio.opts -steps 120 -progress_every 1000)
add_test(NAME articulated_bridge_small
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && loops==26"
                 -- ${ART} -scene bridge -bridge_chains 6 -bridge_links 20 -bridge_tie_every 5 -bridge_sag 2 -steps 60 -ksp_rtol 1e-10 -progress_every 1000)
# IC(0) in the physics order factorises each chain exactly: one CG iteration per solve where Jacobi needs ~50.
add_test(NAME articulated_bridge_icc
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && cg_its<=1.5 && loops==11"
                 -- ${ART} -scene bridge -bridge_chains 6 -bridge_links 40 -bridge_tie_every 40 -bridge_sag 4 -steps 30 -mat_type aij
                    -pc_type icc -ksp_rtol 1e-4 -ksp_max_it 3000 -max_corrections 20 -progress_every 1000)
# The same with binbcsr + mcg (its generic-PC path) and binbcsr's ICC: the rows must stay in physics order
# (no length grouping under a factorising PC), else IC(0) is not exact and the iterations grow.
add_test(NAME articulated_bridge_icc_binbcsr
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && cg_its<=1.5 && loops==11"
                 -- ${ART} -scene bridge -bridge_chains 6 -bridge_links 40 -bridge_tie_every 40 -bridge_sag 4 -steps 30 -mat_type binbcsr
                    -ksp_type mcg -pc_type icc -ksp_rtol 1e-4 -ksp_max_it 3000 -max_corrections 20 -progress_every 1000)
# The full bridge as options/bridge.opts runs it (IC(0), -joint_refresh), past step ~21 where the fixed
# start-of-step matrix used to stall: every step converged with one CG iteration per solve (~3 s).
add_test(NAME articulated_bridge_full_binbcsr
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && stalled_steps==0 && joint_error_max<1e-6 && cg_its<=1.5 && corrections_max<=3"
                 -- ${ART} -options_file ${OPTS}/bridge.opts -steps 40 -mat_type binbcsr -ksp_type mcg -progress_every 1000)
# -joint_refresh is on by default: one chain of the bridge (100 planks, 10 m sag, IC(0), no refresh
# option given) converges every one of 40 steps with <= 2 corrections; the same run with the fixed
# start-of-step matrix (-joint_refresh 0) stalls from step ~21 (13 steps unconverged, 1.3 mm joint error),
# which shows the scene tells the two apart. ~0.4 s each.
set(ART_ONE_CHAIN ${ART} -scene bridge -bridge_chains 1 -bridge_links 100 -bridge_tie_every 100 -bridge_sag 10 -dt 0.0166667 -steps 40
                  -mat_type aij -pc_type icc -ksp_rtol 1e-4 -ksp_max_it 3000 -max_corrections 20 -progress_every 1000)
add_test(NAME articulated_refresh_default
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && stalled_steps==0 && halvings_per_step==0 && joint_error_max<1e-6 && corrections_max<=2"
                 -- ${ART_ONE_CHAIN})
add_test(NAME articulated_refresh_off_stalls
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps>=10 && stalled_steps>=10 && joint_error_max>1e-4"
                 -- ${ART_ONE_CHAIN} -joint_refresh 0)
set_tests_properties(articulated_refresh_default articulated_refresh_off_stalls PROPERTIES LABELS "articulated" TIMEOUT 60)
add_test(NAME articulated_bridge_icc_binbcsr_np2
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && cg_its<=12"
                 -- ${MPIEXEC_CMD} -n 2 ${ART} -scene bridge -bridge_chains 6 -bridge_links 40 -bridge_tie_every 40 -bridge_sag 4 -steps 30
                    -mat_type binbcsr -ksp_type mcg -pc_type bjacobi -sub_pc_type icc -ksp_rtol 1e-4 -ksp_max_it 3000 -max_corrections 20
                    -progress_every 1000)
set_tests_properties(articulated_bridge_icc_binbcsr_np2 PROPERTIES LABELS "articulated;mpi" PROCESSORS 2 TIMEOUT 60)
# The same warm-started (-joint_warm_start, as options/bridge.opts): block Jacobi misses only the tie across
# the cut, whose impulse changes little from step to step, so the iterations halve (8.2 -> 4.3 per solve).
add_test(NAME articulated_bridge_warm_np2
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && cg_its<=5.5"
                 -- ${MPIEXEC_CMD} -n 2 ${ART} -scene bridge -bridge_chains 6 -bridge_links 40 -bridge_tie_every 40 -bridge_sag 4 -steps 30
                    -mat_type binbcsr -ksp_type mcg -pc_type bjacobi -sub_pc_type icc -ksp_rtol 1e-4 -ksp_max_it 3000 -max_corrections 20
                    -joint_warm_start -progress_every 1000)
set_tests_properties(articulated_bridge_warm_np2 PROPERTIES LABELS "articulated;mpi" PROCESSORS 2 TIMEOUT 60)
add_test(NAME articulated_bad_halvings
         COMMAND ${EXPECT_RUN} nonzero "halvings must be non-negative" -- ${ART} -options_file ${OPTS}/chain.opts -joint_max_halvings -1)
set(ART_SAME "${ART} -options_file ${OPTS}/chain.opts -steps 100 -ksp_rtol 1e-12 -progress_every 1000")
add_test(NAME articulated_same_result_mat_types
         COMMAND ${SUMMARY_SAME} "energy_final:1e-9 joint_error_final:1e-12 corrections_per_step:0" 1e-6
                 "${ART_SAME} -mat_type aij" "${ART_SAME} -mat_type baij" "${ART_SAME} -mat_type aij -ksp_type pipecg"
                 "${ART_SAME} -mat_type binbcsr" "${ART_SAME} -mat_type binbcsr -ksp_type mcg")
add_test(NAME articulated_bad_dt
         COMMAND ${EXPECT_RUN} nonzero "time step must be positive" -- ${ART} -options_file ${OPTS}/chain.opts -dt -1)
add_test(NAME articulated_bad_mass
         COMMAND ${EXPECT_RUN} nonzero "masses must be positive" -- ${ART} -options_file ${OPTS}/chain.opts -chain_mass_first 0)
add_test(NAME articulated_bad_scene
         COMMAND ${EXPECT_RUN} nonzero "unknown -scene trampoline" -- ${ART} -scene trampoline)
# A failed preconditioner is named with its reason (src/sim/pc_failure.h; every LU pivot counts as zero).
add_test(NAME articulated_pc_failure_named
         COMMAND ${EXPECT_RUN} 2 "failed \\(DIVERGED_PC_FAILED, preconditioner: FACTOR_NUMERIC_ZEROPIVOT\\)"
                 -- ${ART} -options_file ${OPTS}/chain.opts -steps 2 -mat_type aij -ksp_type cg -pc_type lu -pc_factor_zeropivot 1e300)
set_tests_properties(articulated_pc_failure_named PROPERTIES LABELS "articulated" TIMEOUT 60)
set_tests_properties(articulated_bridge_icc articulated_bridge_icc_binbcsr articulated_bridge_full_binbcsr articulated_bad_halvings articulated_chain articulated_loop articulated_loop_warm_start articulated_warm_start_max_it_solved_once articulated_mass_ratio_1e4 articulated_mass_ratio_1e8_finite
                     articulated_bridge_small articulated_same_result_mat_types articulated_bad_dt articulated_bad_mass
                     articulated_bad_scene PROPERTIES LABELS "articulated" TIMEOUT 60)

set(ART_MPI "${ART} -options_file ${OPTS}/loop.opts -steps 100 -ksp_rtol 1e-12 -progress_every 1000")
add_test(NAME articulated_mpi_np2
         COMMAND ${SUMMARY_SAME} "energy_final:1e-9 joint_error_final:1e-12 corrections_per_step:0" 1e-6
                 "${ART_MPI}" "${MPIEXEC_LINE} -n 2 ${ART_MPI}" "${MPIEXEC_LINE} -n 2 ${ART_MPI} -mat_type baij"
                 "${MPIEXEC_LINE} -n 2 ${ART_MPI} -mat_type binbcsr -ksp_type mcg")
set_tests_properties(articulated_mpi_np2 PROPERTIES LABELS "articulated;mpi" TIMEOUT 60)
# A 10-link chain split over 2 ranks (each rank moves the bodies of its own joints, the two middle links on
# both): the same motion as one rank; one run also writes frames, which gathers every body mid-run.
add_test(NAME articulated_mpi_np2_chain
         COMMAND ${SUMMARY_SAME} "energy_final:1e-9 joint_error_final:1e-12 corrections_per_step:0" 1e-6
                 "${ART_SAME} -mat_type aij" "${MPIEXEC_LINE} -n 2 ${ART_SAME} -mat_type aij"
                 "${MPIEXEC_LINE} -n 2 ${ART_SAME} -mat_type binbcsr -ksp_type mcg -vtk art_np2_chain -vtk_every 50 -vtk_points")
set_tests_properties(articulated_mpi_np2_chain PROPERTIES LABELS "articulated;mpi" PROCESSORS 2 TIMEOUT 60)

# More ranks than joints: a rank that owns no joint must still take part in every reduction of the
# step (it used to take itself for an unsplit run and skip them: the others waited for good), and its
# empty block of PCBJACOBI must factor (PETSc's SBAIJ ICC crashed on the empty block of binbcsr's shadow).
add_test(NAME articulated_more_ranks_than_joints
         COMMAND ${SUMMARY_SAME} "energy_final:1e-9 joint_error_final:1e-12 corrections_per_step:0" 1e-6
                 "${ART} -options_file ${OPTS}/chain.opts -chain_links 2 -steps 20 -mat_type aij"
                 "${MPIEXEC_LINE} -n 3 ${ART} -options_file ${OPTS}/chain.opts -chain_links 2 -steps 20 -mat_type aij"
                 "${MPIEXEC_LINE} -n 3 ${ART} -options_file ${OPTS}/chain.opts -chain_links 2 -steps 20 -mat_type binbcsr -ksp_type mcg")
set_tests_properties(articulated_more_ranks_than_joints PROPERTIES LABELS "articulated;mpi" TIMEOUT 60)
add_test(NAME articulated_bridge_rank_without_rows
         COMMAND ${SUMMARY_CHECK} "nan==0 && unconverged_steps==0 && joint_error_max<1e-6 && ranks==5"
                 -- ${MPIEXEC_CMD} -n 5 ${ART} -options_file ${OPTS}/bridge.opts -bridge_chains 1 -bridge_links 2
                    -bridge_tie_every 1 -steps 3 -mat_type binbcsr -ksp_type mcg)
set_tests_properties(articulated_bridge_rank_without_rows PROPERTIES LABELS "articulated;mpi" TIMEOUT 60)

# -vtk writes one .vtu per frame and a .pvd collection; -dump_matrix writes a PETSc binary matrix.
add_test(NAME articulated_vtk_dump
         COMMAND sh -c "rm -rf art_out && mkdir art_out && ${ART} -options_file ${OPTS}/loop.opts -steps 4 -vtk art_out/loop -vtk_every 2 -dump_matrix art_out/A.bin -progress_every 10 && test -s art_out/loop_00004.vtu && grep -q 'NumberOfCells=\"3\"' art_out/loop_00004.vtu && grep -q loop_00002.vtu art_out/loop.pvd && test -s art_out/A.bin")
set_tests_properties(articulated_vtk_dump PROPERTIES LABELS "articulated" TIMEOUT 60)

# When the physics or the solver breaks the run says so (src/sim/run_guard.h): a link mass of
# 1e300 or 1e-300 makes the state nonfinite in the first step (energy -nan), which ends the run with a
# message and a non-zero exit status (exit code 3, or 2 when a solve fails first); serial and on 2 ranks.
foreach(mass 1e300 1e-300)
  foreach(np 1 2)
    add_test(NAME articulated_link_mass_${mass}_np${np}
             COMMAND ${EXPECT_RUN} nonzero "error: .*step 1 .*ended=(nonfinite_state|solver_failure)@step1 status=(nonfinite|solver_failed)"
                     -- ${MPIEXEC_CMD} -n ${np} ${ART} -options_file ${OPTS}/chain.opts -chain_mass_last ${mass} -steps 5 -progress_every 1000)
    set_tests_properties(articulated_link_mass_${mass}_np${np} PROPERTIES LABELS "articulated;mpi" PROCESSORS ${np} TIMEOUT 60)
  endforeach()
endforeach()
# A step far too long (1e10 s) leaves the joints 1e21 m apart, and link masses of 1e30 and 1e-30 kg
# leave one 5 cm open: every step UNCONVERGED, and the run claimed status=ok. A joint open by more than
# 5% of the smallest body is the articulation coming apart (-health_joint_error): a warning and
# status=unstable, or a stop with -on_unstable stop.
add_test(NAME articulated_joints_apart_unstable
         COMMAND ${EXPECT_RUN} 0 "warning: unstable at step 1: a joint is .* m open .*status=unstable"
                 -- ${ART} -options_file ${OPTS}/chain.opts -dt 1e10 -steps 5 -progress_every 1000)
add_test(NAME articulated_joints_apart_stop
         COMMAND ${EXPECT_RUN} 4 "error: unstable at step 5: a joint is 0.05.* m open .*ended=unstable@step5 status=unstable"
                 -- ${ART} -options_file ${OPTS}/chain.opts -chain_mass_first 1e30 -chain_mass_last 1e-30 -steps 5
                    -on_unstable stop -progress_every 1000)
set_tests_properties(articulated_joints_apart_unstable articulated_joints_apart_stop PROPERTIES LABELS "articulated"
                     TIMEOUT 60)
# A healthy chain runs to the end and says so.
add_test(NAME articulated_chain_completes
         COMMAND ${EXPECT_RUN} 0 "ended=completed status=ok" -- ${ART} -options_file ${OPTS}/chain.opts -steps 20 -progress_every 1000)
add_test(NAME articulated_bad_chain_length
         COMMAND ${EXPECT_RUN} nonzero "link length and width must be positive" -- ${ART} -options_file ${OPTS}/chain.opts -chain_length 0)
add_test(NAME articulated_bad_chain_links
         COMMAND ${EXPECT_RUN} nonzero "at most 1,000,000 links" -- ${ART} -options_file ${OPTS}/chain.opts -chain_links 100000000)
add_test(NAME articulated_bad_bridge_sag
         COMMAND ${EXPECT_RUN} nonzero "sag must be positive and finite" -- ${ART} -options_file ${OPTS}/bridge.opts -bridge_sag 0)
set_tests_properties(articulated_chain_completes articulated_bad_chain_length articulated_bad_chain_links
                     articulated_bad_bridge_sag PROPERTIES LABELS "articulated" TIMEOUT 60)
# -write_positions / -reference_positions (sim/position_file.h): the bodies' centres of mass against
# another run's. The same run gives 0; a looser joint tolerance (1e-3 m) moves the chain by 2.5e-4 m rms;
# 2 ranks give one rank's motion; a scene with another body count is a clear error.
set(ART_POS "${ART} -options_file ${OPTS}/chain.opts -steps 50 -ksp_rtol 1e-12 -progress_every 1000")
add_test(NAME articulated_reference_positions
         COMMAND sh -c "${ART_POS} -write_positions art_ref_positions.txt >/dev/null && ${SUMMARY_CHECK} 'rms_position_diff==0 && max_position_diff==0' -- ${ART_POS} -reference_positions art_ref_positions.txt && ${SUMMARY_CHECK} 'rms_position_diff>1e-4' -- ${ART_POS} -joint_tol 1e-3 -reference_positions art_ref_positions.txt && ${SUMMARY_CHECK} 'rms_position_diff<1e-9' -- ${MPIEXEC_LINE} -n 2 ${ART_POS} -mat_type binbcsr -ksp_type mcg -reference_positions art_ref_positions.txt && ${ART} -options_file ${OPTS}/chain.opts -chain_links 7 -steps 1 -reference_positions art_ref_positions.txt 2>&1 | grep -q 'this run has 7 positions'")
set_tests_properties(articulated_reference_positions PROPERTIES LABELS "articulated;mpi" PROCESSORS 2 TIMEOUT 60)
