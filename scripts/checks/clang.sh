#!/usr/bin/env bash
# Build the whole project with clang (same warnings, -Werror) and run the
# unit tests built that way.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-clang}
cmake -S "$TASE_ROOT" -B "$out" -DCMAKE_C_COMPILER=clang -DTASE_CHECKS=OFF -DCMAKE_BUILD_TYPE=Debug >/dev/null
cmake --build "$out" -j"$(nproc)"
cd "$out" && ctest --output-on-failure -L unit
