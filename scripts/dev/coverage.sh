#!/usr/bin/env bash
# Line and branch coverage of the core (src/) by the unit tests, with a
# gate: fails below TASE_COV_LINES % of lines (95) or TASE_COV_BRANCHES %
# of branches (90). One command produces the report:
#   scripts/dev/coverage.sh [OUTDIR]   (default build/coverage)
# OUTDIR/index.html (per-file, annotated source), OUTDIR/summary.txt (lines
# per file) and OUTDIR/totals.txt (line, function and branch totals).
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build/coverage}
lines=${TASE_COV_LINES:-95}
branches=${TASE_COV_BRANCHES:-90}
bld="$out/build"
rm -rf "$bld" && mkdir -p "$out"
# -O0 keeps one branch per source condition; -fprofile-update=atomic: the
# pty and ring tests run library code on two threads, and racing counter
# updates made gcov report negative branch counts. TASE_CHECKS=OFF: the unit
# tests (and corpus replays are not unit tests there) are what count.
cmake -S "$TASE_ROOT" -B "$bld" -DCMAKE_C_COMPILER=gcc -DCMAKE_BUILD_TYPE=Debug \
    -DTASE_CHECKS=OFF -DCMAKE_C_FLAGS="--coverage -O0 -fprofile-update=atomic" \
    -DCMAKE_EXE_LINKER_FLAGS="--coverage" >/dev/null
cmake --build "$bld" -j2 >/dev/null
(cd "$bld" && ctest --output-on-failure -L unit >/dev/null)
gcovr --root "$TASE_ROOT" --object-directory "$bld" --filter "$TASE_ROOT/src/" \
    --exclude-unreachable-branches --exclude-directories '.*CompilerId.*' \
    --html-details "$out/index.html" --txt "$out/summary.txt" --print-summary \
    --fail-under-line "$lines" --fail-under-branch "$branches" >"$out/totals.txt" || {
    cat "$out/totals.txt"
    cat "$out/summary.txt"
    echo "coverage below the gate (lines >= $lines%, branches >= $branches%); report: $out/index.html"
    exit 1
}
cat "$out/summary.txt" "$out/totals.txt"
echo "coverage gate passed (lines >= $lines%, branches >= $branches%); report: $out/index.html"
