# The C++ sources of src/, examples/ and tests/ are laid out as .clang-format says (scripts/format
# --check lists the files that are not; `scripts/format` fixes them). Skipped where the formatter is not
# clang-format 14 (Debian 13 has 19, which lays some lines out differently) or the tree is no git clone.
# Label: style. Budget: a few seconds.
add_test(NAME style_clang_format COMMAND ${CMAKE_SOURCE_DIR}/scripts/format --check)
set_tests_properties(style_clang_format PROPERTIES LABELS "style" TIMEOUT 120 SKIP_RETURN_CODE 77)
