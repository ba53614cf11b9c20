# Issue 17: the example autopilot firmware (host role, Cortex-M4F) under
# QEMU's mps2-an386, flying a SPOI mission against a live tase-sim over the
# guest's UART. Real clock, about 12 s of mission after the build.
if(TARGET tase_sim)
  add_test(NAME autopilot_qemu
           COMMAND ${PROJECT_SOURCE_DIR}/scripts/check-autopilot.sh $<TARGET_FILE:tase_sim>
                   ${CMAKE_BINARY_DIR}/autopilot)
  set_tests_properties(autopilot_qemu PROPERTIES LABELS check TIMEOUT 300)
endif()
