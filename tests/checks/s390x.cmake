# Issue 13: every unit test built for s390x (big-endian) with Debian's
# cross compiler and run under qemu-user (scripts/checks/s390x.sh).
add_test(NAME s390x COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/s390x.sh ${CMAKE_BINARY_DIR}/s390x)
# RUN_SERIAL: the unit tests on the real clock (ptys, threads, timeouts)
# run under emulation here; parallel fuzzers must not starve them.
set_tests_properties(s390x PROPERTIES LABELS check TIMEOUT 600 RUN_SERIAL TRUE)
