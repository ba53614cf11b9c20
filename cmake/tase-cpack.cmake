# Debian packages (cpack -G DEB in a build configured with
# -DCMAKE_INSTALL_PREFIX=/usr, so that the libraries land in Debian's
# multiarch directory, /usr/lib/<triplet>):
#   libtase-dev  the install component "dev": static libraries, headers,
#                CMake package, pkg-config files
#   tase-tools   the component "tools": tase, tase-sim and their manual
#   python3-tase the component "python": the Python package (python/)
# scripts/checks/packages.sh builds both, unpacks them and builds consumer
# programs from the unpacked tree.
set(CPACK_PACKAGE_NAME tase)
set(CPACK_PACKAGE_VENDOR "The tase-gimbal-stack authors")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
# Maintainer field; a distributor building its own packages sets its own.
set(CPACK_PACKAGE_CONTACT "The tase-gimbal-stack authors <maintainers@users.noreply.h-seed-eca75558.example>" CACHE STRING "Debian Maintainer field")
# Each package's description below starts with its own synopsis line; an
# empty package-wide summary keeps CPack from putting a shared one above.
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGE_DIRECTORY ${PROJECT_BINARY_DIR}/packages)
set(CPACK_GENERATOR DEB)

set(CPACK_COMPONENTS_ALL dev)
if(TARGET tase_cli)
  list(APPEND CPACK_COMPONENTS_ALL tools)
endif()
if(TARGET tase_python)
  list(APPEND CPACK_COMPONENTS_ALL python)
endif()
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT) # <name>_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)

set(CPACK_DEBIAN_DEV_PACKAGE_NAME libtase-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_DESCRIPTION
"TASE gimbal protocol stack: static libraries and headers
C99 library for the Cloud Cap TASE gimbal's serial and CAN protocol:
framing, every packet's encoder and decoder, dispatch, CAN, KLV, the host
and gimbal roles. No heap, no globals. Static libraries for the core
(tase) and the ports (posix_uart, socketcan, baremetal), headers under
/usr/include/tase, the CMake package (find_package(tase)) and pkg-config
files (tase, tase-posix-uart, tase-socketcan, tase-baremetal).")

set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME tase-tools)
set(CPACK_DEBIAN_TOOLS_PACKAGE_SECTION electronics)
set(CPACK_DEBIAN_TOOLS_PACKAGE_SHLIBDEPS ON) # Depends: libc6 (>= ...)
set(CPACK_DEBIAN_TOOLS_DESCRIPTION
"TASE gimbal bench tools: tase and tase-sim
tase talks to a Cloud Cap TASE gimbal over a serial port or SocketCAN:
monitor telemetry, send commands, run queries, decode captures to JSON.
tase-sim is a simulated gimbal on a pseudo-terminal or CAN interface.
The Wireshark dissector is /usr/share/tase/tase.lua (wireshark -X
lua_script:/usr/share/tase/tase.lua); the manual is
/usr/share/doc/tase-tools/TOOLS.md.")

# The Python package: its extension is built for the Python of the build
# (TASE_PYTHON_VERSION, Debian 12: 3.11).
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-tase)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS
    "python3 (>= ${TASE_PYTHON_VERSION}), python3 (<< ${TASE_PYTHON_NEXT}), python3-cffi-backend")
set(CPACK_DEBIAN_PYTHON_PACKAGE_RECOMMENDS "python3-serial, python3-can, python3-matplotlib, tase-tools")
set(CPACK_DEBIAN_PYTHON_DESCRIPTION
"TASE gimbal protocol stack: Python 3 package
The tase package drives a Cloud Cap TASE gimbal from Python over the same
C code the firmware links: packets from the library's schema, encode and
decode, serial, SocketCAN and virtual CAN links with queries and retries,
the simulator, captures of tase record and plots (docs/PYTHON.md).")

# Programs and the Python extension stripped (lintian:
# unstripped-binary-or-object); CMake never strips the static libraries,
# whose symbol tables are their contents.
set(CPACK_STRIP_FILES ON)

# Debian's changelog.Debian.gz in each package's doc directory (lintian:
# no-changelog): one entry for this version, naming the upstream changelog.
# Compressed with gzip -9n as Debian's own tools do; without gzip there is
# none (a package is still built).
# Only for a build for /usr, the packages' prefix: another install has no
# Debian package to describe.
if(TASE_GZIP AND CMAKE_INSTALL_PREFIX STREQUAL "/usr") # gzip found by tase-install.cmake
  string(TIMESTAMP tase_deb_date "%a, %d %b %Y %H:%M:%S +0000" UTC) # SOURCE_DATE_EPOCH if set
  foreach(tase_comp IN LISTS CPACK_COMPONENTS_ALL)
    string(TOUPPER ${tase_comp} tase_COMP)
    set(tase_pkg ${CPACK_DEBIAN_${tase_COMP}_PACKAGE_NAME})
    set(tase_cl ${PROJECT_BINARY_DIR}/debian/${tase_pkg}/changelog.Debian)
    file(WRITE ${tase_cl}
"${tase_pkg} (${PROJECT_VERSION}-${CPACK_DEBIAN_PACKAGE_RELEASE}) unstable; urgency=medium

  * Built with CPack from the tase-gimbal-stack source, version
    ${PROJECT_VERSION}. The changes are in the upstream changelog,
    /usr/share/doc/libtase-dev/changelog.gz.

 -- ${CPACK_PACKAGE_CONTACT}  ${tase_deb_date}
")
    execute_process(COMMAND ${CMAKE_COMMAND} -DGZIP=${TASE_GZIP} -DIN=${tase_cl} -DOUT=${tase_cl}.gz
                            -P ${CMAKE_CURRENT_LIST_DIR}/tase-gzip.cmake)
    install(FILES ${tase_cl}.gz DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${tase_pkg}
            COMPONENT ${tase_comp})
  endforeach()
endif()

include(CPack)
