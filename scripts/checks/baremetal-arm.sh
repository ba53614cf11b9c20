#!/usr/bin/env bash
# Compile the bare-metal UART template (port/baremetal) and the roles for a
# Cortex-M CPU with the project's warnings as errors and WITHOUT the host's
# barrier config, i.e. exactly as firmware would: portable C99, no
# extensions, default (empty) TASE_RING_BARRIER().
# Usage: scripts/checks/baremetal-arm.sh cortex-m0plus|cortex-m4|... [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
cpu=${1:?cpu}
out=${2:-$TASE_ROOT/build-baremetal-$cpu}
mkdir -p "$out"
flags=(-std=c99 -mcpu="$cpu" -mthumb -Os -ffunction-sections -fdata-sections
       -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror
       -I"$TASE_ROOT/include" -I"$TASE_ROOT/port/baremetal")
objs=()
for src in "$TASE_ROOT"/port/baremetal/*.c "$TASE_ROOT"/src/tase_host.c "$TASE_ROOT"/src/tase_gimbal.c \
           "$TASE_ROOT"/src/tase_port_io.c; do
    obj="$out/$(basename "$src" .c).o"
    arm-none-eabi-gcc "${flags[@]}" -c "$src" -o "$obj"
    objs+=("$obj")
done
"$TASE_ROOT/scripts/checks/no-heap.sh" arm-none-eabi-nm "${objs[@]}"
arm-none-eabi-size "${objs[@]}"
echo "bare-metal port and roles build warning-free for $cpu"
