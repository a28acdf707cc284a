# examples/fem driver runs (small scenes; the physics is checked by unit_fem, these check the program:
# options, scene files, mesh input, errors, MPI). Each must print `status=ok` or the expected error.
set(FEM $<TARGET_FILE:fem>)
set(FEM_SRC ${CMAKE_SOURCE_DIR})
set(FEM_SMALL -mesh_box 1,0.1,0.1,8,2,2 -fix xmin -steps 3 -fem_quiet)

function(fem_test name regex)
  add_test(NAME ${name} COMMAND ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS "fem" PASS_REGULAR_EXPRESSION "${regex}" TIMEOUT 60
                                          WORKING_DIRECTORY ${FEM_SRC})
endfunction()

fem_test(fem_p1_aij_cg "status=ok" ${FEM} ${FEM_SMALL} -mat_type aij -ksp_type cg)
fem_test(fem_p2_binbcsr_mcg "order=2.*status=ok" ${FEM} ${FEM_SMALL} -fem_order 2 -mat_type binbcsr -ksp_type mcg)
fem_test(fem_p2_baij_pipecg "mat_type=seqbaij.*status=ok" ${FEM} ${FEM_SMALL} -fem_order 2 -mat_type baij -ksp_type pipecg)
fem_test(fem_p2_sell_linear "mat_type=seqsell.*status=ok" ${FEM} ${FEM_SMALL} -fem_order 2 -mat_type sell -fem_corotational 0
         -fem_mass_lumped)
fem_test(fem_fixed_iterations "timer=cpu .*cg_its=30 .*status=ok" ${FEM} ${FEM_SMALL} -fem_timer cpu -mat_type binbcsr -ksp_type mcg
         -ksp_mcg_fixed_iterations 30 -ksp_max_it 30)
fem_test(fem_static_cantilever "status=ok" ${FEM} -options_file options/cantilever.opts -static -steps 3)
fem_test(fem_scene_files "mat_type=seqaij ksp_type=cg .*cg_its=30 .*status=ok" ${FEM} -options_file options/cantilever.opts
         -options_file options/compare_aij_cg.opts -ksp_max_it 30 -steps 2)
fem_test(fem_vtk_and_dump "status=ok" ${FEM} ${FEM_SMALL} -fem_order 2 -vtk ${CMAKE_CURRENT_BINARY_DIR}/fem_vtk_test
         -vtk_every 2 -dump_matrix ${CMAKE_CURRENT_BINARY_DIR}/fem_dump_test.bin)
fem_test(fem_inverted_start "initial min volume ratio -.*status=ok" ${FEM} -mesh_box 1,0.2,0.2,6,1,1 -fix xmin -gravity 0,0,0 -initial_perturb 27,0,-0.3,-0.35
         -rayleigh 1,0 -steps 40 -fem_quiet -ksp_rtol 1e-10)
fem_test(fem_geo_mesh "elements=.*status=ok" ${FEM} -mesh examples/meshes/bunny.geo -mesh_size 0.06 -fix zmin:0.05 -steps 2
         -fem_quiet)
fem_test(fem_aijcusparse_error "needs a PETSc configured with CUDA" ${FEM} ${FEM_SMALL} -options_file options/compare_aijcusparse.opts)
fem_test(fem_bad_mesh_error "cannot open mesh file" ${FEM} -mesh /nonexistent/mesh.msh)
fem_test(fem_bad_option_error "-fix .*expected none" ${FEM} ${FEM_SMALL} -fix middle)
fem_test(fem_bad_material_error "Poisson" ${FEM} ${FEM_SMALL} -poisson 0.5)
fem_test(fem_mpi2_aij "ranks=2 .*status=ok" ${MPIEXEC_CMD} -n 2 ${FEM} ${FEM_SMALL} -fem_order 2 -mat_type aij)
set_tests_properties(fem_mpi2_aij PROPERTIES LABELS "fem;mpi")
# The COO mirror on 2 ranks (upper blocks only, lower ones filled by the Mat, also across ranks) and
# the matrix dump of such a system.
fem_test(fem_mpi2_binbcsr_mirror "mat_type=mpibinbcsr .*ranks=2 .*status=ok" ${MPIEXEC_CMD} -n 2 ${FEM} ${FEM_SMALL} -fem_order 2
         -mat_type binbcsr -mat_binbcsr_coo_mirror -ksp_type mcg -dump_matrix ${CMAKE_CURRENT_BINARY_DIR}/fem_mirror_dump.bin)
set_tests_properties(fem_mpi2_binbcsr_mirror PROPERTIES LABELS "fem;mpi")
add_test(NAME unit_fem_mpi2 COMMAND ${MPIEXEC_CMD} -n 2 $<TARGET_FILE:test_fem> "[mpi]")
set_tests_properties(unit_fem_mpi2 PROPERTIES LABELS "fem;mpi;unit" TIMEOUT 60)
# GAMG with the rest shape's rigid body modes as near null space (the driver's default): a slender beam
# that GAMG's default translations-only space leaves at 43-45 CG iterations per solve takes about 22 with them.
set(FEM_BEAM_GAMG -mesh_box 1,0.1,0.1,16,3,3 -fix xmin -steps 3 -fem_quiet -mat_type binbcsr -ksp_type cg -pc_type gamg -ksp_rtol 1e-8)
fem_test(fem_gamg_rigid_body_modes "cg_its=(1[0-9]|2[0-5])[. ].*status=ok" ${FEM} ${FEM_BEAM_GAMG})
fem_test(fem_mpi2_gamg_rigid_body_modes "ranks=2 .*cg_its=(1[0-9]|2[0-5])[. ].*status=ok" ${MPIEXEC_CMD} -n 2 ${FEM} ${FEM_BEAM_GAMG})
set_tests_properties(fem_mpi2_gamg_rigid_body_modes PROPERTIES LABELS "fem;mpi")
fem_test(fem_gamg_translations_only "cg_its=(3[5-9]|4[0-9]|5[0-5])[. ].*status=ok" ${FEM} ${FEM_BEAM_GAMG} -fem_rigid_body_modes 0)
