#!/usr/bin/env bash
# The project's main job: build and run the bench session.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
tase_need base
build="$TASE_ROOT/build"
cmake -S "$TASE_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"$(nproc)" --target basic_rx >/dev/null
"$build/examples/basic_rx"
