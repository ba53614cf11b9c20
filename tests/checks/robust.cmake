# Issue 9's robustness checks. Each script also runs on its own; see
# docs/ROBUSTNESS.md.
add_test(NAME format COMMAND ${PROJECT_SOURCE_DIR}/scripts/format.sh)
set_tests_properties(format PROPERTIES LABELS check TIMEOUT 120)
