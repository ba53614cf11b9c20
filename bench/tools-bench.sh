#!/usr/bin/env bash
# Decode speed of `tase decode` on dense telemetry, beside md5sum reading the
# same file in the same run (the disk and page-cache baseline). Two 100 MB
# captures: back-to-back GIMBAL_ANGLE frames (14 bytes each, the densest
# telemetry), and GIMBAL_ANGLE + GIMBAL_RATE + GEOREFERENCE_DATA in turn (as
# at equal PACKET_RATEs). Output goes to /dev/null; each figure is the best
# of three runs (wall clock, informational: other load only makes it
# slower). Prints a Markdown table for docs/TOOLS.md.
# Usage: bench/tools-bench.sh [TASE] [MB]   (default build/tools/tase, 100)
set -euo pipefail
. "$(dirname "$0")/../scripts/lib.sh"
tase=${1:-$TASE_ROOT/build/tools/tase}
mb=${2:-100}
[ -x "$tase" ] || { echo "no $tase: build first (cmake --build build)"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

python3 - "$work" "$mb" <<'PY'
import random, struct, sys
def frame(g, t, d):
    b = bytes([0, 0xFF, 0x5A, len(d) + 2, g, t]) + d
    s = sum(b) & 0xFFFF
    return b + bytes([s >> 8, s & 0xFF])
rng = random.Random(15)
angle, mix = [], []
for i in range(4096):
    a = frame(0x08, 0x10, struct.pack(">hhh", rng.randint(-18000, 17999), rng.randint(-9000, 9000), 0))
    r = frame(0x08, 0x40, struct.pack(">Ihhhhhhxb", i * 10, rng.randint(-3000, 3000),
                                      rng.randint(-3000, 3000), 0, 1, 2, 3, 0x41))
    g = frame(0x10, 0x41, bytes(rng.randint(0, 255) for _ in range(63)))
    angle.append(a)
    mix.append(a + r + g)
size = int(sys.argv[2]) * 1000000
for name, parts in (("angle", angle), ("mix", mix)):
    blob = b"".join(parts)
    with open("%s/%s.bin" % (sys.argv[1], name), "wb") as f:
        n = 0
        while n < size:
            f.write(blob)
            n += len(blob)
PY

# best WALL-SECONDS of three runs of CMD...
best() {
    local b="" t i
    for i in 1 2 3; do
        t=$( { TIMEFORMAT=%R; time "$@" >/dev/null 2>&1; } 2>&1)
        if [ -z "$b" ] || awk -v a="$t" -v b="$b" 'BEGIN {exit !(a < b)}'; then b=$t; fi
    done
    echo "$b"
}
mbps() { awk -v s="$1" -v f="$2" 'BEGIN {printf "%.0f", s / 1e6 / (f > 0 ? f : 0.001)}'; }

echo "| capture | size | \`tase decode\` | md5sum |"
echo "|---|---|---|---|"
for name in angle mix; do
    f="$work/$name.bin"
    sz=$(stat -c %s "$f")
    cat "$f" >/dev/null # into the page cache for both
    td=$(best "$tase" decode "$f")
    tm=$(best md5sum "$f")
    label=$([ $name = angle ] && echo "GIMBAL_ANGLE only" || echo "angle + rate + georef")
    echo "| $label | $((sz / 1000000)) MB | $(mbps "$sz" "$td") MB/s ($td s) | $(mbps "$sz" "$tm") MB/s ($tm s) |"
done
