# Shared by the scripts under scripts/ and bench/; source it, do not run it.
# shellcheck shell=bash

TASE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# tase_need LIST...: install the Debian packages named in
# scripts/packages.d/LIST.txt (one per line, # comments; NAME:ARCH for
# another architecture's package) that are missing.
# Runs apt-get update once, only when something is missing.
tase_need() {
    local list pkgs=() missing=() p
    for list in "$@"; do
        while read -r p; do
            p=${p%%#*}; p=${p//[[:space:]]/}
            [ -n "$p" ] && pkgs+=("$p")
        done < "$TASE_ROOT/scripts/packages.d/$list.txt"
    done
    for p in "${pkgs[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    echo "== installing: ${missing[*]}"
    local sudo="" arch
    [ "$(id -u)" -ne 0 ] && sudo=sudo
    export DEBIAN_FRONTEND=noninteractive
    # A package of another architecture (libcmocka-dev:s390x): Debian
    # multiarch, which the following update then indexes.
    for p in "${missing[@]}"; do
        case $p in
        *:*)
            arch=${p#*:}
            dpkg --print-foreign-architectures | grep -qx "$arch" || $sudo dpkg --add-architecture "$arch"
            ;;
        esac
    done
    $sudo apt-get -o DPkg::Lock::Timeout=600 update -qq
    $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# tase_all_lists: every package list, for the full test suite.
tase_all_lists() {
    local f
    for f in "$TASE_ROOT"/scripts/packages.d/*.txt; do
        basename "$f" .txt
    done
}

# tase_version: the library's MAJOR.MINOR.PATCH, from include/tase/version.h.
tase_version() {
    sed -n 's/^#define TASE_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\)$/\2/p' \
        "$TASE_ROOT/include/tase/version.h" | paste -sd.
}

# Progress and failure lines of the longer check scripts:
# tase_step TEXT prints TEXT with the seconds since the script started.
tase_step() { echo "== [${SECONDS} s] $*"; }
tase_fail() {
    echo "FAIL: $*"
    exit 1
}
