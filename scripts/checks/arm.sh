#!/usr/bin/env bash
# Cross-build the core for a Cortex-M CPU with the project's full warning set
# as errors, two ways:
#   1. "copy into another build": include/ and src/ copied to a scratch
#      directory and every src/*.c compiled by hand (no CMake, nothing
#      generated);
#   2. the CMake toolchain file cmake/arm-none-eabi.cmake (core library only).
# Then check that no object references the heap, 64-bit division or
# double arithmetic (scripts/checks/no-softmath.sh; KLV excepted).
# Usage: scripts/checks/arm.sh cortex-m0plus|cortex-m3|cortex-m4|cortex-m7 [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
cpu=${1:?cpu}
out=${2:-$TASE_ROOT/build-arm-$cpu}
rm -rf "$out/copy" "$out/cmake"
mkdir -p "$out/copy" "$out/obj"
cp -r "$TASE_ROOT/include" "$TASE_ROOT/src" "$out/copy/"
flags=(-std=c99 -mcpu="$cpu" -mthumb -Os -ffunction-sections -fdata-sections
       -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror
       -I"$out/copy/include")
objs=()
for src in "$out"/copy/src/*.c; do
    obj="$out/obj/$(basename "$src" .c).o"
    arm-none-eabi-gcc "${flags[@]}" -c "$src" -o "$obj"
    objs+=("$obj")
done
"$TASE_ROOT/scripts/checks/no-heap.sh" arm-none-eabi-nm "${objs[@]}"
"$TASE_ROOT/scripts/checks/no-softmath.sh" arm-none-eabi-nm "${objs[@]}"
arm-none-eabi-size -t "${objs[@]}" | tail -1

cmake -S "$TASE_ROOT" -B "$out/cmake" -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/arm-none-eabi.cmake" \
      -DTASE_CPU="$cpu" >/dev/null
cmake --build "$out/cmake" -j2 >/dev/null
lib="$out/cmake/libtase.a"
"$TASE_ROOT/scripts/checks/no-heap.sh" arm-none-eabi-nm "$lib"
echo "core builds warning-free for $cpu (${#objs[@]} objects by hand, $lib via the toolchain file)"
