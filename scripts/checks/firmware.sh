#!/usr/bin/env bash
# Build the example gimbal firmware (examples/firmware) for Cortex-M3 with
# the toolchain file and run it under QEMU's mps2-an385 board. The image
# checks itself and exits through semihosting with its pass/fail status.
# Usage: scripts/checks/firmware.sh [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-firmware}
src="$TASE_ROOT/examples/firmware"
mkdir -p "$out"

# stream.h is committed; it must be what mkstream.py writes.
if command -v python3 >/dev/null; then
    python3 "$src/mkstream.py" > "$out/stream.h"
    if ! cmp -s "$out/stream.h" "$src/stream.h"; then
        echo "examples/firmware/stream.h is stale: cd examples/firmware && python3 mkstream.py > stream.h"
        exit 1
    fi
fi

cmake -S "$src" -B "$out" -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/arm-none-eabi.cmake" \
      -DTASE_CPU=cortex-m3 >/dev/null
cmake --build "$out" -j2
# -icount: the guest's clock (SysTick) counts executed instructions (32 ns
# each, about the board's 25 MHz) instead of host time, and sleep=off skips
# idle time. The run is then exactly repeatable: the image checks that its
# main loop handled every 1 ms tick before the next one, which on a loaded
# host with a wall-clock SysTick is not guaranteed.
timeout 120 qemu-system-arm -M mps2-an385 -nographic -monitor none \
    -icount shift=5,sleep=off \
    -semihosting-config enable=on,target=native -kernel "$out/tase_gimbal.elf"
