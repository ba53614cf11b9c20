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
# A packet whose CAN frames come 30 ms apart (cansend, a slow scheduler): the
# time bound cuts it short at 20 ms, and says so; --margin 100 waits for it.
gap=$(mktemp)
python3 - "$gap" <<'PY'
import sys
f = bytes([0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x03, 0xE8, 0xFE, 0x0C, 0, 0])
f += (sum(f) & 0xFFFF).to_bytes(2, "big")
with open(sys.argv[1], "w") as o:
    o.write("(1700000000.000100) can0 10000000#%s\n" % f[:8].hex().upper())
    o.write("(1700000000.030100) can0 10000000#%s\n" % f[8:].hex().upper())
PY
rc=0
"$TASE" decode --candump --stats "$gap" >"$out" 2>"$gap.err" || rc=$?
if [ "$rc" -ne 4 ] || [ -s "$out" ] || ! grep -q "1 held frames cut short by a pause" "$gap.err" ||
    ! grep -q "cut short by pauses longer than the quiet limit; --margin MS" "$gap.err"; then
    echo "tase decode --candump of frames 30 ms apart: exit $rc"; cat "$out" "$gap.err"; exit 1
fi
"$TASE" decode --candump --margin 100 "$gap" >"$out"
grep -q '^{"offset":0,"time":1700000000.030100,"dir":"out","interface":"can0",.*"name":"GIMBAL_ANGLE"' "$out" ||
    { echo "tase decode --candump --margin 100:"; cat "$out"; exit 1; }
# Only a pause cuts a frame short: false syncs 1 ms apart (a lagging scan
# discards bytes at every tick) counted 42 "cut short" and hinted --margin;
# a GIMBAL_RATE missing its middle CAN frame is cut short by a 100 ms pause
# before the next packet, not by a 5 ms one (there it fails its checksum).
python3 - "$gap" <<'PY'
import random, sys
rng = random.Random(7)
with open(sys.argv[1], "w") as o:
    for i in range(400):
        d = [0x00, 0xFF, 0x5A, rng.randint(0x5A, 0x93), 0x00, 0xFF, 0x5A, rng.randint(0x5A, 0x93)]
        o.write("(%d.%06d) can0 10000000#%s\n" % (1700000000 + i // 1000, (i % 1000) * 1000,
                                                   bytes(d).hex().upper()))
for period in (5, 100):
    f = bytes([0x00, 0xFF, 0x5A, 0x14, 0x08, 0x40] + [0] * 18)
    f += (sum(f) & 0xFFFF).to_bytes(2, "big")
    us = 0
    with open("%s.%d" % (sys.argv[1], period), "w") as o:
        for p in range(4):
            for c in range(0, len(f), 8):
                if not (p == 1 and c == 8):
                    o.write("(%d.%06d) can0 10000000#%s\n" % (1700000000 + us // 1000000, us % 1000000,
                                                               f[c:c + 8].hex().upper()))
                us += 1000
            us += period * 1000
PY
rc=0
"$TASE" decode --candump --stats "$gap" >"$out" 2>"$gap.err" || rc=$?
if [ "$rc" -ne 4 ] || grep -q "cut short" "$gap.err" || ! grep -q "each with a bad checksum" "$gap.err"; then
    echo "tase decode --candump of false syncs 1 ms apart: exit $rc"; cat "$gap.err"; exit 1
fi
"$TASE" decode --candump --stats "$gap.5" >"$out" 2>"$gap.err"
grep -q "3 frames .* 1 checksum errors" "$gap.err" && ! grep -q "cut short" "$gap.err" ||
    { echo "a lost middle CAN frame, packets 5 ms apart:"; cat "$gap.err"; exit 1; }
"$TASE" decode --candump --stats "$gap.100" >"$out" 2>"$gap.err"
grep -q "3 frames .* 0 checksum errors.*, 1 held frames cut short by a pause" "$gap.err" ||
    { echo "a lost middle CAN frame, packets 100 ms apart:"; cat "$gap.err"; exit 1; }
rm -f "$gap" "$gap.err" "$gap.5" "$gap.100"
echo "decode: serial, candump and KLV captures match their expected JSON; a frame inside a CAMERA_PASS is data; --margin waits for paced CAN frames"
