#!/usr/bin/env bash
# Integration check (issue 13): build small consumer projects the ways
# users take the library, from this source tree:
#   1. cmake --install, then find_package(tase <version> CONFIG) with a
#      port target, in C and in C++ (every header included, the dispatcher
#      table built as tase/dispatch.h documents for C++); an incompatible
#      version is refused; an unset build type gives Release;
#   2. the headers as C (clang -Weverything, gcc's cast warnings) and as
#      C++98..C++20 (g++, clang++ -Weverything) with warnings as errors;
#   3. add_subdirectory() and FetchContent(SOURCE_DIR) from a parent with
#      extra warning flags: no warning, no -Werror, no tests, tools or
#      install rules forced on the parent (TASE_INSTALL opts in); a parent
#      that enables C++ only; a clang parent with -Weverything;
#   4. pkg-config from the installed tree;
#   5. a CubeMX-style flat Makefile (one object folder, notdir + vpath)
#      with the application's own can.c and one TASE_CONFIG_HEADER;
#   6. Cortex-M4 through CMake and the toolchain file: the core and
#      tase::baremetal installed and used by a C and C++ firmware project
#      (the C++ handler table must land in .rodata);
#   7. the configuration and the ABI level: (a) TASE_RX_CANDIDATES has no
#      effect: an application built with 1 against a default library
#      links and runs clean under ASan with the library's sizeof(tase_rx_t)
#      (it used to overrun the stack, then to fail to link); (b) a library
#      built with -DTASE_CONFIG_HEADER passes it on to add_subdirectory,
#      find_package and pkg-config consumers, and each sees the value the
#      library applies; (c) headers of another ABI level (tase/version.h)
#      do not link against the library, naming the guarded initialiser,
#      and every initialiser the libraries export carries the level;
#   8. TASE_BUILD_TOOLS=OFF with the tests on still builds test_sim_model.
# The Debian packages are consumed by scripts/checks/packages.sh.
# Usage: scripts/checks/integration.sh [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-integration}
cons="$TASE_ROOT/tests/integration"
rm -rf "$out"
mkdir -p "$out"
jobs=2
# expect_fail LOG PATTERN DESCRIPTION -- CMD...: CMD must fail and its
# output must match PATTERN.
expect_fail() {
    local log=$1 pat=$2 what=$3
    shift 4
    if "$@" >"$log" 2>&1; then
        tase_fail "$what: succeeded, expected a failure (log $log)"
    fi
    grep -q -- "$pat" "$log" || {
        cat "$log"
        tase_fail "$what: failed, but without \"$pat\""
    }
    echo "   refused as expected: $what"
}
version=$(tase_version)
major=${version%%.*}
minor=$(echo "$version" | cut -d. -f2)
lib_flags=(-DTASE_BUILD_TESTS=OFF -DTASE_BUILD_TOOLS=OFF -DTASE_CHECKS=OFF)

# tase_all.h for the C/C++ consumers: every public header of a tree.
gen_all() {
    local inc=$1 dst=$2 h
    mkdir -p "$dst"
    for h in "$inc"/tase/*.h; do
        [ "$(basename "$h")" = user_config.h ] && continue
        echo "#include \"tase/$(basename "$h")\""
    done >"$dst/tase_all.h"
}

tase_step "1. install, then find_package(tase $major.$minor CONFIG) + tase::posix_uart, C and C++"
prefix="$out/prefix"
cmake -S "$TASE_ROOT" -B "$out/lib" -DCMAKE_INSTALL_PREFIX="$prefix" "${lib_flags[@]}" >/dev/null
grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$out/lib/CMakeCache.txt" ||
    tase_fail "no build type given: expected Release, got $(grep '^CMAKE_BUILD_TYPE:' "$out/lib/CMakeCache.txt")"
grep -q "^CMAKE_PROJECT_VERSION:STATIC=$version$" "$out/lib/CMakeCache.txt" ||
    tase_fail "CMake's project version is not tase/version.h's $version"
cmake --build "$out/lib" -j$jobs >/dev/null
cmake --install "$out/lib" >/dev/null
for f in include/tase/frame.h include/tase/config.h include/tase/version.h include/tase/posix_uart.h \
    include/tase/socketcan.h include/tase/bm_uart.h include/tase/ring.h \
    lib/libtase.a lib/libtase_posix_uart.a lib/libtase_socketcan.a lib/libtase_baremetal.a \
    lib/cmake/tase/tase-config.cmake lib/cmake/tase/tase-config-version.cmake \
    lib/pkgconfig/tase.pc lib/pkgconfig/tase-posix-uart.pc; do
    [ -f "$prefix/$f" ] || tase_fail "not installed: $f"
done
gen_all "$prefix/include" "$out/pkg/gen"
cmake -S "$cons/consumer" -B "$out/pkg" -DHOW=package -DTASE_WANT="$major.$minor" -DPORT=posix_uart \
    -DWITH_CXX=ON -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Wold-style-cast -Werror" \
    -DCMAKE_C_FLAGS="-Wall -Wextra -Wpedantic -Werror" >"$out/pkg.log"
grep -q "consumer: tase $version from $prefix/lib/cmake/tase" "$out/pkg.log" || {
    cat "$out/pkg.log"
    tase_fail "find_package did not find the installed tase $version"
}
cmake --build "$out/pkg" -j$jobs >/dev/null
pkg_line=$("$out/pkg/app")
echo "   $pkg_line"
"$out/pkg/app_cxx"
expect_fail "$out/pkg-next.log" "compatible" "find_package(tase $((major + 1)).0)" -- \
    cmake -S "$cons/consumer" -B "$out/pkg-next" -DHOW=package -DTASE_WANT="$((major + 1)).0" -DPORT=none \
    -DCMAKE_PREFIX_PATH="$prefix"

tase_step "2. every header as C (gcc, clang -Weverything) and C++98..C++20 (g++, clang++ -Weverything)"
gen_all "$TASE_ROOT/include" "$out/hdr"
for p in "$TASE_ROOT"/port/*/tase/*.h; do echo "#include \"tase/$(basename "$p")\""; done >>"$out/hdr/tase_all.h"
# every header, and the packet id constants used as a user's code uses them (g++
# -Wuseless-cast failed on user code only: TASE_ID()'s casts of literals)
{
    echo '#include "tase_all.h"'
    echo 'unsigned tase_uses(void);'
    echo 'unsigned tase_uses(void)'
    echo '{'
    echo '    unsigned n = 0u;'
    sed -n 's/^#define \(TASE_ID_[A-Z0-9_]*[A-Z0-9]\) TASE_ID[_K]*(.*/\1/p' "$TASE_ROOT/include/tase/ids.h" |
        while read -r id; do
            echo "    n += $id;"
            echo "    n += TASE_ID_GROUP($id);"
            echo "    n += TASE_ID_TYPE($id);"
        done
    # the function-like macros of flags.h and common.h as a user writes
    # them (g++ -Wuseless-cast failed on TASE_GIMBAL_FLAGS(2, 1) and
    # TASE_UART_BYTES_PER_S(57600u): casts of arguments of the type
    # already; clean from C++11 on, see ids.h)
    echo '#if !defined(__cplusplus) || __cplusplus >= 201103L'
    echo '    {'
    echo '        uint8_t flags = 0x20u;'
    echo '        uint16_t status = 0x1234u;'
    echo '        n += TASE_UART_BYTES_PER_S(57600u);'
    echo '        n += TASE_UART_BYTES_PER_S(57600);'
    echo '        n += TASE_GIMBAL_FLAGS(2, 1);'
    echo '        n += TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_POSITION, 1);'
    echo '        n += TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND(flags), 0u);'
    echo '        n += TASE_MODE_SET_VALUE(flags, 3u);'
    echo '        n += TASE_MODE_SET_VALUE(flags, 3);'
    echo '        n += TASE_MODE_VALUE(flags);'
    echo '        n += TASE_GPS_FIX(status);'
    echo '        n += TASE_GPS_ANTENNA(status);'
    echo '        n += TASE_NAV_FILTER_MODE(0xF000u);'
    echo '        n += TASE_BITS16_SET(status, 0, 2, 5u);'
    echo '        n += TASE_ID(TASE_GROUP_COMMAND, 0x10u);'
    echo '    }'
    echo '#endif'
    echo '    return n;'
    echo '}'
    echo 'int main(void) { return tase_uses() == 0u; }'
} >"$out/hdr/all.cpp"
grep -q "TASE_ID_SPOI_CMD" "$out/hdr/all.cpp" || tase_fail "no packet id constant found in ids.h"
cp "$out/hdr/all.cpp" "$out/hdr/all.c"
inc=(-I"$out/hdr" -I"$TASE_ROOT/include")
for p in "$TASE_ROOT"/port/*/; do inc+=(-I"$p"); done
gcc -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wbad-function-cast \
    -Wcast-qual -Wfloat-equal -Wundef -Wstrict-prototypes -Werror "${inc[@]}" -c "$out/hdr/all.c" -o "$out/hdr/c.o"
clang -std=c99 -Weverything -Wno-padded -Werror "${inc[@]}" -c "$out/hdr/all.c" -o "$out/hdr/c.o"
for std in c++98 c++11 c++14 c++17 c++20; do
    g++ -std=$std -Wall -Wextra -Wpedantic -Wold-style-cast -Wuseless-cast -Wshadow -Werror "${inc[@]}" \
        -c "$out/hdr/all.cpp" -o "$out/hdr/cxx.o"
    clang++ -std=$std -Weverything -Wno-padded -Werror "${inc[@]}" -c "$out/hdr/all.cpp" -o "$out/hdr/cxx.o"
done
# and as firmware's C++ sees them: arm-none-eabi-g++ with newlib, whose
# <stdint.h> defines UINT32_C() before C++11 only on request (schema.h
# used it: C++98 failed there)
gen_all "$TASE_ROOT/include" "$out/hdr-arm"
for p in "$TASE_ROOT"/port/baremetal/tase/*.h; do echo "#include \"tase/$(basename "$p")\""; done \
    >>"$out/hdr-arm/tase_all.h"
cp "$out/hdr/all.cpp" "$out/hdr-arm/all.cpp"
for std in c++98 c++11 c++20; do
    arm-none-eabi-g++ -std=$std -mcpu=cortex-m4 -mthumb -Wall -Wextra -Wpedantic -Wold-style-cast \
        -Wuseless-cast -Wshadow -Werror -I"$out/hdr-arm" -I"$TASE_ROOT/include" \
        -I"$TASE_ROOT/port/baremetal" -c "$out/hdr-arm/all.cpp" -o "$out/hdr-arm/cxx.o"
done
echo "   clean: C99 (gcc, clang), C++98, 11, 14, 17, 20 (g++, clang++), C++98, 11, 20 (arm-none-eabi-g++)"

tase_step "3. add_subdirectory and FetchContent(SOURCE_DIR) from a parent with extra warnings"
extra="-Wall -Wextra -Wfloat-equal -Wundef -Wcast-qual -Wstrict-prototypes -Wmissing-prototypes \
-Wold-style-definition -Wbad-function-cast -Wredundant-decls -Wswitch-default -Wwrite-strings \
-Wmissing-declarations -Wdouble-promotion -Wformat=2 -Wlogical-op -Wduplicated-cond"
for how in subdir fetch; do
    b="$out/$how"
    port=posix_uart
    [ $how = fetch ] && port=baremetal
    cmake -S "$cons/consumer" -B "$b" -DHOW=$how -DTASE_SRC="$TASE_ROOT" -DPORT=$port \
        -DCMAKE_C_FLAGS="$extra" -DCMAKE_INSTALL_PREFIX="$b/inst" >/dev/null
    for v in TASE_WERROR TASE_INSTALL TASE_BUILD_TESTS TASE_BUILD_TOOLS TASE_CHECKS; do
        grep -q "^$v:BOOL=OFF$" "$b/CMakeCache.txt" || tase_fail "$how: $v is not OFF under a parent"
    done
    cmake --build "$b" -j$jobs >"$b/build.log" 2>&1 || {
        cat "$b/build.log"
        tase_fail "$how: the parent's build failed"
    }
    if grep -q "warning:" "$b/build.log"; then
        grep -B2 -A4 "warning:" "$b/build.log"
        tase_fail "$how: warnings under the parent's flags"
    fi
    "$b/app"
    cmake --install "$b" >/dev/null
    if [ -e "$b/inst" ] && find "$b/inst" -name 'libtase*' -o -name 'tase-config.cmake' | grep -q .; then
        tase_fail "$how: the parent's install installed tase without TASE_INSTALL"
    fi
    echo "   $how: built warning-free with $port, nothing of tase installed"
done
# A parent that enables C++ only: tase's C99 requirement stays inside its
# own targets (a PUBLIC c_std_99 made CMake fail to generate such a parent:
# "No known features for C compiler").
for how in subdir fetch; do
    b="$out/$how-cxx"
    gen_all "$TASE_ROOT/include" "$b/gen"
    cmake -S "$cons/consumer" -B "$b" -DHOW=$how -DTASE_SRC="$TASE_ROOT" -DCXX_ONLY=ON \
        -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Wold-style-cast -Werror" >"$b.log" 2>&1 || {
        cat "$b.log"
        tase_fail "$how: a C++-only parent does not configure"
    }
    cmake --build "$b" -j$jobs >/dev/null
    "$b/app_cxx"
    echo "   $how: a parent with only C++ enabled builds and runs its C++ program"
done
# A clang parent with -Weverything (less the three README names): the
# library with each port, the hosted ring's barrier included (it was an
# implicit seq_cst atomic).
for port in posix_uart baremetal socketcan; do
    b="$out/weverything-$port"
    cmake -S "$cons/consumer" -B "$b" -DHOW=subdir -DTASE_SRC="$TASE_ROOT" -DPORT=$port \
        -DCMAKE_C_COMPILER=clang \
        -DCMAKE_C_FLAGS="-Weverything -Wno-padded -Wno-declaration-after-statement -Wno-reserved-identifier -Werror" \
        >/dev/null
    cmake --build "$b" -j$jobs >"$b/build.log" 2>&1 || {
        grep -B2 -A6 "error:" "$b/build.log" | head -40
        tase_fail "clang -Weverything parent with $port: the build failed"
    }
done
echo "   clang -Weverything parent: library and every port clean"
# A parent's own targets named as tase's tests and example are when tase is
# the top-level project: with TASE_BUILD_TESTS=ON in the parent CMake
# failed ("target test_can ... already exists"); tase's are tase_test_* now.
b="$out/subdir-tests"
cmake -S "$cons/consumer" -B "$b" -DHOW=subdir -DTASE_SRC="$TASE_ROOT" -DPORT=posix_uart \
    -DPARENT_TARGETS=ON -DTASE_BUILD_TESTS=ON >"$b.log" 2>&1 || {
    cat "$b.log"
    tase_fail "subdir with TASE_BUILD_TESTS=ON beside the parent's test_can/basic_rx: configure failed"
}
cmake --build "$b" -j$jobs --target tase_test_can >/dev/null
(cd "$b/tase/tests" && ctest -R '^can$' >/dev/null) || tase_fail "subdir with TASE_BUILD_TESTS=ON: its test 'can' failed"
echo "   subdir with TASE_BUILD_TESTS=ON: tase's tests are tase_test_*, beside the parent's test_can"
cmake -S "$cons/consumer" -B "$out/subdir" -DTASE_INSTALL=ON >/dev/null
cmake --build "$out/subdir" -j$jobs >/dev/null
cmake --install "$out/subdir" >/dev/null
[ -f "$out/subdir/inst/lib/cmake/tase/tase-config.cmake" ] || tase_fail "TASE_INSTALL=ON under a parent installed no package"
echo "   subdir: TASE_INSTALL=ON installs the package"

tase_step "4. pkg-config"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
[ "$(pkg-config --modversion tase)" = "$version" ] || tase_fail "pkg-config tase version $(pkg-config --modversion tase)"
pkg-config --exists "tase-posix-uart = $version" "tase-socketcan = $version" "tase-baremetal = $version" ||
    tase_fail "pkg-config: a port's .pc is missing or has another version"
make -s -C "$cons/pkgconfig" BUILD="$out/pc" >/dev/null
"$out/pc/app"
make -s -C "$cons/pkgconfig" BUILD="$out/pc-bm" PKGS=tase-baremetal APP_DEFS=-DAPP_BAREMETAL >/dev/null
"$out/pc-bm/app"
# An installed tree copied elsewhere points at its own files: the .pc files
# named the install prefix, so a moved SDK built against the old headers.
rm -rf "$out/moved"
cp -a "$prefix" "$out/moved"
export PKG_CONFIG_PATH="$out/moved/lib/pkgconfig"
flags=$(pkg-config --cflags --libs tase-posix-uart)
case "$flags" in
*"$prefix"*) tase_fail "a moved install's pkg-config flags name the old prefix: $flags" ;;
*"$out/moved/"*) echo "   a moved install: pkg-config points into it ($flags)" ;;
*) tase_fail "a moved install's pkg-config flags: $flags" ;;
esac
unset PKG_CONFIG_PATH

tase_step "5. flat Makefile copy (CubeMX style) with the application's own can.c"
flat="$out/flat"
cp -r "$cons/flat" "$flat"
mkdir -p "$flat/Middlewares/tase/port"
cp -r "$TASE_ROOT/include" "$TASE_ROOT/src" "$flat/Middlewares/tase/"
cp -r "$TASE_ROOT/port/baremetal" "$flat/Middlewares/tase/port/"
cp "$cons/app.c" "$flat/Core/Src/main.c"
make -s -C "$flat" >/dev/null
"$flat/build/app"
[ -f "$flat/build/tase_can.o" ] && [ -f "$flat/build/can.o" ] || tase_fail "flat build: expected can.o and tase_can.o"
# The copied core as it stands must stay clean under clang's full set.
for f in "$flat"/Middlewares/tase/src/*.c; do
    clang -std=c99 -O2 -Weverything -Wno-padded -Werror -I"$flat/Middlewares/tase/include" -c "$f" \
        -o "$flat/build/clang.o"
done
echo "   src/*.c clean under clang -Weverything -Wno-padded"

tase_step "6. Cortex-M4 through CMake and cmake/arm-none-eabi.cmake: core + tase::baremetal, C and C++"
m4="$out/prefix-m4"
cmake -S "$TASE_ROOT" -B "$out/m4-lib" -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/arm-none-eabi.cmake" \
    -DTASE_CPU=cortex-m4 -DCMAKE_INSTALL_PREFIX="$m4" >/dev/null
# tase builds Release by default; the toolchain file must keep its -Os.
flags=$(grep -h '^C_FLAGS' "$out/m4-lib/CMakeFiles/tase.dir/flags.make")
[[ $flags == *-Os* && $flags != *-O2* && $flags != *-O3* ]] || tase_fail "m4: not built with -Os alone: $flags"
cmake --build "$out/m4-lib" -j$jobs >/dev/null
cmake --install "$out/m4-lib" >/dev/null
[ -f "$m4/lib/libtase_baremetal.a" ] || tase_fail "m4: tase::baremetal not installed"
[ ! -e "$m4/lib/libtase_posix_uart.a" ] || tase_fail "m4: a POSIX port was built for bare metal"
gen_all "$m4/include" "$out/m4/gen"
# Extra flags through CFLAGS/CXXFLAGS: they add to the toolchain file's
# CPU flags (-DCMAKE_C_FLAGS would replace them).
CFLAGS="-Wall -Wextra -Werror" CXXFLAGS="-Wall -Wextra -Wold-style-cast -Werror" \
    cmake -S "$cons/consumer" -B "$out/m4" -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/arm-none-eabi.cmake" \
    -DTASE_CPU=cortex-m4 -DHOW=package -DPORT=baremetal -DWITH_CXX=ON -DCMAKE_PREFIX_PATH="$m4" >/dev/null
cmake --build "$out/m4" -j$jobs >/dev/null
arm-none-eabi-readelf -h "$out/m4/app" | grep -q 'Machine:.*ARM' || tase_fail "m4: app is not an ARM image"
sec=$(arm-none-eabi-objdump -t "$out/m4/app_cxx" | awk '/_ZL8handlers$/ {print $4}')
[ "$sec" = ".rodata" ] || tase_fail "m4: the C++ handler table is in '$sec', not .rodata"
echo "   app and app_cxx linked for Cortex-M4; the C++ handler table is in .rodata"
expect_fail "$out/m4-posix.log" "posix_uart" "find_package(tase COMPONENTS posix_uart) for bare metal" -- \
    cmake -S "$cons/consumer" -B "$out/m4-posix" -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/arm-none-eabi.cmake" \
    -DTASE_CPU=cortex-m4 -DHOW=package -DPORT=posix_uart -DCMAKE_PREFIX_PATH="$m4"

tase_step "7. the configuration header and the ABI level"
# sizeof(tase_rx_t) as a program prints it ("... sizeof(tase_rx_t) N, ...").
rx_size() { sed -n 's/.*sizeof(tase_rx_t) \([0-9]*\),.*/\1/p' <<<"$1"; }
# (a) TASE_RX_CANDIDATES=1 in the application only, the library built with
# the default: links, runs clean under ASan (tase_rx_init writes the whole
# instance), and both sides agree on sizeof(tase_rx_t) (step 1's consumer
# was built with the library's configuration).
gcc -std=c99 -g -fsanitize=address,undefined -fno-sanitize-recover=all -DTASE_RX_CANDIDATES=1 \
    -I"$prefix/include" "$cons/app.c" -L"$prefix/lib" -ltase -o "$out/cand1" >"$out/cand1.log" 2>&1 || {
    cat "$out/cand1.log"
    tase_fail "TASE_RX_CANDIDATES=1 app against the default library did not build"
}
cand1_line=$("$out/cand1" 2>&1) || {
    echo "$cand1_line"
    tase_fail "TASE_RX_CANDIDATES=1 app against the default library failed under ASan"
}
lib_size=$(rx_size "$pkg_line")
app_size=$(rx_size "$cand1_line")
[ -n "$lib_size" ] && [ "$lib_size" = "$app_size" ] ||
    tase_fail "sizeof(tase_rx_t): library's configuration '$lib_size', TASE_RX_CANDIDATES=1 app '$app_size'"
echo "   $cand1_line"
echo "   TASE_RX_CANDIDATES=1 app, default library: ran clean under ASan, sizeof(tase_rx_t) $app_size on both sides"
expect_fail "$out/cand17.log" "TASE_RX_CANDIDATES must be 1..16" "TASE_RX_CANDIDATES=17" -- \
    gcc -std=c99 -DTASE_RX_CANDIDATES=17 -I"$prefix/include" -c "$cons/app.c" -o "$out/cand17.o"

# (b) A library configured with a header: every consumer kind gets it, and
# the app checks both the value it sees and that the library applies it.
cfg="$out/cfg/tase_config.h"
mkdir -p "$out/cfg"
# (the ring's barrier hook there too, as ring.h offers: the hosted build's own
# definition replaced it with a "redefined" error under -Werror)
printf '#define TASE_PORT_WRITE_TIMEOUT_MS 250u\n#define TASE_RING_BARRIER() __sync_synchronize()\n' >"$cfg"
pcfg="$out/prefix-cfg"
cmake -S "$TASE_ROOT" -B "$out/cfg-lib" -DCMAKE_INSTALL_PREFIX="$pcfg" -DTASE_CONFIG_HEADER="$cfg" \
    -DTASE_BUILD_TESTS=ON -DTASE_BUILD_TOOLS=OFF -DTASE_CHECKS=OFF >/dev/null
cmake --build "$out/cfg-lib" -j$jobs --target tase tase_posix_uart tase_socketcan tase_baremetal >/dev/null
cmake --install "$out/cfg-lib" >/dev/null
[ -f "$pcfg/include/tase/user_config.h" ] || tase_fail "the configuration header was not installed"
cmake -S "$cons/consumer" -B "$out/cfg-pkg" -DHOW=package -DPORT=posix_uart -DEXPECT_WRITE_TIMEOUT_MS=250 \
    -DCMAKE_PREFIX_PATH="$pcfg" -DCMAKE_C_FLAGS="-fsanitize=address" >/dev/null
cmake --build "$out/cfg-pkg" -j$jobs >/dev/null
line=$("$out/cfg-pkg/app")
echo "   find_package: $line"
PKG_CONFIG_PATH="$pcfg/lib/pkgconfig" make -s -C "$cons/pkgconfig" BUILD="$out/cfg-pc" \
    APP_DEFS="-DAPP_POSIX_UART -DAPP_EXPECT_WRITE_TIMEOUT_MS=250 -fsanitize=address" >/dev/null
line=$("$out/cfg-pc/app")
echo "   pkg-config: $line"
cmake -S "$cons/consumer" -B "$out/cfg-subdir" -DHOW=subdir -DTASE_SRC="$TASE_ROOT" -DPORT=baremetal \
    -DTASE_CONFIG_HEADER="$cfg" -DEXPECT_WRITE_TIMEOUT_MS=250 >/dev/null
cmake --build "$out/cfg-subdir" -j$jobs >/dev/null
line=$("$out/cfg-subdir/app")
echo "   add_subdirectory: $line"
# A parent that sets TASE_CONFIG_HEADER as a plain variable (not -D): taken
# on the first configure, both ways in (a cache set() dropped it then, and
# only a second configure built the library with it)
for how in subdir fetch; do
    cmake -S "$cons/consumer" -B "$out/cfg-parent-$how" -DHOW=$how -DTASE_SRC="$TASE_ROOT" \
        -DPORT=baremetal -DPARENT_CONFIG_HEADER="$cfg" -DEXPECT_WRITE_TIMEOUT_MS=250 >/dev/null
    cmake --build "$out/cfg-parent-$how" -j$jobs >/dev/null
    line=$("$out/cfg-parent-$how/app") ||
        tase_fail "$how: TASE_CONFIG_HEADER set by the parent was not applied on the first configure: $line"
    echo "   $how, set(TASE_CONFIG_HEADER) in the parent, first configure: $line"
done
# Options with a range refuse a value outside it with their own message
# (TASE_PORT_WRITE_TIMEOUT_MS=0 was a -Wtype-limits error inside the
# library; TASE_GIMBAL_TELEMETRY_SHARE took 0 and 150 without a word)
expect_fail "$out/timeout0.log" "TASE_PORT_WRITE_TIMEOUT_MS must be 1" "TASE_PORT_WRITE_TIMEOUT_MS=0" -- \
    gcc -std=c99 -Wall -Wextra -Werror -DTASE_PORT_WRITE_TIMEOUT_MS=0 -I"$TASE_ROOT/include" \
    -c "$TASE_ROOT/src/tase_port_io.c" -o "$out/timeout0.o"
for share in 0 150; do
    expect_fail "$out/share$share.log" "TASE_GIMBAL_TELEMETRY_SHARE must be 1..100" \
        "TASE_GIMBAL_TELEMETRY_SHARE=$share" -- \
        gcc -std=c99 -DTASE_GIMBAL_TELEMETRY_SHARE=$share -I"$TASE_ROOT/include" \
        -c "$TASE_ROOT/src/tase_gimbal.c" -o "$out/share$share.o"
done
# The app's check is not vacuous: built without the installed header (no
# TASE_USER_CONFIG) it sees 100 ms while the library applies 250.
expect_fail "$out/cfg-none.log" "^FAIL" "an app without the library's configuration header" -- \
    bash -c "gcc -std=c99 -I'$pcfg/include' '$cons/app.c' -L'$pcfg/lib' -ltase -o '$out/cfg-none' && '$out/cfg-none'"

# (c) Headers of another ABI level (a copy of the installed ones with
# TASE_ABI_LEVEL changed, standing in for another release's headers, such
# as a stale /usr/local/include) against the library: no link.
level=$(sed -n 's/^#define TASE_ABI_LEVEL \([0-9][0-9]*\)$/\1/p' "$prefix/include/tase/version.h")
[ -n "$level" ] || tase_fail "tase/version.h: no TASE_ABI_LEVEL"
next=$((level + 1))
mkdir -p "$out/abi-next"
cp -r "$prefix/include" "$out/abi-next/"
sed -i "s/^#define TASE_ABI_LEVEL $level\$/#define TASE_ABI_LEVEL $next/" "$out/abi-next/include/tase/version.h"
grep -q "^#define TASE_ABI_LEVEL $next\$" "$out/abi-next/include/tase/version.h" ||
    tase_fail "could not make headers of ABI level $next"
expect_fail "$out/abi-next.log" "tase_rx_init_abi$next" "headers of ABI level $next, library of level $level" -- \
    gcc -std=c99 -I"$out/abi-next/include" "$cons/app.c" -L"$prefix/lib" -ltase -o "$out/abi-next/app"
# Every guarded initialiser (tase/config.h's list) is defined with the
# level and never under its plain name (0.1.0's headers reference plain
# names), and no initialiser the libraries export escapes the list.
mapfile -t guarded < <(sed -n 's/^#define \(tase_[a-z0-9_]*\) TASE_CONFIG_LINK_NAME(.*/\1/p' \
    "$prefix/include/tase/config.h")
[ "${#guarded[@]}" -gt 0 ] || tase_fail "tase/config.h: no guarded function found"
defined=$(nm -g --defined-only "$prefix"/lib/libtase*.a 2>/dev/null | awk '$2 == "T" {print $3}' | sort -u)
for g in "${guarded[@]}"; do
    grep -qx "${g}_abi$level" <<<"$defined" || tase_fail "$g: no ${g}_abi$level in the installed libraries"
    ! grep -qx "$g" <<<"$defined" || tase_fail "$g: defined under its plain name"
done
unguarded=$(grep -E '^tase_[a-z0-9_]*_(init|open|open_flags|attach|adopt)$' <<<"$defined" || true)
[ -z "$unguarded" ] || tase_fail "initialisers without the ABI level (add them to tase/config.h): $unguarded"
echo "   ${#guarded[@]} initialisers link as <name>_abi$level; headers of level $next do not link"

tase_step "8. TASE_BUILD_TOOLS=OFF with the tests on: test_sim_model links and passes"
cmake --build "$out/cfg-lib" -j$jobs --target test_sim_model >/dev/null
"$out/cfg-lib/tests/test_sim_model" >/dev/null

tase_step "integration: every consumer built and ran"
