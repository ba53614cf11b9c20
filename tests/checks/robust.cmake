# Issue 9's robustness checks (docs/ROBUSTNESS.md). Each script also runs
# on its own from the source tree.
add_test(NAME format COMMAND ${PROJECT_SOURCE_DIR}/scripts/dev/format.sh)
add_test(NAME sanitize COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/sanitize.sh ${CMAKE_BINARY_DIR}/sanitize)
# memcheck over every unit and end-to-end test, in two halves that ctest runs
# side by side: valgrind_serial takes the tests ctest runs alone (RUN_SERIAL,
# on the real clock: still one after another inside it), valgrind the rest.
# As one test it took 730 s of a 1,228 s CI run (2026-11-28) and started
# only after 200 s, so the serial tests waited for it; the COSTs make ctest
# start both halves first (a clean clone has no cost data of its own).
# In the CI run after the split (2026-11-28): 502 s and 215 s, the whole
# suite 964 s (was 1,228); the bound leaves over twice the larger.
add_test(NAME valgrind_serial COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/valgrind.sh ${CMAKE_BINARY_DIR} serial)
add_test(NAME valgrind COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/valgrind.sh ${CMAKE_BINARY_DIR} parallel)
set_tests_properties(valgrind_serial PROPERTIES LABELS check TIMEOUT 1200 COST 1000)
set_tests_properties(valgrind PROPERTIES LABELS check TIMEOUT 600 COST 500)
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
