#!/usr/bin/env bash
# Bounded libFuzzer run of one harness (fuzz/<harness>.c) over the core
# (every src/*.c), with AddressSanitizer and UndefinedBehaviorSanitizer,
# no recovery: any crash, leak, UB, broken invariant or stall fails.
# Usage: scripts/checks/fuzz.sh HARNESS SECONDS [OUTDIR]
#   TASE_FUZZ_TIME=N overrides SECONDS (e.g. 5 for a smoke run, 3600 for a
#   long local campaign).
# The committed corpus fuzz/corpus/HARNESS is replayed first (seeds and
# crash regressions); new inputs go to OUTDIR/corpus-HARNESS, which
# persists between runs. A crash leaves OUTDIR/artifacts-HARNESS/crash-*:
# fix the bug, then commit the file as fuzz/corpus/HARNESS/regress-<what>
# (and add a unit test for it) so every later run replays it.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
h=${1:?harness}
secs=${TASE_FUZZ_TIME:-${2:?seconds}}
out=${3:-$TASE_ROOT/build/fuzz}
cc=$(command -v clang-14 || command -v clang)
mkdir -p "$out/corpus-$h" "$out/artifacts-$h"
bin="$out/fuzz_$h"
"$cc" -std=c99 -g -O1 -fno-omit-frame-pointer \
    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
    -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror \
    -I"$TASE_ROOT/include" "$TASE_ROOT"/src/*.c "$TASE_ROOT/fuzz/$h.c" -o "$bin"
log="$out/fuzz_$h.log"
set +e
"$bin" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
    -print_final_stats=1 -artifact_prefix="$out/artifacts-$h/" \
    "$out/corpus-$h" "$TASE_ROOT/fuzz/corpus/$h" >"$log" 2>&1
rc=$?
set -e
runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
cov=$(grep -Eo 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1 || true)
if [ "$rc" -ne 0 ]; then
    grep -v '# Uses:' "$log" | tail -40
    echo "fuzz_$h: FAILED (exit $rc); reproducer in $out/artifacts-$h/"
    echo "replay: $bin $out/artifacts-$h/crash-*"
    exit 1
fi
echo "fuzz_$h: ${runs:-?} executions in ${secs}s (${rate:-?} exec/s), $cov," \
     "corpus $(find "$out/corpus-$h" -type f | wc -l) + $(find "$TASE_ROOT/fuzz/corpus/$h" -type f | wc -l) committed"
