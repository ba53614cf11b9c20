#!/usr/bin/env bash
# Adversarial search for the receiver's worst calls (bench/cm/search.c): a
# hill climb over a period of bytes, measured with exact Cortex-M counts
# under QEMU. Deterministic: the same arguments give the same result.
#   bench/search.sh MEASURE [--cpu CPU] [--opt O2|Os] [--iters N] [--seed STREAM]
#                           [--rng N] [--out FILE]
#     MEASURE  push | feed16 | feed64 | sustained
#     --cpu    cortex-m4 (default) or cortex-m0plus
#     --opt    O2 (default) or Os
#     --iters  mutation steps (default 2000; a few minutes on M4)
#     --seed   the bench stream the period starts from (default syncrand;
#              bench/streams.h)
#     --rng    the mutation generator's seed (default 12345)
#     --out    where the best 2048-byte period goes (default
#              BUILD/search_MEASURE_CPU_OPT.bin); replay it tiled
#     --build  where the image is built (default build-bench)
# Prints the seed's score, each improvement and "best SCORE" (instructions:
# of the longest call, or of pushing 2048 bytes for sustained); for
# sustained also "tiled ...: X a byte net", the best period repeated over
# 262,144 bytes and counted as bench.sh counts a stream (its figure to quote).
set -euo pipefail
. "$(dirname "$0")/../scripts/lib.sh"
[ $# -ge 1 ] || { sed -n '2,20p' "$0"; exit 2; }
case $1 in
    push) mode=0 ;;
    feed16) mode=1 ;;
    feed64) mode=2 ;;
    sustained) mode=3 ;;
    *) echo "search.sh: MEASURE is push, feed16, feed64 or sustained, not $1" >&2; exit 2 ;;
esac
measure=$1
shift
cpu=cortex-m4 opt=O2 iters=2000 seed=syncrand rng=12345 out= bdir=$TASE_ROOT/build-bench
while [ $# -gt 0 ]; do
    [ $# -ge 2 ] || { echo "search.sh: $1 needs a value" >&2; exit 2; }
    case $1 in
        --cpu) cpu=$2 ;;
        --opt) opt=$2 ;;
        --iters) iters=$2 ;;
        --seed) seed=$2 ;;
        --rng) rng=$2 ;;
        --out) out=$2 ;;
        --build) bdir=$2 ;;
        *) echo "search.sh: unknown option $1" >&2; exit 2 ;;
    esac
    shift 2
done
case $opt in O2 | Os) ;; *) echo "search.sh: --opt is O2 or Os" >&2; exit 2 ;; esac
[[ $iters =~ ^[0-9]+$ && $rng =~ ^[1-9][0-9]*$ ]] ||
    { echo "search.sh: --iters and --rng take numbers (--rng not 0)" >&2; exit 2; }
[[ $seed =~ ^[a-z0-9]+$ ]] || { echo "search.sh: --seed takes a stream name" >&2; exit 2; }
tase_need base firmware
mkdir -p "$bdir"
bdir=$(cd "$bdir" && pwd)
out=${out:-$bdir/search_${measure}_${cpu}_$opt.bin}
elf=$bdir/search_${measure}_${cpu}_$opt.elf
cd "$TASE_ROOT"
arm-none-eabi-gcc -std=c99 -mcpu="$cpu" -mthumb -"$opt" -g -Wall -Wextra -Wconversion \
    -Wsign-conversion -Wshadow -Werror -ffunction-sections -fdata-sections -Iinclude \
    -DSEARCH_MODE="$mode" -DSEARCH_ITERS="${iters}u" -DSEARCH_RNG="${rng}u" \
    -DSEARCH_SEED="\"$seed\"" -DSEARCH_OUT="\"$out\"" \
    src/tase_frame.c src/tase_frame_time.c bench/streams.c bench/cm/search.c bench/cm/longest.c \
    bench/cm/measure.c \
    bench/cm/startup.c -T bench/cm/mps2.ld --specs=rdimon.specs -nostartfiles -Wl,--gc-sections \
    -o "$elf"
qemu-system-arm -M mps2-an386 -nographic -monitor none -icount shift=0 \
    -semihosting-config enable=on,target=native -kernel "$elf"
echo "best period: $out"
