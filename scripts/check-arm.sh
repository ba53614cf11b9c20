#!/usr/bin/env bash
# Compile every core source (src/*.c) for a Cortex-M CPU with the project's
# full warning set as errors, then check that no object references the heap.
# Usage: scripts/check-arm.sh cortex-m4|cortex-m0plus|cortex-m3|cortex-m7 [outdir]
set -euo pipefail
. "$(dirname "$0")/lib.sh"
cpu=${1:?cpu}
out=${2:-$TASE_ROOT/build-arm-$cpu}
mkdir -p "$out"
flags=(-std=c99 -mcpu="$cpu" -mthumb -Os -ffunction-sections -fdata-sections
       -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror
       -I"$TASE_ROOT/include")
objs=()
for src in "$TASE_ROOT"/src/*.c; do
    obj="$out/$(basename "$src" .c).o"
    arm-none-eabi-gcc "${flags[@]}" -c "$src" -o "$obj"
    objs+=("$obj")
done
"$TASE_ROOT/scripts/check-no-heap.sh" arm-none-eabi-nm "${objs[@]}"
arm-none-eabi-size -t "${objs[@]}" | tail -1
echo "core builds warning-free for $cpu (${#objs[@]} objects)"
