# -citations lists the method's source (the journal article and the thesis) in any program that loads
# the plug-in: a stock PETSc program with -dll_append, and one of the project's drivers.
# Label: stock. Budget: about a second.
binbcsr_stock_example(petsc_ksp_ex4 ksp/ksp/tutorials/ex4.c)
set(CITATION_REGEX "Efficient \\{GPU\\} Data Structures and Methods to Solve Sparse Linear Systems.*Computer Graphics Forum.*Interactive Physically Based Simulation")
add_test(NAME citations_dll_append
  COMMAND ${CMAKE_BINARY_DIR}/stock/petsc_ksp_ex4 -m 4 -n 4 -dll_append $<TARGET_FILE:petscbinbcsr>
          -mat_type binbcsr -citations)
set_tests_properties(citations_dll_append PROPERTIES LABELS "stock" TIMEOUT 60
  PASS_REGULAR_EXPRESSION "${CITATION_REGEX}")
