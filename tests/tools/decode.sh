#!/usr/bin/env bash
# `tase decode` on the committed captures must print exactly the JSON lines
# their generator (tests/data/gen_captures.py) wrote from the values it encoded.
# Usage: tests/tools/decode.sh TASE DATA_DIR
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
# `tase klv`: offset and raw fields (in tag order) must equal what the
# generator encoded; the "units" object is formatting and is not compared.
"$TASE" klv "$DATA/klv_noisy.bin" >"$out"
python3 - "$DATA/klv_noisy.jsonl" "$out" <<'PY'
import json, sys
exp = [json.loads(l) for l in open(sys.argv[1])]
got = [json.loads(l) for l in open(sys.argv[2])]
assert len(got) == len(exp), "tase klv printed %d packets, expected %d" % (len(got), len(exp))
for e, g in zip(exp, got):
    assert g["offset"] == e["offset"], (g["offset"], e["offset"])
    assert list(g["fields"].items()) == list(e["fields"].items()), (g, e)
    assert "units" in g and not set(g["units"]) & set(g["fields"])
PY
"$TASE" klv - <"$DATA/klv_noisy.bin" | cmp -s - "$out"
# Issue 12: a 28-byte CAMERA_PASS whose camera bytes are a whole GIMBAL_CMD
# frame (pan 90.00, tilt -10.00) decodes to the CAMERA_PASS only.
printf '\x00\xff\x5a\x16\x00\x42\x01\x08\x00\x00\x00\xff\x5a\x0a\x00\x80\x23\x28\xfc\x18\x00\x00\x00\x00\x03\x42\x05\x41' |
    "$TASE" decode - >"$out"
if [ "$(wc -l <"$out")" -ne 1 ] || ! grep -q '^{"offset":0,.*"name":"CAMERA_PASS"' "$out"; then
    echo "tase decode of a CAMERA_PASS carrying a GIMBAL_CMD frame:"; cat "$out"; exit 1
fi
echo "decode: serial, candump and KLV captures match their expected JSON; a frame inside a CAMERA_PASS is data"
