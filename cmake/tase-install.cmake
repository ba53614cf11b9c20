# Install rules (TASE_INSTALL): the static libraries, the public headers
# under include/tase/, the CMake package (find_package(tase CONFIG)), one
# pkg-config file per library, the bench programs (tools/CMakeLists.txt)
# and the Debian packages built from all that (cmake/tase-cpack.cmake).
#
# Components, which become the Debian packages:
#   dev    libraries, headers, CMake package, .pc files  -> libtase-dev
#   tools  tase, tase-sim                                 -> tase-tools
include(CMakePackageConfigHelpers)

set(TASE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/tase)
get_property(TASE_LIBS GLOBAL PROPERTY TASE_LIBRARIES)

install(TARGETS ${TASE_LIBS} EXPORT tase-targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/tase
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
if(TASE_CONFIG_HEADER) # cmake/tase-config-header.cmake
  install(FILES ${PROJECT_BINARY_DIR}/tase-user-config/tase/user_config.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tase COMPONENT dev)
endif()
# Each port's headers (port/<name>/tase/*.h) go beside the core's.
foreach(lib ${TASE_LIBS})
  if(lib MATCHES "^tase_(.+)$")
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/port/${CMAKE_MATCH_1}/tase
            DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev
            FILES_MATCHING PATTERN "*.h")
  endif()
endforeach()

# CMake package: tase-config.cmake, its version file and the targets.
# While the major version is 0, a minor release may change the API (semantic
# versioning), so find_package(tase 0.2) accepts 0.2.x only; from 1.0 on,
# any 1.x.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(TASE_COMPAT SameMinorVersion)
else()
  set(TASE_COMPAT SameMajorVersion)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tase-config.cmake.in
  ${PROJECT_BINARY_DIR}/tase-config.cmake INSTALL_DESTINATION ${TASE_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/tase-config-version.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY ${TASE_COMPAT})
install(FILES ${PROJECT_BINARY_DIR}/tase-config.cmake ${PROJECT_BINARY_DIR}/tase-config-version.cmake
        DESTINATION ${TASE_CMAKE_DIR} COMPONENT dev)
install(EXPORT tase-targets NAMESPACE tase:: DESTINATION ${TASE_CMAKE_DIR} COMPONENT dev)

# pkg-config: tase.pc for the core, tase-<port>.pc (Requires: tase) for
# each port library. The prefix is written at install time, so
# `cmake --install --prefix DIR` and DESTDIR staging (CPack) both give
# correct paths.
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(TASE_PC_DEST "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
else()
  set(TASE_PC_DEST "\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig")
endif()
foreach(dir LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${dir}}")
    set(TASE_PC_${dir} "${CMAKE_INSTALL_${dir}}")
  else()
    set(TASE_PC_${dir} "\${prefix}/${CMAKE_INSTALL_${dir}}")
  endif()
endforeach()
set(TASE_PC_PREFIX "@TASE_PC_PREFIX@") # second stage, at install time
# A prefix other than /usr is written relative to the .pc file's own place
# (${pcfiledir}, which pkg-config sets), so that an installed tree moved or
# copied elsewhere still points at its own headers and libraries, not at
# the old place; /usr (the Debian packages) keeps its absolute paths, which
# pkg-config leaves out of the flags as the system's.
set(TASE_PC_UP "")
if(NOT IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  string(REGEX REPLACE "[^/]+" ".." TASE_PC_UP "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
endif()
foreach(lib ${TASE_LIBS})
  if(lib STREQUAL "tase")
    set(TASE_PC_NAME tase)
    set(TASE_PC_DESC "${PROJECT_DESCRIPTION}: the portable core")
    set(TASE_PC_REQUIRES "")
  else()
    string(REGEX REPLACE "^tase_" "" port ${lib})
    string(REPLACE "_" "-" TASE_PC_NAME "tase-${port}")
    set(TASE_PC_DESC "${PROJECT_DESCRIPTION}: the ${port} port")
    set(TASE_PC_REQUIRES "Requires: tase = ${PROJECT_VERSION}")
  endif()
  set(TASE_PC_LIB ${lib})
  set(stage ${PROJECT_BINARY_DIR}/pkgconfig/${TASE_PC_NAME}.pc.in)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/tase.pc.in ${stage} @ONLY)
  install(CODE "
    set(TASE_PC_PREFIX \"\${CMAKE_INSTALL_PREFIX}\")
    if(NOT TASE_PC_PREFIX STREQUAL \"/usr\" AND NOT \"${TASE_PC_UP}\" STREQUAL \"\")
      set(TASE_PC_PREFIX \"\\\${pcfiledir}/${TASE_PC_UP}\")
    endif()
    configure_file(\"${stage}\" \"${PROJECT_BINARY_DIR}/pkgconfig/install/${TASE_PC_NAME}.pc\" @ONLY)
    file(INSTALL DESTINATION \"${TASE_PC_DEST}\" TYPE FILE
         FILES \"${PROJECT_BINARY_DIR}/pkgconfig/install/${TASE_PC_NAME}.pc\")"
    COMPONENT dev)
endforeach()

# Debian wants each package's copyright in /usr/share/doc/<package>/.
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/libtase-dev
        RENAME copyright COMPONENT dev)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/libtase-dev
        COMPONENT dev)
# The upstream changelog under the name Debian gives it (changelog.gz:
# lintian's wrong-name-for-upstream-changelog), compressed when it is
# installed (an install after building only the library has it too); as
# CHANGELOG.md where there is no gzip.
find_program(TASE_GZIP gzip)
mark_as_advanced(TASE_GZIP)
if(TASE_GZIP)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_DATADIR}")
    set(tase_doc_dir "${CMAKE_INSTALL_DATADIR}/doc/libtase-dev")
  else()
    set(tase_doc_dir "\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/doc/libtase-dev")
  endif()
  install(CODE "
    execute_process(COMMAND \"${CMAKE_COMMAND}\" \"-DGZIP=${TASE_GZIP}\"
                            \"-DIN=${PROJECT_SOURCE_DIR}/CHANGELOG.md\"
                            \"-DOUT=${PROJECT_BINARY_DIR}/doc/changelog.gz\"
                            -P \"${CMAKE_CURRENT_LIST_DIR}/tase-gzip.cmake\" RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR \"changelog.gz: gzip failed\")
    endif()
    file(INSTALL DESTINATION \"${tase_doc_dir}\" TYPE FILE FILES \"${PROJECT_BINARY_DIR}/doc/changelog.gz\")"
          COMPONENT dev)
else()
  install(FILES ${PROJECT_SOURCE_DIR}/CHANGELOG.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/libtase-dev
          COMPONENT dev)
endif()
# The headers refer to docs/*.md (TIMING.md for the worst cases, FOOTPRINT.md
# for stack, PORTS.md, ...): they go beside the README.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/libtase-dev/docs
        COMPONENT dev FILES_MATCHING PATTERN "*.md")

# The Debian packages; only when tase is the top-level project (a parent
# that opts into TASE_INSTALL keeps its own CPack configuration).
if(TASE_IS_TOP)
  include(${CMAKE_CURRENT_LIST_DIR}/tase-cpack.cmake)
endif()
