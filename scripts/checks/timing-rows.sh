#!/usr/bin/env bash
# Every public function of src/ and of the bare-metal port has a measured
# worst case in docs/TIMING.md: a row named after it (`f` or `f/case`).
# TIMING.md is made by bench/bench.sh under QEMU (not run by the tests);
# this check fails when a function is added without a row, or a row's
# function is gone, so the table cannot fall behind the headers unseen.
# Usage: scripts/checks/timing-rows.sh
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
timing="$TASE_ROOT/docs/TIMING.md"
rows=$(sed -n 's/^| `\(tase_[a-z0-9_]*\)[`/].*/\1/p' "$timing" | sort -u)
fns=$("$TASE_ROOT/bench/public-fns.sh" "$TASE_ROOT")
# both lists sorted: comm -23 what only the headers have, -13 only the table
mapfile -t missing < <(comm -23 <(echo "$fns") <(echo "$rows"))
mapfile -t gone < <(comm -13 <(echo "$fns") <(echo "$rows"))
[ ${#missing[@]} -eq 0 ] || tase_fail "docs/TIMING.md has no row for: ${missing[*]} (measure them in bench/cm/timing_*.c and run bench/bench.sh)"
[ ${#gone[@]} -eq 0 ] || tase_fail "docs/TIMING.md has rows for functions no header declares: ${gone[*]}"
echo "docs/TIMING.md: a row for each of the $(wc -l <<<"$rows") public functions"
