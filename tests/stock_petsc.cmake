# PETSc's own example programs, built unchanged from the installed sources, run with the plug-in
# loaded at run time (-dll_append) and -mat_type binbcsr, against the same program with a stock type.
# tests/stock_compare.sh runs both and compares the result lines (norms, iteration counts, vectors).
# Label: stock, mat_ops. Budget: about 30 s for all of them on the 2-core machine.
# Matrix listings are compared where the program prints them: the format prints them like seqaij.
set(STOCK_COMPARE ${CMAKE_CURRENT_SOURCE_DIR}/stock_compare.sh)
set(SPD_MATRIX ${PETSC_DATAFILES_DIR}/matrices/spd-real-int32-float64)
set(STOCK_DIR ${CMAKE_BINARY_DIR}/stock)

binbcsr_stock_example(petsc_ksp_ex4 ksp/ksp/tutorials/ex4.c)
binbcsr_stock_example(petsc_ksp_ex72 ksp/ksp/tutorials/ex72.c)
binbcsr_stock_example(petsc_mat_ex18 mat/tests/ex18.c)
binbcsr_stock_example(petsc_mat_ex5 mat/tests/ex5.c)
binbcsr_stock_example(petsc_mat_ex184 mat/tests/ex184.c)
binbcsr_stock_example(petsc_mat_ex2 mat/tests/ex2.c)
binbcsr_stock_example(petsc_mat_ex11 mat/tests/ex11.c)

# name, then stock_compare.sh arguments; the plug-in's path is substituted for @PLUGIN@.
function(binbcsr_stock_case name)
  set(args ${ARGN})
  list(TRANSFORM args REPLACE "@PLUGIN@" "$<TARGET_FILE:petscbinbcsr>")
  list(TRANSFORM args REPLACE "@STOCK@" "${STOCK_DIR}")
  add_test(NAME stock_${name} COMMAND sh ${STOCK_COMPARE} ${args})
  set_tests_properties(stock_${name} PROPERTIES LABELS "stock;mat_ops" TIMEOUT 120)
endfunction()

set(PLUGIN_ARGS "-dll_append @PLUGIN@")

# ksp ex4: 3 unknowns per vertex, assembled point-wise with ADD_VALUES after MatSeqAIJSetPreallocation;
# CG + Jacobi (ex4 assembles point-wise with the AIJ preallocation; binbcsr's block ILU would not match
# aij's point ILU, so the factorisations are compared on ex72 below).
set(EX4 "@STOCK@/petsc_ksp_ex4 -bs 3 -m 9 -n 7 -ksp_type cg -pc_type jacobi -ksp_monitor_short")
binbcsr_stock_case(ksp_ex4_bs3
  --keep "Norm of error|Residual norm" --atol 1e-12
  --ref "${EX4} -mat_type aij"
  --test "${EX4} ${PLUGIN_ARGS} -mat_type binbcsr")
binbcsr_stock_case(ksp_ex4_bs3_single
  --keep "iterations|Residual norm" --drop "Norm of error" --rtol 1e-5
  --ref "${EX4} -mat_type aij"
  --test "${EX4} ${PLUGIN_ARGS} -mat_type binbcsr -mat_binbcsr_precision single")

# Registration through -dll_append really happened: the matrix reports the plug-in's type and its
# layout (and the run would fail with "Unknown type" otherwise).
binbcsr_stock_case(dll_append_registers_binbcsr
  --keep "Norm of error" --atol 1e-12 --expect "BIN-BCSR, block size 3"
  --ref "${EX4} -mat_type aij"
  --test "${EX4} ${PLUGIN_ARGS} -mat_type binbcsr -mat_view ::ascii_info")

# ksp ex72: PETSc's SPD data matrix loaded as seqaij and converted (-mat_convert_type), and loaded
# directly through MatLoad as binbcsr with 3x3 blocks (-matload_block_size 3).
set(EX72 "@STOCK@/petsc_ksp_ex72 -f0 ${SPD_MATRIX} -ksp_type cg -pc_type jacobi -ksp_monitor_short -viewer_binary_skip_info")
binbcsr_stock_case(ksp_ex72_convert
  --keep "Number of iterations|Residual norm" --atol 1e-12
  --ref "${EX72}"
  --test "${EX72} ${PLUGIN_ARGS} -mat_convert_type binbcsr")
binbcsr_stock_case(ksp_ex72_matload_bs3
  --keep "Number of iterations|Residual norm" --atol 1e-12
  --ref "${EX72} -mat_type baij -matload_block_size 3"
  --test "${EX72} ${PLUGIN_ARGS} -mat_type binbcsr -matload_block_size 3")
# The same matrix with PETSc's block ICC(0) and ILU(0) (binbcsr factors through a seqsbaij/seqbaij copy,
# as seqbaij itself does for ICC): the same iterations and residuals as baij.
binbcsr_stock_case(ksp_ex72_icc_bs3
  --keep "Number of iterations|Residual norm" --atol 1e-12 --expect "type: seqbinbcsr"
  --ref "${EX72} -mat_type baij -matload_block_size 3 -pc_type icc"
  --test "${EX72} ${PLUGIN_ARGS} -mat_type binbcsr -matload_block_size 3 -pc_type icc -ksp_view")
binbcsr_stock_case(ksp_ex72_ilu_bs3
  --keep "Number of iterations|Residual norm" --atol 1e-12 --expect "type: seqbinbcsr"
  --ref "${EX72} -mat_type baij -matload_block_size 3 -ksp_type gmres -pc_type ilu"
  --test "${EX72} ${PLUGIN_ARGS} -mat_type binbcsr -matload_block_size 3 -ksp_type gmres -pc_type ilu -ksp_view")

# PETSc's SPD data matrix is 12 x 12: ICC(0) and ILU(0) factor it exactly (one iteration), so they
# cannot tell a right incomplete factorisation from an exact solve. A 624-unknown FEM matrix
# (the fem driver's first step, P1 beam 12 x 3 x 3 cells) takes 45 CG + ICC(0) and 49 GMRES + ILU(0)
# iterations against 1 with Cholesky: binbcsr must take baij's counts and residuals.
if(TARGET fem)
  set(FEM_MATRIX ${CMAKE_CURRENT_BINARY_DIR}/stock_fem_matrix.bin)
  add_test(NAME stock_fem_matrix_setup
           COMMAND $<TARGET_FILE:fem> -mesh_box 1,0.1,0.1,12,3,3 -fix xmin -steps 1 -fem_quiet -mat_type aij -dump_matrix ${FEM_MATRIX})
  set_tests_properties(stock_fem_matrix_setup PROPERTIES LABELS "stock;mat_ops" FIXTURES_SETUP stock_fem_matrix TIMEOUT 60)
  set(EX72_FEM "@STOCK@/petsc_ksp_ex72 -f0 ${FEM_MATRIX} -rhs 0 -ksp_type cg -matload_block_size 3 -viewer_binary_skip_info")
  binbcsr_stock_case(ksp_ex72_fem_icc_bs3
    --keep "Number of iterations|Residual norm" --rtol 1e-4 --expect "Number of iterations = +45"
    --ref "${EX72_FEM} -mat_type baij -pc_type icc"
    --test "${EX72_FEM} ${PLUGIN_ARGS} -mat_type binbcsr -pc_type icc")
  binbcsr_stock_case(ksp_ex72_fem_ilu_bs3
    --keep "Number of iterations|Residual norm" --rtol 1e-4 --expect "Number of iterations = +49"
    --ref "${EX72_FEM} -mat_type baij -ksp_type gmres -pc_type ilu"
    --test "${EX72_FEM} ${PLUGIN_ARGS} -mat_type binbcsr -ksp_type gmres -pc_type ilu")
  set_tests_properties(stock_ksp_ex72_fem_icc_bs3 stock_ksp_ex72_fem_ilu_bs3 PROPERTIES FIXTURES_REQUIRED stock_fem_matrix)
endif()

# CG + SSOR (PCSOR, block sweeps with the 3x3 diagonal blocks inverted, as seqbaij): whole and
# upper-triangle storage take baij's iterations and residuals.
binbcsr_stock_case(ksp_ex72_ssor_bs3
  --keep "Number of iterations|Residual norm" --atol 1e-12 --expect "type: seqbinbcsr"
  --ref "${EX72} -mat_type baij -matload_block_size 3 -pc_type sor"
  --test "${EX72} ${PLUGIN_ARGS} -mat_type binbcsr -matload_block_size 3 -pc_type sor -ksp_view")
binbcsr_stock_case(ksp_ex72_ssor_bs3_symmetric_storage
  --keep "Number of iterations|Residual norm" --atol 1e-12
  --ref "${EX72} -mat_type baij -matload_block_size 3 -pc_type sor"
  --test "${EX72} ${PLUGIN_ARGS} -mat_type binbcsr -mat_binbcsr_symmetric_storage -matload_block_size 3 -pc_type sor")

# mat ex18: MatZeroRowsColumns with x and b on a 3x3-block matrix; the program checks b itself and
# prints it. The matrix listings differ by format and are not compared.
set(EX18 "@STOCK@/petsc_mat_ex18 -bs 3")
binbcsr_stock_case(mat_ex18_bs3
  --drop "^row |Mat Object|type:|^ +row " --rtol 1e-12
  --ref "${EX18} -mat_type aij"
  --test "${EX18} ${PLUGIN_ARGS} -mat_type binbcsr")
binbcsr_stock_case(mat_ex18_bs3_nonlocal_bc
  --drop "^row |Mat Object|type:|^ +row " --rtol 1e-12
  --ref "${EX18} -nonlocal_bc -mat_type aij"
  --test "${EX18} -nonlocal_bc ${PLUGIN_ARGS} -mat_type binbcsr")

# mat ex5: MatMult(Add), MatMultTranspose(Add), MatGetDiagonal, MatDiagonalScale, MatScale, on square
# and rectangular matrices; the output is identical to seqaij's but for the type line.
foreach(shape square rectA rectB)
  set(shape_arg "")
  if(NOT shape STREQUAL "square")
    set(shape_arg "-${shape}")
  endif()
  binbcsr_stock_case(mat_ex5_${shape}
    --drop "type:" --rtol 1e-12
    --ref "@STOCK@/petsc_mat_ex5 ${shape_arg} -mat_type seqaij"
    --test "@STOCK@/petsc_mat_ex5 ${shape_arg} ${PLUGIN_ARGS} -mat_type binbcsr")
endforeach()

# mat ex184: MatSetValuesBlocked and MatInvertBlockDiagonalMat with 3x3 blocks; it prints only when
# the inverse is wrong.
binbcsr_stock_case(mat_ex184_bs3
  --allow-empty --keep "Norm of error|Inverse|rror" --expect "type: seqbinbcsr"
  --ref "@STOCK@/petsc_mat_ex184 -mat_size 12 -mat_block_size 3 -mat_type seqbaij"
  --test "@STOCK@/petsc_mat_ex184 -mat_size 12 -mat_block_size 3 ${PLUGIN_ARGS} -mat_type binbcsr -mat_view ::ascii_info")

# mat ex2: MatNorm (Frobenius, 1, infinity), MatAXPY (same and different patterns, transposed
# operands), MatAYPX, MatTranspose, MatZeroRows, MatShift. binbcsr keeps its pattern in MatZeroRows
# where seqaij drops the entries: stored zeros are left out of the comparison.
foreach(shape square rectA rectB)
  set(shape_arg "")
  if(NOT shape STREQUAL "square")
    set(shape_arg "-${shape}")
  endif()
  binbcsr_stock_case(mat_ex2_${shape}
    --drop "type:" --strip "[(][0-9]+, -?0[.][)] *" --rtol 1e-12
    --ref "@STOCK@/petsc_mat_ex2 ${shape_arg} -mat_type seqaij"
    --test "@STOCK@/petsc_mat_ex2 ${shape_arg} ${PLUGIN_ARGS} -mat_type binbcsr")
endforeach()

# mat ex11: MatZeroRowsIS with a diagonal value after MatSetUp without preallocation (the pattern
# comes from MatSetValues), scalar and 5x5 blocks (a block size binbcsr handles generically).
binbcsr_stock_case(mat_ex11
  --drop "type:" --strip "[(][0-9]+, -?0[.][)] *" --rtol 1e-12
  --ref "@STOCK@/petsc_mat_ex11 -mat_type seqaij"
  --test "@STOCK@/petsc_mat_ex11 ${PLUGIN_ARGS} -mat_type binbcsr")
binbcsr_stock_case(mat_ex11_bs5
  --drop "type:" --strip "[(][0-9]+, -?0[.][)] *" --rtol 1e-12
  --ref "@STOCK@/petsc_mat_ex11 -keep_nonzero_pattern -mat_type seqbaij -mat_block_size 5"
  --test "@STOCK@/petsc_mat_ex11 -keep_nonzero_pattern ${PLUGIN_ARGS} -mat_type binbcsr -mat_block_size 5")
