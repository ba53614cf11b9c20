#!/usr/bin/env bash
# `tase decode` on the committed captures must print exactly the JSON lines
# their generator (tests/data/gen_captures.py) wrote from the values it encoded.
# Usage: scripts/tools-decode.sh TASE DATA_DIR
set -euo pipefail
TASE=$1
DATA=$2
out=$(mktemp)
trap 'rm -f "$out"' EXIT
"$TASE" decode "$DATA/decode_noisy.bin" >"$out"
diff -u "$DATA/decode_noisy.jsonl" "$out"
"$TASE" decode - <"$DATA/decode_noisy.bin" | diff -u "$DATA/decode_noisy.jsonl" -
"$TASE" decode --candump "$DATA/decode_candump.log" >"$out"
diff -u "$DATA/decode_candump.jsonl" "$out"
echo "decode: serial and candump captures match their expected JSON"
