# Issue 2's build matrix: clang, Cortex-M cross builds, no heap in the core.
add_test(NAME clang_build COMMAND ${PROJECT_SOURCE_DIR}/scripts/check-clang.sh ${CMAKE_BINARY_DIR}/clang)
add_test(NAME arm_cortex_m4 COMMAND ${PROJECT_SOURCE_DIR}/scripts/check-arm.sh cortex-m4 ${CMAKE_BINARY_DIR}/arm-m4)
add_test(NAME arm_cortex_m0plus COMMAND ${PROJECT_SOURCE_DIR}/scripts/check-arm.sh cortex-m0plus ${CMAKE_BINARY_DIR}/arm-m0plus)
add_test(NAME no_heap_host COMMAND ${PROJECT_SOURCE_DIR}/scripts/check-no-heap.sh nm $<TARGET_FILE:tase>)
set_tests_properties(clang_build arm_cortex_m4 arm_cortex_m0plus no_heap_host PROPERTIES LABELS check TIMEOUT 600)
