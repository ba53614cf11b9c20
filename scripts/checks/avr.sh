#!/usr/bin/env bash
# The core on an 8-bit AVR (ATmega2560: int and size_t are 16 bits):
#   1. every src/*.c and port/baremetal/*.c compiled with avr-gcc and the
#      project's full warning set as errors (reports the flash of each);
#   2. tests/avr/avr_core.c (every packet's round trip, the receiver on a
#      noisy stream fed in chunks and byte by byte) linked with the core
#      and run under simavr; its UART output must end in
#      "AVR RESULT: PASS";
#   3. the same program built for the host must print the same results
#      (the pseudo-random streams are identical, so any difference is the
#      16-bit target computing something else).
# Usage: scripts/checks/avr.sh [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-avr}
rm -rf "$out"
mkdir -p "$out/obj"
mcu=atmega2560
warn=(-Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror)
flags=(-mmcu=$mcu -std=c99 -Os -ffunction-sections -fdata-sections "${warn[@]}"
       -I"$TASE_ROOT/include" -I"$TASE_ROOT/port/baremetal")

tase_step "compile the core and the bare-metal port for $mcu ($(avr-gcc -dumpversion))"
objs=()
for src in "$TASE_ROOT"/src/*.c "$TASE_ROOT"/port/baremetal/*.c; do
    obj="$out/obj/$(basename "$src" .c).o"
    avr-gcc "${flags[@]}" -c "$src" -o "$obj"
    objs+=("$obj")
done
avr-size "${objs[@]}"
"$TASE_ROOT/scripts/checks/no-heap.sh" avr-nm "${objs[@]}"

tase_step "run tests/avr/avr_core.c under simavr"
avr-gcc "${flags[@]}" "$TASE_ROOT/tests/avr/avr_core.c" "$TASE_ROOT"/src/*.c -Wl,--gc-sections \
    -o "$out/avr_core.elf"
avr-size "$out/avr_core.elf"
# simavr prints the UART's lines in colour with "." for the newline.
timeout 300 simavr -m $mcu -f 16000000 "$out/avr_core.elf" 2>&1 |
    sed 's/\x1b\[[0-9;]*m//g; s/\.$//' | grep -v '^Loaded ' >"$out/avr.txt" || true
cat "$out/avr.txt"
grep -qx 'AVR RESULT: PASS' "$out/avr.txt" || tase_fail "the AVR program did not pass"
grep -q '^FAIL' "$out/avr.txt" && tase_fail "the AVR program reported failures"

tase_step "the same program on the host gives the same results"
cc -std=c99 -O2 "${warn[@]}" -I"$TASE_ROOT/include" "$TASE_ROOT/tests/avr/avr_core.c" \
    "$TASE_ROOT"/src/*.c -o "$out/host_core"
"$out/host_core" >"$out/host.txt"
if ! diff <(grep -E '^(packets|receiver|AVR RESULT):' "$out/avr.txt") \
    <(grep -E '^(packets|receiver|AVR RESULT):' "$out/host.txt"); then
    tase_fail "the AVR and the host disagree"
fi
tase_step "avr: the core builds warning-free with 16-bit int and passes its test under simavr"
