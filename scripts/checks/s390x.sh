#!/usr/bin/env bash
# The unit tests on a big-endian CPU: the whole tree (core, ports, the
# simulator's model, every tests/test_*.c and the fuzz corpus replays)
# cross-built for s390x with Debian's cross compiler and the project's
# warnings as errors, then run by ctest under qemu-user
# (cmake/s390x-linux-gnu.cmake). The protocol is big-endian, so this runs
# every encoder and decoder where the host's byte order is the wire's.
# cmocka for s390x comes from Debian multiarch (libcmocka-dev:s390x,
# scripts/packages.d/s390x.txt).
# Usage: scripts/checks/s390x.sh [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-s390x}
rm -rf "$out"
mkdir -p "$out/cmocka-include"
# cmocka.h is architecture-independent and lives in /usr/include; copy it
# so that the cross build never puts the host's /usr/include on its path.
cp /usr/include/cmocka.h "$out/cmocka-include/"
lib=/usr/lib/s390x-linux-gnu/libcmocka.so
[ -e "$lib" ] || tase_fail "$lib missing (libcmocka-dev:s390x)"
tase_step "configure and build for s390x"
cmake -S "$TASE_ROOT" -B "$out/build" -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/s390x-linux-gnu.cmake" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTASE_BUILD_TESTS=ON -DTASE_BUILD_TOOLS=OFF -DTASE_CHECKS=OFF \
    -DTASE_WERROR=ON -DCMOCKA_INCLUDE_DIR="$out/cmocka-include" -DCMOCKA_LIBRARY="$lib" >/dev/null
cmake --build "$out/build" -j2 >/dev/null
readelf -h "$out/build/tests/test_codec" | grep -q 'big endian' || tase_fail "test_codec is not a big-endian binary"
readelf -h "$out/build/tests/test_codec" | grep -q 'IBM S/390' || tase_fail "test_codec is not an s390x binary"
tase_step "run the unit tests under qemu-s390x"
# Two assertions need what qemu-user does not emulate (TIOCGEXCL, kernel
# receive timestamps); the tests skip them, saying so, when told they run
# under an emulator. Everything else runs as on the host.
(cd "$out/build" && TASE_TEST_EMULATOR=qemu-user ctest --output-on-failure -L unit -j2)
tase_step "s390x: every unit test passed on a big-endian CPU"
