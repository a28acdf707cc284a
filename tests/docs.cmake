# Every file the README, the changelog and docs/ name exists (scripts/check-doc-refs).
# Label: docs. Budget: a few seconds.
add_test(NAME docs_file_references COMMAND ${CMAKE_SOURCE_DIR}/scripts/check-doc-refs)
set_tests_properties(docs_file_references PROPERTIES LABELS "docs" TIMEOUT 60)
