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
#      install rules forced on the parent (TASE_INSTALL opts in);
#   4. pkg-config from the installed tree;
#   5. a CubeMX-style flat Makefile (one object folder, notdir + vpath)
#      with the application's own can.c and one TASE_CONFIG_HEADER;
#   6. Cortex-M4 through CMake and the toolchain file: the core and
#      tase::baremetal installed and used by a C and C++ firmware project
#      (the C++ handler table must land in .rodata);
#   7. the configuration header: a library built with
#      -DTASE_CONFIG_HEADER passes it on to find_package and pkg-config
#      consumers, and an application built with another TASE_RX_CANDIDATES
#      than its library fails to link (it used to overrun the stack);
#   8. TASE_BUILD_TOOLS=OFF with the tests on still builds test_sim_model.
# The Debian packages are consumed by scripts/check-packages.sh.
# Usage: scripts/check-integration.sh [outdir]
set -euo pipefail
. "$(dirname "$0")/lib.sh"
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
"$out/pkg/app"
"$out/pkg/app_cxx"
expect_fail "$out/pkg-next.log" "compatible" "find_package(tase $((major + 1)).0)" -- \
    cmake -S "$cons/consumer" -B "$out/pkg-next" -DHOW=package -DTASE_WANT="$((major + 1)).0" -DPORT=none \
    -DCMAKE_PREFIX_PATH="$prefix"

tase_step "2. every header as C (gcc, clang -Weverything) and C++98..C++20 (g++, clang++ -Weverything)"
gen_all "$TASE_ROOT/include" "$out/hdr"
for p in "$TASE_ROOT"/port/*/tase/*.h; do echo "#include \"tase/$(basename "$p")\""; done >>"$out/hdr/tase_all.h"
printf '#include "tase_all.h"\nint main(void) { return 0; }\n' >"$out/hdr/all.c"
cp "$out/hdr/all.c" "$out/hdr/all.cpp"
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
echo "   clean: C99 (gcc, clang), C++98, 11, 14, 17, 20 (g++, clang++)"

tase_step "3. add_subdirectory and FetchContent(SOURCE_DIR) from a parent with extra warnings"
extra="-Wall -Wextra -Wfloat-equal -Wundef -Wcast-qual -Wstrict-prototypes -Wmissing-prototypes \
-Wold-style-definition -Wbad-function-cast -Wredundant-decls -Wswitch-default -Wwrite-strings \
-Wmissing-declarations -Wdouble-promotion -Wformat=2"
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

tase_step "7. one configuration header; a mismatched configuration does not link"
# An application built with TASE_RX_CANDIDATES 1 against the default
# library: its tase_rx_t is smaller than the one tase_rx_init() writes.
expect_fail "$out/mismatch.log" "tase_rx_init_rx_candidates_1" "TASE_RX_CANDIDATES=1 app, default library" -- \
    gcc -std=c99 -fsanitize=address -DTASE_RX_CANDIDATES=1 -I"$prefix/include" "$cons/app.c" \
    -L"$prefix/lib" -ltase -o "$out/mismatch"
cfg="$out/cfg/tase_config.h"
mkdir -p "$out/cfg"
printf '#define TASE_RX_CANDIDATES 2\n' >"$cfg"
pcfg="$out/prefix-cfg"
cmake -S "$TASE_ROOT" -B "$out/cfg-lib" -DCMAKE_INSTALL_PREFIX="$pcfg" -DTASE_CONFIG_HEADER="$cfg" \
    -DTASE_BUILD_TESTS=ON -DTASE_BUILD_TOOLS=OFF -DTASE_CHECKS=OFF >/dev/null
cmake --build "$out/cfg-lib" -j$jobs --target tase tase_posix_uart tase_socketcan tase_baremetal >/dev/null
cmake --install "$out/cfg-lib" >/dev/null
[ -f "$pcfg/include/tase/user_config.h" ] || tase_fail "the configuration header was not installed"
cmake -S "$cons/consumer" -B "$out/cfg-pkg" -DHOW=package -DPORT=posix_uart -DEXPECT_CANDIDATES=2 \
    -DCMAKE_PREFIX_PATH="$pcfg" -DCMAKE_C_FLAGS="-fsanitize=address" >/dev/null
cmake --build "$out/cfg-pkg" -j$jobs >/dev/null
"$out/cfg-pkg/app"
PKG_CONFIG_PATH="$pcfg/lib/pkgconfig" make -s -C "$cons/pkgconfig" BUILD="$out/cfg-pc" \
    APP_DEFS="-DAPP_POSIX_UART -DAPP_EXPECT_CANDIDATES=2 -fsanitize=address" >/dev/null
"$out/cfg-pc/app"
expect_fail "$out/mismatch2.log" "tase_rx_init_rx_candidates_4" "default app, library configured for 2" -- \
    gcc -std=c99 -I"$pcfg/include" "$cons/app.c" -L"$pcfg/lib" -ltase -o "$out/mismatch2"

tase_step "8. TASE_BUILD_TOOLS=OFF with the tests on: test_sim_model links and passes"
cmake --build "$out/cfg-lib" -j$jobs --target test_sim_model >/dev/null
"$out/cfg-lib/tests/test_sim_model" >/dev/null

tase_step "integration: every consumer built and ran"
