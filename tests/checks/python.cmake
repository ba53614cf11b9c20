# Issue 22: the Python package (python/, docs/PYTHON.md). python_build
# builds it into the build tree (never into the source tree: a clean clone
# stays clean) with the cffi of the interpreter below; python_pytest runs
# its pytest suite against that build, tase and tase-sim of this build.
# The interpreter is TASE_PYTHON (python/CMakeLists.txt, tests/CMakeLists.txt):
# by default Debian's /usr/bin/python3 when present (with the python3-cffi,
# python3-pytest, ... of scripts/packages.d/python.txt), else python3 on
# the PATH. Without cffi the build test fails saying so. The tools' tests
# that import the package need python_build too (tase_python_tests()).
if(NOT TARGET tase_cli OR NOT TARGET tase_sim)
  return()
endif()
add_test(NAME python_build
         COMMAND ${CMAKE_COMMAND} -E env TASE_SOURCE_DIR=${PROJECT_SOURCE_DIR} PYTHONDONTWRITEBYTECODE=1
                 ${TASE_PYTHON} ${PROJECT_SOURCE_DIR}/python/tase/_build.py --out ${TASE_PYTHON_OUT})
add_test(NAME python_pytest
         COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${TASE_PYTHON_OUT} PYTHONDONTWRITEBYTECODE=1
                 TASE_CLI=$<TARGET_FILE:tase_cli> TASE_SIM=$<TARGET_FILE:tase_sim>
                 ${TASE_PYTHON} -m pytest -q -p no:cacheprovider ${PROJECT_SOURCE_DIR}/python/tests
         WORKING_DIRECTORY ${TASE_PYTHON_OUT})
set_tests_properties(python_build PROPERTIES LABELS "check;python" TIMEOUT 300
                     FIXTURES_SETUP tase_python)
set_tests_properties(python_pytest PROPERTIES LABELS "check;e2e;python" TIMEOUT 300
                     FIXTURES_REQUIRED tase_python)
# The README's Python section: its install commands in a fresh venv
# (offline), its example against tase-sim (python/check-readme.sh).
add_test(NAME python_readme
         COMMAND ${PROJECT_SOURCE_DIR}/python/check-readme.sh $<TARGET_FILE:tase_sim> ${TASE_PYTHON})
set_tests_properties(python_readme PROPERTIES LABELS "check;python" TIMEOUT 300)
# python_pytest talks to tase-sim on the real clock (query timeouts, the
# time bound): alone, as tools_e2e, so the fuzzers cannot starve it.
set_tests_properties(python_pytest PROPERTIES RUN_SERIAL TRUE)
