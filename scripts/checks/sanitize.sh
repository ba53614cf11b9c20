#!/usr/bin/env bash
# The whole unit-test suite built with AddressSanitizer (+ LeakSanitizer)
# and UndefinedBehaviorSanitizer, no recovery (the first report fails the
# test), in a separate build directory; then every committed fuzz corpus
# replayed under the same sanitizers.
# Usage: scripts/checks/sanitize.sh [OUTDIR] (default build-sanitize)
#   TASE_SAN_CC=gcc to use gcc instead of clang.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-sanitize}
cc=${TASE_SAN_CC:-clang}
san="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -S "$TASE_ROOT" -B "$out" -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Debug \
    -DTASE_CHECKS=OFF -DCMAKE_C_FLAGS="$san" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$out" -j2
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
(cd "$out" && ctest --output-on-failure -L unit)
for dir in "$TASE_ROOT"/fuzz/corpus/*/; do
    h=$(basename "$dir")
    [ -f "$TASE_ROOT/fuzz/$h.c" ] || continue
    # shellcheck disable=SC2086
    "$cc" -std=c99 -g -O1 $san -I"$TASE_ROOT/include" "$TASE_ROOT"/src/*.c \
        "$TASE_ROOT/fuzz/$h.c" "$TASE_ROOT/fuzz/replay_main.c" -o "$out/replay_$h"
    printf 'corpus %s: ' "$h"
    "$out/replay_$h" "$dir"
done
echo "sanitizers: unit tests and fuzz corpora clean ($cc)"
