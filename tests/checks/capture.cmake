# Issue 15 items 5 and 6: pcap captures (`tase decode` of pcap/pcapng,
# `tase record`, `--record`, `tase replay`) end to end, and the Wireshark
# dissector tools/wireshark/tase.lua under Debian's tshark, compared with
# `tase decode` (scripts/packages.d/wireshark.txt).
if(TARGET tase_cli AND TARGET tase_sim)
  # Prints the dissector's packet table from the library's schema.
  add_executable(tase_schema_lua ${PROJECT_SOURCE_DIR}/tools/wireshark/schema_lua.c)
  target_link_libraries(tase_schema_lua PRIVATE tase)
  target_compile_options(tase_schema_lua PRIVATE ${TASE_WARNINGS})
  add_test(NAME tools_capture
           COMMAND ${PROJECT_SOURCE_DIR}/tests/tools/capture.sh $<TARGET_FILE:tase_cli>
                   $<TARGET_FILE:tase_sim> ${PROJECT_SOURCE_DIR}/tests/data)
  add_test(NAME wireshark
           COMMAND ${PROJECT_SOURCE_DIR}/tests/tools/wireshark.sh $<TARGET_FILE:tase_cli>
                   $<TARGET_FILE:tase_sim> $<TARGET_FILE:tase_schema_lua>
                   ${PROJECT_SOURCE_DIR}/tests/data)
  set_tests_properties(tools_capture wireshark PROPERTIES LABELS "check;e2e" TIMEOUT 180)
  tase_python_tests(tools_capture wireshark) # capture_util.py imports the tase package
  # tools_capture checks replay timing on the real clock: it runs alone.
  set_tests_properties(tools_capture PROPERTIES RUN_SERIAL TRUE)
endif()
