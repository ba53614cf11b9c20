#!/usr/bin/env bash
# Regenerate the bit-error sweep table in docs/ROBUSTNESS.md (between the
# ber-sweep markers) from tests/robust/ber_sweep.c, and fail if the sweep
# breaks a requirement. Usage: bench/ber-sweep.sh [PACKETS] (default 1e6)
set -euo pipefail
. "$(dirname "$0")/../scripts/lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cc -std=c99 -O2 -I"$TASE_ROOT/include" "$TASE_ROOT"/src/*.c "$TASE_ROOT/tests/robust/ber_sweep.c" \
    -lm -o "$out/ber_sweep"
"$out/ber_sweep" --check --markdown --packets "${1:-1000000}" >"$out/table.md"
doc="$TASE_ROOT/docs/ROBUSTNESS.md"
awk -v table="$out/table.md" '
    /<!-- ber-sweep:begin -->/ { print; while ((getline l < table) > 0) print l; skip = 1; next }
    /<!-- ber-sweep:end -->/ { skip = 0 }
    !skip { print }' "$doc" >"$out/doc.md"
cp "$out/doc.md" "$doc"
cat "$out/table.md"
