# Label `valgrind` (excluded from the default run; `scripts/test -L valgrind`): the matrix unit tests
# (mat_core, mat_ops, mat_sym, mat_factor, mat_sub, mat_rowops: 1 rank)
# under memcheck, with --error-exitcode=1 and definite leaks counted as errors.
#
# valgrind 3.19 cannot decode the AVX-512 instructions that -march=native emits on AVX-512 machines,
# so these runs use their own build of the plug-in and of the tests without native tuning, in
# build/valgrind (made by the first case, valgrind_build; the others require it as a fixture).
find_program(VALGRIND_EXECUTABLE valgrind)
set(VALGRIND_AREAS)
foreach(area mat_core mat_ops mat_sym mat_factor mat_sub mat_rowops)
  if(TARGET test_${area})
    list(APPEND VALGRIND_AREAS ${area})
  endif()
endforeach()

if(VALGRIND_EXECUTABLE AND VALGRIND_AREAS)
  set(VALGRIND_BUILD_DIR ${CMAKE_BINARY_DIR}/valgrind)
  set(valgrind_targets "")
  foreach(area ${VALGRIND_AREAS})
    string(APPEND valgrind_targets " test_${area}")
  endforeach()
  add_test(NAME valgrind_build
    COMMAND sh -c "\"${CMAKE_COMMAND}\" -S \"${CMAKE_SOURCE_DIR}\" -B \"${VALGRIND_BUILD_DIR}\" -DCMAKE_BUILD_TYPE=Release -DBINBCSR_NATIVE=OFF >/dev/null && \"${CMAKE_COMMAND}\" --build \"${VALGRIND_BUILD_DIR}\" -j2 --target${valgrind_targets}")
  set_tests_properties(valgrind_build PROPERTIES LABELS "valgrind" FIXTURES_SETUP valgrind_build TIMEOUT 1800)
  foreach(area ${VALGRIND_AREAS})
    add_test(NAME valgrind_${area}
      COMMAND ${VALGRIND_EXECUTABLE} --error-exitcode=1 --num-callers=40 --leak-check=full
              --errors-for-leak-kinds=definite --suppressions=${CMAKE_CURRENT_SOURCE_DIR}/valgrind.supp
              ${VALGRIND_BUILD_DIR}/tests/test_${area})
    set_tests_properties(valgrind_${area} PROPERTIES LABELS "valgrind;${area}" FIXTURES_REQUIRED valgrind_build TIMEOUT 1800)
  endforeach()
endif()
