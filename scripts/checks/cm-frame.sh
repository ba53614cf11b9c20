#!/usr/bin/env bash
# The checksum and the receiver on a Cortex-M CPU's own code paths
# (tests/cm/frame_on_target.c): built for the CPU at -O2 and -Os and run
# under QEMU's mps2-an386 board (a Cortex-M4; ARMv6-M code for the M0+
# runs on it instruction for instruction). The image exits with its
# pass/fail status through semihosting. It compares results: QEMU does not
# fault on unaligned word accesses on either board (nor on its Cortex-M0
# micro:bit), so a stray unaligned load in M0+ code is not caught here.
# Usage: scripts/checks/cm-frame.sh cortex-m4|cortex-m0plus|... [outdir]
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
cpu=${1:?cpu}
out=${2:-$TASE_ROOT/build-cm-frame}
mkdir -p "$out"
for opt in O2 Os; do
    elf="$out/frame_on_target_${cpu}_$opt.elf"
    arm-none-eabi-gcc -std=c99 -mcpu="$cpu" -mthumb -"$opt" -g \
        -Wall -Wextra -Wconversion -Wsign-conversion -Wshadow -Werror \
        -ffunction-sections -fdata-sections -I"$TASE_ROOT/include" \
        "$TASE_ROOT/tests/cm/frame_on_target.c" "$TASE_ROOT/src/tase_frame.c" \
        "$TASE_ROOT/src/tase_frame_time.c" "$TASE_ROOT/bench/cm/startup.c" \
        -T "$TASE_ROOT/bench/cm/mps2.ld" --specs=rdimon.specs -nostartfiles -Wl,--gc-sections \
        -o "$elf"
    timeout 300 qemu-system-arm -M mps2-an386 -nographic -monitor none \
        -semihosting-config enable=on,target=native -kernel "$elf"
done
