# Issue 4: real SocketCAN in a VM. Boots Debian's kernel under qemu (TCG),
# creates vcan0 and runs the project's static agent against can-utils'
# candump and cansend. Skipped (exit 77) only when qemu cannot run at all.
if(TARGET tase_port AND CMAKE_SYSTEM_NAME STREQUAL "Linux")
  add_executable(tase_can_vm_agent ${CMAKE_CURRENT_SOURCE_DIR}/vm/can_vm_agent.c)
  target_link_libraries(tase_can_vm_agent PRIVATE tase_port tase)
  target_link_options(tase_can_vm_agent PRIVATE -static)
  target_compile_options(tase_can_vm_agent PRIVATE ${TASE_WARNINGS})
  add_test(NAME can_vm
           COMMAND ${PROJECT_SOURCE_DIR}/scripts/can-vm/run.sh
                   $<TARGET_FILE:tase_can_vm_agent> ${CMAKE_BINARY_DIR}/can-vm)
  set_tests_properties(can_vm PROPERTIES LABELS check TIMEOUT 600 SKIP_RETURN_CODE 77)
endif()
