#!/usr/bin/env bash
# The whole test suite: installs what it needs, builds with gcc, runs every
# ctest test (unit tests and the whole-project checks they register).
# Usage: scripts/test.sh [extra ctest arguments, e.g. -L unit or -R frame]
set -euo pipefail
. "$(dirname "$0")/lib.sh"
# shellcheck disable=SC2046
tase_need $(tase_all_lists)
build="$TASE_ROOT/build"
cmake -S "$TASE_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=gcc >/dev/null
cmake --build "$build" -j"$(nproc)"
cd "$build"
ctest --output-on-failure -j"$(nproc)" "$@"
