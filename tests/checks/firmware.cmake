# Issue 8: the example gimbal firmware, built for Cortex-M3 and run under
# QEMU (mps2-an385); it exits with its own pass/fail status.
add_test(NAME firmware_qemu COMMAND ${PROJECT_SOURCE_DIR}/scripts/check-firmware.sh ${CMAKE_BINARY_DIR}/firmware)
set_tests_properties(firmware_qemu PROPERTIES LABELS check TIMEOUT 600)
