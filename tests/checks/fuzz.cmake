# libFuzzer harnesses (fuzz/<name>.c), one line each: tase_fuzz(<name> <seconds>).
# Each registers two tests:
#   fuzz_<name>         bounded fuzz run with clang, ASan + UBSan (label check);
#   fuzz_replay_<name>  the committed corpus fuzz/corpus/<name> (seeds and
#                       crash regressions) replayed with the project compiler
#                       (label unit, fast).
# Keep the sum of the times <= ~240 s: ctest runs two at a time on 2 cores.
function(tase_fuzz name seconds)
  add_test(NAME fuzz_${name}
           COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/fuzz.sh ${name} ${seconds} ${CMAKE_BINARY_DIR}/fuzz)
  math(EXPR limit "${seconds} + 300")
  set_tests_properties(fuzz_${name} PROPERTIES LABELS "check;fuzz" TIMEOUT ${limit})
  add_executable(fuzz_replay_${name} ${PROJECT_SOURCE_DIR}/fuzz/${name}.c
                 ${PROJECT_SOURCE_DIR}/fuzz/replay_main.c)
  target_link_libraries(fuzz_replay_${name} PRIVATE tase)
  target_compile_options(fuzz_replay_${name} PRIVATE ${TASE_WARNINGS})
  add_test(NAME fuzz_replay_${name}
           COMMAND fuzz_replay_${name} ${PROJECT_SOURCE_DIR}/fuzz/corpus/${name})
  set_tests_properties(fuzz_replay_${name} PROPERTIES LABELS "unit;fuzz" TIMEOUT 120)
endfunction()

tase_fuzz(rx_bytes 60)  # datalink receiver, arbitrary bytes in random splits
tase_fuzz(rx_frames 30) # valid frames + noise + corruptions: zero collateral loss
tase_fuzz(decode 20)    # every packet decoder + dispatcher, any (group, type) and length
tase_fuzz(klv 20)       # KLV decoder (codes, round trip, first failure wins) + stream scanner
tase_fuzz(can 20)       # CAN reassembly with lost/repeated/reordered/foreign frames; candump
