# Issue 13: the Debian packages libtase-dev and tase-tools, built with
# CPack, checked, unpacked and used from the unpacked tree
# (scripts/checks/packages.sh).
add_test(NAME packages COMMAND ${PROJECT_SOURCE_DIR}/scripts/checks/packages.sh ${CMAKE_BINARY_DIR}/packages)
set_tests_properties(packages PROPERTIES LABELS check TIMEOUT 600)
