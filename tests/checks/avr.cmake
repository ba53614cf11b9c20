# Issue 13: the core and the bare-metal port compiled for an 8-bit AVR
# (16-bit int) with the full warning set, and tests/avr/avr_core.c run
# under simavr with its result checked (scripts/checks/avr.sh).
add_test(NAME avr COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/avr.sh ${CMAKE_BINARY_DIR}/avr)
set_tests_properties(avr PROPERTIES LABELS check TIMEOUT 300)
