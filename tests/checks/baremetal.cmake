# Issue 5: the bare-metal UART template and the roles cross-compile for
# Cortex-M exactly as firmware would (no host barrier config).
add_test(NAME baremetal_arm_m0plus COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/baremetal-arm.sh cortex-m0plus ${CMAKE_BINARY_DIR}/baremetal-m0plus)
add_test(NAME baremetal_arm_m4 COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/baremetal-arm.sh cortex-m4 ${CMAKE_BINARY_DIR}/baremetal-m4)
set_tests_properties(baremetal_arm_m0plus baremetal_arm_m4 PROPERTIES LABELS check TIMEOUT 600)
