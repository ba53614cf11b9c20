# Issue 16: spec fidelity end to end with the built tools. `tase decode`
# types both AXIS_SETTING layouts (22 and 23 bytes); a running tase-sim
# echoes a PACKET_RATE with its reserved bytes zero, answers a SPOI echo
# request with its own flags and reports a NavHealth of filter mode
# "normal". Issue 23: one check per numbered line of the issue (tase-sim
# behaving like a real TASE; see the script's header). About 35 s.
if(TARGET tase_cli AND TARGET tase_sim)
  add_test(NAME spec_e2e
           COMMAND ${PROJECT_SOURCE_DIR}/tests/tools/spec.sh $<TARGET_FILE:tase_cli>
                   $<TARGET_FILE:tase_sim>)
  # a real process pair on the real clock: alone, like tools_e2e
  set_tests_properties(spec_e2e PROPERTIES LABELS "check;e2e" TIMEOUT 60 RUN_SERIAL TRUE)
endif()
