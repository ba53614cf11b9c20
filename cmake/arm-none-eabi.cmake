# CMake toolchain file for bare-metal Cortex-M builds with arm-none-eabi-gcc.
#
#   cmake -S . -B build-m4 -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
#         -DTASE_CPU=cortex-m4 && cmake --build build-m4
#
# TASE_CPU: cortex-m0plus, cortex-m3, cortex-m4 (default) or cortex-m7.
# TASE_FLOAT_ABI: soft, softfp or hard. Defaults to hard on the CPUs with an
# FPU (M4: fpv4-sp-d16, M7: fpv5-d16) and soft elsewhere. The core uses no
# floating point, so this only has to match the firmware it is linked into.
#
# Every object is built with -Os -ffunction-sections -fdata-sections so the
# linker's --gc-sections drops what a firmware does not call. Because
# CMAKE_CROSSCOMPILING is set, the top-level CMakeLists.txt builds the core
# library and the bare-metal port (tase::baremetal) only: no POSIX ports,
# tools, tests or checks. C++ firmware gets arm-none-eabi-g++ with the same
# CPU flags (plus -fno-exceptions -fno-rtti).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(TASE_CPU "cortex-m4" CACHE STRING "Cortex-M CPU: cortex-m0plus, cortex-m3, cortex-m4, cortex-m7")
set_property(CACHE TASE_CPU PROPERTY STRINGS cortex-m0plus cortex-m3 cortex-m4 cortex-m7)

if(TASE_CPU STREQUAL "cortex-m4")
  set(_tase_fpu "-mfpu=fpv4-sp-d16")
  set(_tase_abi_default hard)
elseif(TASE_CPU STREQUAL "cortex-m7")
  set(_tase_fpu "-mfpu=fpv5-d16")
  set(_tase_abi_default hard)
elseif(TASE_CPU STREQUAL "cortex-m0plus" OR TASE_CPU STREQUAL "cortex-m3")
  set(_tase_fpu "")
  set(_tase_abi_default soft)
else()
  message(FATAL_ERROR "TASE_CPU=${TASE_CPU}: use cortex-m0plus, cortex-m3, cortex-m4 or cortex-m7")
endif()
set(TASE_FLOAT_ABI "${_tase_abi_default}" CACHE STRING "Float ABI: soft, softfp or hard")
if(TASE_FLOAT_ABI STREQUAL "soft")
  set(_tase_fpu "")
endif()

# try_compile() runs this file again in a fresh project: pass the choices on.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES TASE_CPU TASE_FLOAT_ABI)
# Nothing can be linked without a board's startup code and linker script.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++) # for C++ firmware projects
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_AR arm-none-eabi-ar CACHE FILEPATH "")
set(CMAKE_RANLIB arm-none-eabi-ranlib CACHE FILEPATH "")
set(CMAKE_SIZE arm-none-eabi-size CACHE FILEPATH "")

set(CMAKE_C_FLAGS_INIT
    "-mcpu=${TASE_CPU} -mthumb -mfloat-abi=${TASE_FLOAT_ABI} ${_tase_fpu} -Os -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${CMAKE_C_FLAGS_INIT} -fno-exceptions -fno-rtti")
set(CMAKE_ASM_FLAGS_INIT "-mcpu=${TASE_CPU} -mthumb -mfloat-abi=${TASE_FLOAT_ABI} ${_tase_fpu}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,--gc-sections")
# Keep -Os whatever build type is chosen (tase builds Release by default).
# CMake appends its own -O3 / -O2 to the *_INIT values of the build types,
# so the per-type flags are set as cache entries here, before it does; a
# value given with -D on the command line still wins.
foreach(lang C CXX)
  set(CMAKE_${lang}_FLAGS_RELEASE "-DNDEBUG" CACHE STRING "")
  set(CMAKE_${lang}_FLAGS_MINSIZEREL "-DNDEBUG" CACHE STRING "")
  set(CMAKE_${lang}_FLAGS_RELWITHDEBINFO "-g -DNDEBUG" CACHE STRING "")
endforeach()

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
