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
echo "decode: serial, candump and KLV captures match their expected JSON"
