# Issue 4: real SocketCAN in a VM. Boots Debian's kernel under qemu (TCG),
# creates vcan0 and runs the project's static agent against can-utils'
# candump and cansend, then the bench tools of issue 6 (tase-sim --can and
# tase --can, built static for the VM) over vcan0. Skipped (exit 77) only
# when qemu cannot run at all.
if(TARGET tase_socketcan)
  # The static programs are built by the check itself (can_vm_build below),
  # not by the default build: static glibc's linker warnings about NSS calls
  # (which the tools never make) stay out of an ordinary build's output.
  add_executable(tase_can_vm_agent EXCLUDE_FROM_ALL ${CMAKE_CURRENT_SOURCE_DIR}/vm/can_vm_agent.c)
  target_link_libraries(tase_can_vm_agent PRIVATE tase_socketcan tase)
  target_link_options(tase_can_vm_agent PRIVATE -static)
  target_compile_options(tase_can_vm_agent PRIVATE ${TASE_WARNINGS})
  # Static copies of the tools from the same sources (the VM has no libc).
  # Static glibc warns about getaddrinfo/NSS; the tools use neither.
  set(TASE_CAN_VM_TOOLS "")
  set(TASE_CAN_VM_TARGETS "")
  if(TARGET tase_capture AND TARGET tase_sim_model)
    # libpcap.a needs libdbus-1.a, and that two libsystemd calls (shim).
    # TASE_CLI_SOURCES, TASE_SIM_SOURCES: tools/CMakeLists.txt
    add_executable(tase_can_vm_cli EXCLUDE_FROM_ALL ${TASE_CLI_SOURCES}
                                   ${CMAKE_CURRENT_SOURCE_DIR}/vm/libsystemd_stub.c)
    target_link_libraries(tase_can_vm_cli PRIVATE tase_capture pcap dbus-1)
    add_executable(tase_can_vm_sim EXCLUDE_FROM_ALL ${TASE_SIM_SOURCES})
    target_link_libraries(tase_can_vm_sim PRIVATE tase_toolkit tase_sim_model)
    foreach(t tase_can_vm_cli tase_can_vm_sim)
      target_link_options(${t} PRIVATE -static)
      target_compile_options(${t} PRIVATE ${TASE_WARNINGS})
    endforeach()
    set(TASE_CAN_VM_TOOLS $<TARGET_FILE:tase_can_vm_cli> $<TARGET_FILE:tase_can_vm_sim>)
    set(TASE_CAN_VM_TARGETS tase_can_vm_cli tase_can_vm_sim)
  else()
    message(STATUS "can_vm: the bench tools are not built; the VM test skips their CAN part")
  endif()
  add_test(NAME can_vm_build
           COMMAND ${CMAKE_COMMAND} --build ${CMAKE_BINARY_DIR} --target tase_can_vm_agent
                   ${TASE_CAN_VM_TARGETS})
  set_tests_properties(can_vm_build PROPERTIES LABELS check TIMEOUT 600 FIXTURES_SETUP can_vm_programs)
  add_test(NAME can_vm
           COMMAND ${PROJECT_SOURCE_DIR}/scripts/can-vm/run.sh
                   $<TARGET_FILE:tase_can_vm_agent> ${CMAKE_BINARY_DIR}/can-vm
                   ${TASE_CAN_VM_TOOLS})
  # RUN_SERIAL: the guest runs the bench tools on its real (emulated) clock and
  # counts telemetry rates; parallel fuzzers must not starve it.
  set_tests_properties(can_vm PROPERTIES LABELS check TIMEOUT 600 SKIP_RETURN_CODE 77 RUN_SERIAL TRUE
                       FIXTURES_REQUIRED can_vm_programs)
endif()
