# Issue 2's build matrix: clang, Cortex-M cross builds, no heap in the core.
# The Cortex-M builds (issue 8) cover M0+, M3, M4 and M7, each by hand and
# through cmake/arm-none-eabi.cmake.
add_test(NAME clang_build COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/clang.sh ${CMAKE_BINARY_DIR}/clang)
set(TASE_ARM_CHECKS)
foreach(cpu m0plus m3 m4 m7)
  add_test(NAME arm_cortex_${cpu} COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/arm.sh cortex-${cpu} ${CMAKE_BINARY_DIR}/arm-${cpu})
  list(APPEND TASE_ARM_CHECKS arm_cortex_${cpu})
endforeach()
add_test(NAME no_heap_host COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/no-heap.sh nm $<TARGET_FILE:tase>)
set_tests_properties(clang_build ${TASE_ARM_CHECKS} no_heap_host PROPERTIES LABELS check TIMEOUT 600)
