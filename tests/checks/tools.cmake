# Issues 6 and 15: the bench tools. The decode golden files, the command
# line and decoding behaviour without a simulator (tools_cli), and the
# end-to-end run of `tase` against a real `tase-sim` process over a
# pseudo-terminal (tools_e2e).
if(TARGET tase_cli AND TARGET tase_sim)
  add_test(NAME tools_decode
           COMMAND ${PROJECT_SOURCE_DIR}/tests/tools/decode.sh $<TARGET_FILE:tase_cli>
                   ${PROJECT_SOURCE_DIR}/tests/data)
  add_test(NAME tools_cli
           COMMAND ${PROJECT_SOURCE_DIR}/tests/tools/cli.py $<TARGET_FILE:tase_cli>
                   $<TARGET_FILE:tase_sim>)
  # signals at the worst moments for the tools (tests/tools/signal_shim.c)
  add_library(tase_test_signal_shim MODULE ${PROJECT_SOURCE_DIR}/tests/tools/signal_shim.c)
  target_link_libraries(tase_test_signal_shim PRIVATE ${CMAKE_DL_LIBS})
  add_test(NAME tools_e2e
           COMMAND ${PROJECT_SOURCE_DIR}/tests/tools/e2e.sh $<TARGET_FILE:tase_cli>
                   $<TARGET_FILE:tase_sim> $<TARGET_FILE:tase_test_signal_shim>)
  set_tests_properties(tools_decode tools_cli tools_e2e PROPERTIES LABELS "check;e2e" TIMEOUT 180)
  tase_python_tests(tools_cli) # frames built and read by the tase package
  # tools_e2e drives real processes on the real clock (timeouts, rates): it
  # runs alone, so the fuzzers and sanitizer builds cannot starve it.
  set_tests_properties(tools_e2e PROPERTIES RUN_SERIAL TRUE)
endif()
