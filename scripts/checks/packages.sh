#!/usr/bin/env bash
# Debian packages (issue 13): build libtase-dev and tase-tools with CPack
# from a /usr build, check their control fields and contents, unpack them
# into a scratch root and use them from there as a user of the installed
# packages would: a CMake project with find_package(tase CONFIG) and
# tase::socketcan, a pkg-config Makefile build (PKG_CONFIG_SYSROOT_DIR),
# and the programs, whose --version must be the library's version.
# Usage: scripts/checks/packages.sh [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-packages}
cons="$TASE_ROOT/tests/integration"
rm -rf "$out"
mkdir -p "$out"
version=$(tase_version)
arch=$(dpkg --print-architecture)
triplet=$(gcc -print-multiarch)

tase_step "build with -DCMAKE_INSTALL_PREFIX=/usr and run cpack -G DEB"
cmake -S "$TASE_ROOT" -B "$out/build" -DCMAKE_INSTALL_PREFIX=/usr -DTASE_BUILD_TESTS=OFF \
    -DTASE_CHECKS=OFF >/dev/null
cmake --build "$out/build" -j2 >/dev/null
(cd "$out/build" && cpack -G DEB >"$out/cpack.log" 2>&1) || {
    cat "$out/cpack.log"
    tase_fail "cpack"
}
dev="$out/build/packages/libtase-dev_${version}-1_${arch}.deb"
tools="$out/build/packages/tase-tools_${version}-1_${arch}.deb"
for deb in "$dev" "$tools"; do
    [ -f "$deb" ] || {
        ls "$out/build/packages"
        tase_fail "no $(basename "$deb")"
    }
done

tase_step "control fields and contents"
# field DEB NAME EXPECTED-REGEX
field() {
    local v
    v=$(dpkg-deb -f "$1" "$2")
    [[ $v =~ $3 ]] || tase_fail "$(basename "$1"): $2 is '$v', expected /$3/"
}
field "$dev" Package '^libtase-dev$'
field "$tools" Package '^tase-tools$'
for deb in "$dev" "$tools"; do
    field "$deb" Version "^${version}-1$"
    field "$deb" Architecture "^${arch}$"
    field "$deb" Maintainer '.+'
    field "$deb" Description '.+'
done
field "$dev" Section '^libdevel$'
field "$dev" Description '^TASE gimbal protocol stack: static libraries and headers'
field "$tools" Description '^TASE gimbal bench tools'
field "$tools" Depends 'libc6'
dpkg-deb -c "$dev" | awk '{print $6}' | sed 's|^\./||' >"$out/dev.list"
dpkg-deb -c "$tools" | awk '{print $6}' | sed 's|^\./||' >"$out/tools.list"
for f in usr/include/tase/frame.h usr/include/tase/config.h usr/include/tase/version.h \
    usr/include/tase/posix_uart.h usr/include/tase/socketcan.h usr/include/tase/bm_uart.h \
    usr/include/tase/ring.h "usr/lib/$triplet/libtase.a" "usr/lib/$triplet/libtase_posix_uart.a" \
    "usr/lib/$triplet/libtase_socketcan.a" "usr/lib/$triplet/libtase_baremetal.a" \
    "usr/lib/$triplet/cmake/tase/tase-config.cmake" "usr/lib/$triplet/cmake/tase/tase-config-version.cmake" \
    "usr/lib/$triplet/cmake/tase/tase-targets.cmake" "usr/lib/$triplet/pkgconfig/tase.pc" \
    "usr/lib/$triplet/pkgconfig/tase-socketcan.pc" usr/share/doc/libtase-dev/copyright \
    usr/share/doc/libtase-dev/changelog.gz usr/share/doc/libtase-dev/changelog.Debian.gz \
    usr/share/doc/libtase-dev/docs/TIMING.md \
    usr/share/doc/libtase-dev/docs/PORTS.md; do
    grep -qx "$f" "$out/dev.list" || tase_fail "libtase-dev lacks /$f"
done
for f in usr/bin/tase usr/bin/tase-sim usr/share/doc/tase-tools/copyright \
    usr/share/doc/tase-tools/changelog.Debian.gz usr/share/doc/tase-tools/TOOLS.md \
    usr/share/doc/tase-tools/CAN.md usr/share/doc/tase-tools/PROTOCOL-NOTES.md \
    usr/share/man/man1/tase.1.gz usr/share/man/man1/tase-sim.1.gz usr/share/tase/tase.lua; do
    grep -qx "$f" "$out/tools.list" || tase_fail "tase-tools lacks /$f"
done
if grep -q '^usr/bin/' "$out/dev.list" || grep -q '^usr/include/' "$out/tools.list"; then
    tase_fail "a file is in the wrong package"
fi
echo "   libtase-dev: $(grep -c '[^/]$' "$out/dev.list") files; tase-tools: $(grep -c '[^/]$' "$out/tools.list") files"

grep -q "^## \[$version\]" "$TASE_ROOT/CHANGELOG.md" || tase_fail "CHANGELOG.md has no section for $version"
[ "$(dpkg-deb --fsys-tarfile "$dev" | tar -xOf - ./usr/share/doc/libtase-dev/changelog.gz | gzip -dc)" = \
    "$(cat "$TASE_ROOT/CHANGELOG.md")" ] || tase_fail "libtase-dev: changelog.gz is not CHANGELOG.md"

tase_step "unpack both and build consumers from the unpacked tree"
root="$out/root"
dpkg-deb -x "$dev" "$root"
dpkg-deb -x "$tools" "$root"
# CMake: find_package searches <prefix>/lib/<triplet>/cmake as on an
# installed system.
cmake -S "$cons/consumer" -B "$out/cmake" -DHOW=package -DTASE_WANT="$version" -DPORT=socketcan \
    -DCMAKE_PREFIX_PATH="$root/usr" >"$out/cmake.log"
grep -q "consumer: tase $version from $root/usr/lib/$triplet/cmake/tase" "$out/cmake.log" || {
    cat "$out/cmake.log"
    tase_fail "find_package did not take the unpacked package"
}
cmake --build "$out/cmake" -j2 >/dev/null
"$out/cmake/app"
# pkg-config: the .pc files say /usr; the sysroot points it at the tree.
PKG_CONFIG_SYSROOT_DIR="$root" PKG_CONFIG_LIBDIR="$root/usr/lib/$triplet/pkgconfig" \
    make -s -C "$cons/pkgconfig" BUILD="$out/pc" >/dev/null
"$out/pc/app"

tase_step "the programs"
for p in tase tase-sim; do
    "$root/usr/bin/$p" --help >/dev/null 2>&1 || tase_fail "$p --help"
    if v=$("$root/usr/bin/$p" --version 2>/dev/null); then
        [[ $v == *"$version"* ]] || tase_fail "$p --version says '$v', the library is $version"
        echo "   $p --version: $v"
    elif grep -rq --include='*.c' -- '"--version"' "$TASE_ROOT/tools/"; then
        tase_fail "$p --version failed"
    else
        echo "   $p: no --version option in tools/ yet (issue 15); --help runs"
    fi
done
# The manual page has a section for every command `tase --help` lists
# (gyro-zero had none: its hyphen, roff's \-, did not match the name).
cmds=$("$root/usr/bin/tase" --help | sed -n '/^commands:$/,/^[^ ]/s/^  \([a-z][-a-z]*\) .*/\1/p')
[ "$(wc -w <<<"$cmds")" -ge 10 ] || tase_fail "tase --help lists no commands: '$cmds'"
gzip -dc "$root/usr/share/man/man1/tase.1.gz" | sed -n 's/^\.SS //p' | sed 's/\\-/-/g' >"$out/man.ss"
[ "$(tr ' ' '\n' <<<"$cmds" | grep .)" = "$(cat "$out/man.ss")" ] ||
    tase_fail "tase.1's sections ($(tr '\n' ' ' <"$out/man.ss")) are not tase --help's commands ($(tr '\n' ' ' <<<"$cmds"))"
echo "   tase.1: a section for each of the $(wc -w <<<"$cmds") commands of tase --help"
tase_step "python3-tase (issue 22): fields, contents, import from the unpacked tree"
py="$out/build/packages/python3-tase_${version}-1_${arch}.deb"
[ -f "$py" ] || tase_fail "no $(basename "$py") (python3-cffi, python3-dev installed?)"
field "$py" Package '^python3-tase$'
field "$py" Version "^${version}-1$"
field "$py" Depends 'python3 \(>= 3\.[0-9]+\), python3 \(<< 3\.[0-9]+\), python3-cffi-backend'
dpkg-deb -x "$py" "$root"
v=$(cd / && PYTHONPATH="$root/usr/lib/python3/dist-packages" /usr/bin/python3 -c \
    'import tase; print(tase.__version__, tase.__file__)')
[[ $v == "$version $root/usr/lib/python3/dist-packages/tase/__init__.py" ]] ||
    tase_fail "python3-tase: import tase gave '$v'"
echo "   python3-tase: import tase: $v"
# Another prefix: where that python3 looks (/usr/local/lib/python3.X/
# dist-packages); it went to PREFIX/lib/python3/dist-packages, which python3
# searches only under /usr.
rm -rf "$out/stage"
DESTDIR="$out/stage" cmake --install "$out/build" --prefix /usr/local --component python >/dev/null
pyv=$(/usr/bin/python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')
site="/usr/local/lib/python$pyv/dist-packages"
[ -f "$out/stage$site/tase/__init__.py" ] ||
    tase_fail "prefix /usr/local: the Python package is not in $site ($(cd "$out/stage" && find . -name __init__.py))"
/usr/bin/python3 -c "import sys; sys.exit(0 if '$site' in sys.path else 1)" ||
    tase_fail "$site is not on /usr/bin/python3's path"
echo "   prefix /usr/local: the Python package goes to $site, on python3's path"

# Debian's own package check: no error or warning (a review found unstripped
# programs, no changelog.Debian.gz, no manual pages, CHANGELOG.md misnamed).
# initial-upload-closes-no-bugs is the Debian archive's rule for a first
# upload (it closes an ITP bug); these packages are not uploaded there.
tase_step "lintian"
if ! lintian --fail-on error,warning --tag-display-limit 0 \
    --suppress-tags initial-upload-closes-no-bugs "$dev" "$tools" "$py" \
    >"$out/lintian.log" 2>&1; then
    grep -v "root privileges" "$out/lintian.log"
    tase_fail "lintian"
fi
{ grep -v "root privileges" "$out/lintian.log" || echo "no tag"; } | sed 's/^/   /'
tase_step "packages: built, checked, unpacked and used"
