# CMake toolchain file: Linux on IBM Z (s390x, big-endian) with Debian's
# cross compiler, programs run under qemu-user. Used by
# scripts/checks/s390x.sh to run the unit tests on a big-endian CPU:
#
#   cmake -S . -B build-s390x -DCMAKE_TOOLCHAIN_FILE=cmake/s390x-linux-gnu.cmake \
#         -DTASE_BUILD_TESTS=ON && cmake --build build-s390x && ctest --test-dir build-s390x -L unit
#
# ctest runs each test through CMAKE_CROSSCOMPILING_EMULATOR, qemu-s390x.
# Programs are linked against the cross C library (libc6-dev-s390x-cross)
# and run on Debian's multiarch s390x runtime (libc6:s390x, installed with
# libcmocka-dev:s390x): its loader is /lib/ld64.so.1 and it finds
# /usr/lib/s390x-linux-gnu by itself. (Mixing the cross loader, -L
# /usr/s390x-linux-gnu, with the multiarch cmocka aborts every program.)
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR s390x)
set(CMAKE_C_COMPILER s390x-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER s390x-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE s390x-linux-gnu)
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-s390x)

set(CMAKE_FIND_ROOT_PATH /usr/s390x-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
