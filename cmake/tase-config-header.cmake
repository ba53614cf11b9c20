# TASE_CONFIG_HEADER=<file>: the library's configuration (tase/config.h).
# The file is copied into the build tree as tase/user_config.h (and
# installed with the headers), and TASE_USER_CONFIG is defined for the
# library and for everything that links it, in this build and from the
# installed package and pkg-config files. A value-less define rather than
# a quoted file name, because a quoted -D does not survive every way a
# pkg-config or Makefile consumer passes flags through a shell.
# A parent project may set it as a plain variable before add_subdirectory()
# or FetchContent: under CMP0126's old behaviour (cmake_minimum_required
# below 3.21) a cache set() would remove that variable on the first
# configure, and the library would be built without the header.
if(NOT DEFINED TASE_CONFIG_HEADER)
  set(TASE_CONFIG_HEADER "" CACHE FILEPATH
      "Optional configuration header (see tase/config.h), built into the library and passed on to everything that links it")
endif()
set(TASE_PC_CFLAGS "")
if(TASE_CONFIG_HEADER)
  get_filename_component(_tase_cfg "${TASE_CONFIG_HEADER}" ABSOLUTE BASE_DIR ${CMAKE_BINARY_DIR})
  if(NOT EXISTS "${_tase_cfg}")
    message(FATAL_ERROR "TASE_CONFIG_HEADER: ${TASE_CONFIG_HEADER} does not exist")
  endif()
  configure_file("${_tase_cfg}" ${PROJECT_BINARY_DIR}/tase-user-config/tase/user_config.h COPYONLY)
  target_include_directories(tase PUBLIC $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/tase-user-config>)
  target_compile_definitions(tase PUBLIC TASE_USER_CONFIG)
  set(TASE_PC_CFLAGS " -DTASE_USER_CONFIG")
  message(STATUS "tase: configuration header ${_tase_cfg}")
endif()
