# Issue 9's robustness checks (docs/ROBUSTNESS.md). Each script also runs
# on its own from the source tree.
add_test(NAME format COMMAND ${PROJECT_SOURCE_DIR}/scripts/dev/format.sh)
add_test(NAME sanitize COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/sanitize.sh ${CMAKE_BINARY_DIR}/sanitize)
add_test(NAME valgrind COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/valgrind.sh ${CMAKE_BINARY_DIR})
set_tests_properties(format sanitize PROPERTIES LABELS check TIMEOUT 900)
# memcheck over every unit and end-to-end test: 591 s on the CI machine
# (2026-11-27; the tools' end-to-end tests alone 204 s under it), so the
# bound leaves twice that
set_tests_properties(valgrind PROPERTIES LABELS check TIMEOUT 1200)
add_test(NAME coverage COMMAND ${PROJECT_SOURCE_DIR}/scripts/dev/coverage.sh ${CMAKE_BINARY_DIR}/coverage)
set_tests_properties(coverage PROPERTIES LABELS check TIMEOUT 900)
add_test(NAME static_analysis COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/static.sh ${CMAKE_BINARY_DIR}/static)
set_tests_properties(static_analysis PROPERTIES LABELS check TIMEOUT 900)
# Bit-error sweep (tests/robust/ber_sweep.c): 1e6 packets per channel
# through flips/drops/inserts; --check asserts zero collateral loss, no
# single-bit error accepted, false acceptance within the checksum's rate.
add_executable(ber_sweep ${PROJECT_SOURCE_DIR}/tests/robust/ber_sweep.c)
target_link_libraries(ber_sweep PRIVATE tase m)
target_compile_options(ber_sweep PRIVATE ${TASE_WARNINGS})
add_test(NAME ber_sweep COMMAND ber_sweep --check)
set_tests_properties(ber_sweep PROPERTIES LABELS check TIMEOUT 60)
