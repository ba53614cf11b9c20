# The checksum and the receiver on Cortex-M code paths (USADA8 words on the
# M4, bytes on the M0+), built at -O2 and -Os and run under QEMU; each image
# exits with its own pass/fail status (tests/cm/frame_on_target.c).
foreach(cpu cortex-m4 cortex-m0plus)
  string(REPLACE "-" "_" name "cm_frame_${cpu}")
  add_test(NAME ${name} COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/cm-frame.sh ${cpu}
    ${CMAKE_BINARY_DIR}/cm-frame)
  set_tests_properties(${name} PROPERTIES LABELS check TIMEOUT 300)
endforeach()
