# Issue 13: the library as users take it (scripts/checks/integration.sh):
# install + find_package with a port target, add_subdirectory and
# FetchContent under a stricter parent, pkg-config, a CubeMX-style flat
# Makefile, Cortex-M4 through the toolchain file, C++ (every header, the
# handler table), the configuration header and its mismatch detection.
add_test(NAME integration COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/integration.sh ${CMAKE_BINARY_DIR}/integration)
set_tests_properties(integration PROPERTIES LABELS check TIMEOUT 600)
