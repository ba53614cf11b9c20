# cmake -DGZIP=/usr/bin/gzip -DIN=file -DOUT=file.gz -P tase-gzip.cmake:
# OUT is IN compressed as Debian installs documentation (gzip -9n: no name
# or time in the header, so the same input gives the same bytes).
get_filename_component(dir "${OUT}" DIRECTORY)
file(MAKE_DIRECTORY "${dir}")
execute_process(COMMAND "${GZIP}" -9n -c "${IN}" OUTPUT_FILE "${OUT}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE "${OUT}")
  message(FATAL_ERROR "tase-gzip.cmake: ${GZIP} -9n ${IN} failed (${rc})")
endif()
