# The README's example compiles with the full warning set and runs.
add_test(NAME readme_example COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/readme-example.sh ${CMAKE_BINARY_DIR}/readme-example)
set_tests_properties(readme_example PROPERTIES LABELS check TIMEOUT 120)
