#!/usr/bin/env bash
# Receiver benchmark (issue 21): a program that reports numbers, never a
# pass/fail test. Writes docs/PERFORMANCE.md with:
#   0. issue 21's targets side by side: the longest single call and the
#      sustained cost per byte on Cortex-M4 -O2/-Os and Cortex-M0+ -Os under
#      QEMU (exact instruction counts, bench/cm/bench_cm.c), typical cost
#      beside a classic parser, framing flash, push-path stack, sizeof;
#   1. x86-64 gcc -O2, callgrind, one program run per stream: instructions
#      per byte of tase_rx_push() and tase_rx_feed() beside a classic
#      single-state parser and a store-and-sum loop (bench/classic_rx.c);
#   2. x86-64, per stream and chunk size, framing and framing + dispatch
#      (callgrind --toggle-collect, cross-checked by subtracting a run that
#      feeds nothing), and MB/s (wall clock, informational);
#   3. the Cortex-M runs of 0 in full, per stream.
# Usage: bench/bench.sh [--out FILE] [--build DIR]
set -euo pipefail
. "$(dirname "$0")/../scripts/lib.sh"
out="$TASE_ROOT/docs/PERFORMANCE.md"
bdir="$TASE_ROOT/build-bench"
while [ $# -gt 0 ]; do
    case $1 in
        --out) out=$2; shift 2 ;;
        --build) bdir=$2; shift 2 ;;
        *) echo "usage: $0 [--out FILE] [--build DIR]"; exit 2 ;;
    esac
done
tase_need base firmware
mkdir -p "$bdir"
cd "$TASE_ROOT" # the build commands below are quoted relative to it
warn=(-Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror)
cflags=(-std=c99 -O2 -g "${warn[@]}")
variants=(framing)
if [ -f "$TASE_ROOT/include/tase/dispatch.h" ]; then
    cflags+=(-DBENCH_DISPATCH)
    variants+=(dispatch)
fi
srcs=(src/*.c bench/classic_rx.c bench/streams.c bench/bench_rx.c)
build_cmd="gcc ${cflags[*]} -Iinclude src/*.c ${srcs[*]:${#srcs[@]}-3} -o ${bdir#$TASE_ROOT/}/bench_rx"
gcc "${cflags[@]}" -Iinclude "${srcs[@]}" -o "$bdir/bench_rx"
bin="$bdir/bench_rx"
streams=(telemetry badsize sync4 syncrand noise zeros held255 burst heldnoise halfsum synclong)

# ir ARGS...: instructions counted by callgrind (all of them, or only inside
# one function when the first argument is --toggle-collect=...).
ir() {
    local f="$bdir/callgrind.out"
    valgrind --tool=callgrind --callgrind-out-file="$f" "$@" >/dev/null 2>&1
    awk '/^totals:/ {print $2}' "$f"
}
per_byte() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.1f", a / b}'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }
le() { awk -v a="$1" -v b="$2" 'BEGIN {exit !(a <= b)}'; }
met() { if le "$1" "$2"; then echo met; else echo "**missed**"; fi; }
# inclusive FUNCTION: callgrind's inclusive cost of FUNCTION in the last run.
inclusive() {
    callgrind_annotate --inclusive=yes --threshold=100 "$bdir/callgrind.out" 2>/dev/null |
        awk -v fn=":$1 " 'index($0, fn) && $0 !~ /=>/ {gsub(",", "", $1); print $1; exit}'
}

# 1. One run per stream: classic, store-and-sum, push, feed 4096.
cmp_rows=()
for stream in "${streams[@]}"; do
    line=$("$bin" "$stream" 4096 compare)
    bytes=$(sed -n 's/.*bytes=\([0-9]*\).*/\1/p' <<<"$line")
    cframes=$(sed -n 's/.*classic_frames=\([0-9]*\).*/\1/p' <<<"$line")
    pframes=$(sed -n 's/.*push_frames=\([0-9]*\).*/\1/p' <<<"$line")
    ir "$bin" "$stream" 4096 compare >/dev/null
    c=$(per_byte "$(inclusive classic_rx_push)" "$bytes")
    s=$(per_byte "$(inclusive store_sum_push)" "$bytes")
    p=$(per_byte "$(inclusive tase_rx_push)" "$bytes")
    f=$(per_byte "$(inclusive tase_rx_feed)" "$bytes")
    cmp_rows+=("| $stream | $bytes | $cframes | $pframes | $s | $c | $p | $(ratio "$p" "$c") | $f |")
    echo "${cmp_rows[-1]}"
    if [ "$stream" = telemetry ]; then
        t_classic=$c t_store=$s t_push=$p t_feed=$f
    fi
done

# 2. Per stream and chunk size, framing and dispatch.
rows=()
worst_name="" worst=0 worst4096=0 worst4096_name=""
for stream in "${streams[@]}"; do
    for variant in "${variants[@]}"; do
        [ "$variant" = dispatch ] && [ "$stream" != telemetry ] && continue
        extra=(); [ "$variant" = dispatch ] && extra=(dispatch)
        line=$("$bin" "$stream" 4096 once "${extra[@]}")
        bytes=$(sed -n 's/.*bytes=\([0-9]*\).*/\1/p' <<<"$line")
        frames=$(sed -n 's/.*frames=\([0-9]*\).*/\1/p' <<<"$line")
        cols=()
        for chunk in 4096 64 1; do
            tog=tase_rx_feed
            [ "$chunk" = 1 ] && tog=tase_rx_push # chunk 1 goes through tase_rx_push()
            n=$(ir --toggle-collect="$tog" "$bin" "$stream" "$chunk" once "${extra[@]}")
            cols+=("$(per_byte "$n" "$bytes")")
        done
        full=$(ir "$bin" "$stream" 4096 once "${extra[@]}")
        empty=$(ir "$bin" "$stream" 4096 empty "${extra[@]}")
        cross=$(per_byte $((full - empty)) "$bytes")
        mb4096=$("$bin" "$stream" 4096 time "${extra[@]}" | sed -n 's/mbps=\([0-9.]*\).*/\1/p')
        mb1=$("$bin" "$stream" 1 time "${extra[@]}" | sed -n 's/mbps=\([0-9.]*\).*/\1/p')
        rows+=("| $stream | $variant | $bytes | $frames | ${cols[0]} | ${cols[1]} | ${cols[2]} | $cross | $mb4096 | $mb1 |")
        echo "${rows[-1]}"
        if [ "$stream" != telemetry ] && ! le "${cols[2]}" "$worst"; then
            worst=${cols[2]} worst_name=$stream
        fi
        if [ "$stream" != telemetry ] && ! le "${cols[0]}" "$worst4096"; then
            worst4096=${cols[0]} worst4096_name=$stream
        fi
        if [ "$stream" = telemetry ] && [ "$variant" = dispatch ]; then
            tele_dispatch=${cols[0]}
        fi
        if [ "$stream" = telemetry ] && [ "$variant" = framing ]; then
            tele=${cols[0]} tele1=${cols[2]}
            ir --toggle-collect='tase_rx_feed' "$bin" telemetry 4096 once >/dev/null
            profile=$(callgrind_annotate --inclusive=no --auto=no "$bdir/callgrind.out" 2>/dev/null |
                      grep -E '^ *[0-9,]+ +\(' | grep -v 'PROGRAM TOTALS' | head -8 |
                      sed -E "s#$TASE_ROOT/##; s# \[[^]]*\]##; s#^ *#    #")
        fi
    done
done

# 3. Cortex-M in QEMU: M4 -O2, M4 -Os, M0+ -Os (ARMv6-M code on the M4 board).
targets=("cortex-m4 O2" "cortex-m4 Os" "cortex-m0plus Os")
cm_cmd() {
    echo "arm-none-eabi-gcc -std=c99 -mcpu=$1 -mthumb -$2 -g ${cmwarn[*]}" \
         "-ffunction-sections -fdata-sections -Iinclude src/tase_frame.c src/tase_frame_time.c bench/classic_rx.c" \
         "bench/streams.c bench/cm/bench_cm.c bench/cm/longest.c bench/cm/measure.c bench/cm/startup.c" \
         "-T bench/cm/mps2.ld" \
         "--specs=rdimon.specs -nostartfiles -Wl,--gc-sections -o ${bdir#$TASE_ROOT/}/cm_$1_$2.elf"
}
declare -A cm
cmwarn=("${warn[@]/-Wpedantic/}") # startup.c needs GNU attributes and inline assembly
cmwarn=(${cmwarn[@]})
for t in "${targets[@]}"; do
    set -- $t
    key="$1-$2"
    eval "$(cm_cmd "$1" "$2")"
    timeout 900 qemu-system-arm -M mps2-an386 -nographic -monitor none -icount shift=0 \
        -semihosting-config enable=on,target=native -kernel "$bdir/cm_$1_$2.elf" > "$bdir/cm_$key.txt"
    while read -r kind a b c d e f; do
        case $kind in
            calibration) cm[$key,calibration]=$a ;;
            loop) cm[$key,loop,$a,$b]=$d cm[$key,bytes,$b]=$c cm[$key,frames,$a,$b]=$e ;;
            maxcall) cm[$key,max,$a,$b]=$c cm[$key,maxat,$a,$b]=$d cm[$key,maxn,$a,$b]="$e/$f" ;;
            stack) cm[$key,stack,$a]=$b ;;
            sizeof) cm[sizeof]=$b ;;
        esac
    done < "$bdir/cm_$key.txt"
    [ "${cm[$key,calibration]:-}" = 2000000 ] ||
        { echo "QEMU calibration loop ($key): ${cm[$key,calibration]:-none} instructions, want 2000000"; exit 1; }
done
# net FUNC STREAM KEY: instructions per byte of a byte loop, the caller's loop (an empty call) taken off
net() { awk -v a="${cm[$3,loop,$1,$2]}" -v e="${cm[$3,loop,empty,$2]}" -v b="${cm[$3,bytes,$2]}" 'BEGIN {printf "%.1f", (a - e) / b}'; }
# perb FUNC STREAM KEY: instructions per byte, loop included (feed: one call per chunk)
perb() { awk -v a="${cm[$3,loop,$1,$2]}" -v b="${cm[$3,bytes,$2]}" 'BEGIN {printf "%.1f", a / b}'; }
# maxof FUNC KEY: the longest call over all streams, and which stream
maxof() {
    local best=0 at="" s
    for s in "${streams[@]}"; do
        if [ "${cm[$2,max,$1,$s]}" -gt "$best" ]; then best=${cm[$2,max,$1,$s]} at=$s; fi
    done
    echo "$best $at"
}
# worstof FUNC KEY: the highest sustained cost per byte over the adversarial streams
worstof() {
    local best=0 at="" s v
    for s in "${streams[@]}"; do
        [ "$s" = telemetry ] && continue
        if [ "$1" = tase_rx_push ]; then v=$(net "$1" "$s" "$2"); else v=$(perb "$1" "$s" "$2"); fi
        if ! le "$v" "$best"; then best=$v at=$s; fi
    done
    echo "$best $at"
}

# 4. docs/TIMING.md: worst case per call of the public functions of src/
# and of the bare-metal port, port/baremetal (bench/cm/timing*.c), M4 -O2
# and M0+ -Os, beside the receiver's longest
# push/feed calls of part 3.
timing_out="$(dirname "$out")/TIMING.md"
declare -A tm
timing_cmd() {
    echo "arm-none-eabi-gcc -std=c99 -mcpu=$1 -mthumb -$2 -g ${cmwarn[*]}" \
         "-ffunction-sections -fdata-sections -Iinclude -Iport/baremetal src/*.c port/baremetal/*.c" \
         "bench/streams.c bench/cm/timing.c bench/cm/timing_codec.c bench/cm/timing_schema.c" \
         "bench/cm/timing_roles.c bench/cm/timing_misc.c bench/cm/timing_port.c" \
         "bench/cm/measure.c bench/cm/startup.c -T bench/cm/mps2.ld --specs=rdimon.specs" \
         "-nostartfiles -Wl,--gc-sections -o ${bdir#$TASE_ROOT/}/timing_$1_$2.elf"
}
timing_fns=()
for t in "cortex-m4 O2" "cortex-m0plus Os"; do
    set -- $t
    key="$1-$2"
    eval "$(timing_cmd "$1" "$2")" || { echo "bench/cm/timing*.c no longer build against src/: adapt it"; exit 1; }
    timeout 900 qemu-system-arm -M mps2-an386 -nographic -monitor none -icount shift=0 \
        -semihosting-config enable=on,target=native -kernel "$bdir/timing_$1_$2.elf" > "$bdir/timing_$key.txt"
    grep -qx done "$bdir/timing_$key.txt" || { echo "timing run ($key) did not finish"; exit 1; }
    while read -r kind fn insns input; do
        [ "$kind" = timing ] || continue
        [ "$key" = cortex-m4-O2 ] && timing_fns+=("$fn")
        tm[$key,$fn]=$insns tm[$key,input,$fn]=$input
    done < "$bdir/timing_$key.txt"
done
# both_inputs FN: the input each target found worst, once when they agree, else
# "M4: a; M0+: b", and the ending they share (from a separator on) written
# once after them as "; both: ending" (it holds for both)
both_inputs() {
    local a=${tm[cortex-m4-O2,input,$1]} b=${tm[cortex-m0plus-Os,input,$1]:-} n=0 tail=""
    if [ -z "$b" ] || [ "$a" = "$b" ]; then
        echo "$a"
        return
    fi
    while [ $n -lt ${#a} ] && [ $n -lt ${#b} ] &&
          [ "${a:${#a}-n-1:1}" = "${b:${#b}-n-1:1}" ]; do
        n=$((n + 1))
    done
    tail=${a:${#a}-n}
    case $tail in
        *" ("* | *"; "* | *", "*) tail=$(grep -o -E '(; |, | \().*' <<<"$tail" | head -1) ;;
        *) tail="" ;;
    esac
    local a0=${a:0:${#a}-${#tail}} b0=${b:0:${#b}-${#tail}}
    case $tail in
        "") ;;
        ", "* | "; "*) tail="; both: ${tail:2}" ;;
        *) tail="; both:$tail" ;;
    esac
    echo "M4: $a0; M0+: $b0$tail"
}
# per_call FN CALLS KEY: instructions a further port call costs, from FN's
# /bytewise row less its own over CALLS further calls (one decimal)
per_call() {
    awk -v a="${tm[$3,$1/bytewise]}" -v b="${tm[$3,$1]}" -v n="$2" 'BEGIN {printf "%.1f", (a - b) / n}'
}
# per_read KEY: a further read() in tase_host_transact: its /bytewise row less
# its own and less the writes' share (tase_port_send_frame's), over the 256
# further reads of a 261-byte reply (64-byte reads: 5)
per_read() {
    awk -v t="${tm[$1,tase_host_transact/bytewise]}" -v t0="${tm[$1,tase_host_transact]}" \
        -v w="${tm[$1,tase_port_send_frame/bytewise]}" -v w0="${tm[$1,tase_port_send_frame]}" \
        'BEGIN {printf "%.1f", ((t - t0) - (w - w0)) / 256}'
}
# every public function of src/ and of the bare-metal port, to list what
# is not measured
mapfile -t public_fns < <(bench/public-fns.sh "$PWD")

# 5. Framing flash: init/push/feed/flush linked alone, M4 -Os.
fl="$bdir/flash"
mkdir -p "$fl"
flash_cc=(arm-none-eabi-gcc -std=c99 -mcpu=cortex-m4 -mthumb -Os -ffunction-sections -fdata-sections -Iinclude)
"${flash_cc[@]}" -c src/tase_frame.c -o "$fl/tase_frame.o"
"${flash_cc[@]}" -c src/tase_frame_time.c -o "$fl/tase_frame_time.o" # tase_rx_init()
"${flash_cc[@]}" -c bench/cm/framing.c -o "$fl/framing.o"
arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb --specs=nosys.specs -Wl,--gc-sections \
    -Wl,-Map="$fl/framing.map" "$fl/framing.o" "$fl/tase_frame.o" "$fl/tase_frame_time.o" -o "$fl/framing.elf"
flash_rows=$(awk '/^Linker script and memory map/ {on=1} !on {next}
    /^ \.(text|rodata)/ {sec=$1; if (NF>=4) {print sec, $3, $4; sec=""} next}
    sec!="" && NF>=3 && $1 ~ /^0x/ {print sec, $2, $3; sec=""} {sec=""}' "$fl/framing.map" |
    grep -E 'tase_frame(_time)?\.o' | while read -r sec size _; do echo "$sec $((size))"; done)
flash=$(awk '{s += $2} END {print s}' <<<"$flash_rows")
flash_list=$(awk '{sub(/^\.(text|rodata)\./, ""); printf "%s%s %d", sep, $1, $2; sep=", "}' <<<"$flash_rows")

# The issue's targets (issue 21, "Done when").
K4=cortex-m4-O2 K4s=cortex-m4-Os K0=cortex-m0plus-Os
read -r push4 push4_at <<<"$(maxof tase_rx_push $K4)"
read -r push4s push4s_at <<<"$(maxof tase_rx_push $K4s)"
read -r push0 push0_at <<<"$(maxof tase_rx_push $K0)"
read -r f16 f16_at <<<"$(maxof tase_rx_feed/16 $K4)"
read -r f64 f64_at <<<"$(maxof tase_rx_feed/64 $K4)"
read -r f64_0 f64_0_at <<<"$(maxof tase_rx_feed/64 $K0)"
read -r sus4 sus4_at <<<"$(worstof tase_rx_push $K4)"
read -r sus0 sus0_at <<<"$(worstof tase_rx_push $K0)"
read -r sus4f sus4f_at <<<"$(worstof tase_rx_feed/64 $K4)"
read -r sus0f sus0f_at <<<"$(worstof tase_rx_feed/64 $K0)"
typ4=$(net tase_rx_push telemetry $K4) cls4=$(net classic telemetry $K4)
typ0=$(net tase_rx_push telemetry $K0) cls0=$(net classic telemetry $K0)
# the typical-cost ratios from the exact counts, not from the rounded per-byte figures
netratio() {
    awk -v a="${cm[$1,loop,tase_rx_push,telemetry]}" -v c="${cm[$1,loop,classic,telemetry]}" \
        -v e="${cm[$1,loop,empty,telemetry]}" 'BEGIN {printf "%.3f", (a - e) / (c - e)}'
}
rat4=$(netratio $K4) rat0=$(netratio $K0)
stack=0 stack_at=""
for s in "${streams[@]}"; do
    v=${cm[$K4s,stack,tase_rx_push/$s]}
    if [ "$v" -gt "$stack" ]; then stack=$v stack_at=$s; fi
done
# A hand-kept section at the end of the file (the Python package's numbers,
# from python/bench/decode_bench.py) survives regeneration.
kept=$(sed -n '/^<!-- Not generated by bench\/bench.sh/,$p' "$out" 2>/dev/null || true)
{
    echo "# Receiver performance"
    echo
    echo "<!-- GENERATED by bench/bench.sh; do not edit by hand. -->"
    echo "Generated by \`bench/bench.sh\` on $(uname -m), $(gcc --version | head -1),"
    echo "$(valgrind --version), $(arm-none-eabi-gcc --version | head -1),"
    echo "$(qemu-system-arm --version | head -1)."
    echo
    echo "Streams (256 KiB each, deterministic, \`bench/streams.c\`): **telemetry** = GIMBAL_ANGLE"
    echo "(6 data bytes) and GIMBAL_RATE (18) at 10 Hz with GEOREFERENCE_DATA (63) at 4 Hz, back"
    echo "to back; **badsize** = the same with every other frame's Size byte random; **sync4** ="
    echo "\`00 FF 5A FF\` repeated (every 4-byte group is a false sync claiming 253 data bytes, so"
    echo "a candidate fails every 4 bytes); **syncrand** = \`00 FF 5A\` + random Size, repeated;"
    echo "**noise** = uniform random bytes; **zeros** = all 0x00; **held255** = \`00 FF 5A FF\`"
    echo "then 63 groups \`00 FF 5A (255-4k)\`, k = 1..63, repeated (64 complete false"
    echo "candidates decided by one byte: issue 21's longest call); **burst** = \`00 FF 5A FF\`,"
    echo "31 valid empty frames and 9 noise bytes, repeated (one byte releases 31 frames);"
    echo "**heldnoise** = \`00 FF 5A FF\` and 257 noise bytes without a 00, repeated (the scan"
    echo "walks the noise the failed candidate was holding); **halfsum** = 60 noise bytes,"
    echo "\`00 FF 5A FF\` and 64 syncs 4 bytes apart whose candidates each end about half-way"
    echo "through what is left of a reach of 262, 266, ... 330 bytes (every inner candidate is"
    echo "complete when the first fails, and each is summed over a long stretch: found by a"
    echo "review that beat the earlier longest calls with it); **synclong** = \`00 FF 5A\` and a"
    echo "Size of 0x5A..0x93 (about 9 in 100: 0xFF), repeated (the scan never catches up and"
    echo "sums a long stretch for every candidate: a helper's hill-climb found it)."
    echo
    echo "## Issue 21's targets side by side"
    echo
    echo "Cortex-M counts are exact Thumb instruction counts under QEMU (\`bench/cm/bench_cm.c\`,"
    echo "method below); \"longest call\" is the longest single call over every stream above"
    echo "(the stream named), including the caller's argument setup and branch. These are the"
    echo "bench's streams; \`bench/search.sh\` hill-climbs a 2048-byte period from one of them"
    echo "against any row (exact counts, so a run is reproducible) and finds longer calls than"
    echo "these (docs/DESIGN.md)."
    echo
    echo "| target | measured | goal | |"
    echo "|---|---:|---:|---|"
    echo "| longest \`tase_rx_push()\`, M4 -O2 | $push4 ($push4_at) | <= 1000 | $(met "$push4" 1000) |"
    echo "| longest \`tase_rx_push()\`, M4 -Os | $push4s ($push4s_at) | | |"
    echo "| longest \`tase_rx_push()\`, M0+ -Os | $push0 ($push0_at) | <= 2500 | $(met "$push0" 2500) |"
    echo "| longest 16-byte \`tase_rx_feed()\`, M4 -O2 | $f16 ($f16_at) | <= 4000 | $(met "$f16" 4000) |"
    echo "| longest 64-byte \`tase_rx_feed()\`, M4 -O2 | $f64 ($f64_at) | <= 4000 | $(met "$f64" 4000) |"
    echo "| longest 64-byte \`tase_rx_feed()\`, M0+ -Os | $f64_0 ($f64_0_at) | | |"
    echo "| worst sustained, push, instr/byte, M4 -O2 | $sus4 ($sus4_at) | <= 100 | $(met "$sus4" 100) |"
    echo "| worst sustained, push, instr/byte, M0+ -Os | $sus0 ($sus0_at) | <= 250 | $(met "$sus0" 250) |"
    echo "| worst sustained, 64-byte feed, instr/byte, M4 -O2 | $sus4f ($sus4f_at) | <= 100 | $(met "$sus4f" 100) |"
    echo "| worst sustained, 64-byte feed, instr/byte, M0+ -Os | $sus0f ($sus0f_at) | <= 250 | $(met "$sus0f" 250) |"
    echo "| telemetry, push net instr/byte vs classic parser, M4 -O2 | $typ4 vs $cls4 (${rat4}x) | <= 1.0x | $(met "$rat4" 1.0) |"
    echo "| telemetry, push net instr/byte vs classic parser, M0+ -Os | $typ0 vs $cls0 (${rat0}x) | <= 1.0x | $(met "$rat0" 1.0) |"
    echo "| framing flash (init/push/feed/flush), M4 -Os | $flash B | <= 1024 | $(met "$flash" 1024) |"
    echo "| push-path stack, M4 -Os, trivial callback (painted) | $stack B ($stack_at) | <= 128 | $(met "$stack" 128) |"
    echo "| \`sizeof(tase_rx_t)\` (Cortex-M) | ${cm[sizeof]} | <= 360 | $(met "${cm[sizeof]}" 360) |"
    echo
    echo "Framing flash is the sum of the input sections of src/tase_frame.c and src/tase_frame_time.c left in an M4 -Os"
    echo "image that calls only those four functions (\`bench/cm/framing.c\`, linked with"
    echo "\`--gc-sections\`): $flash_list."
    echo
    echo "## Cortex-M (QEMU), per stream"
    echo
    echo "\`bench/cm/bench_cm.c\` runs on QEMU's \`mps2-an386\` (a Cortex-M4) with \`-icount shift=0\`:"
    echo "the virtual clock advances one nanosecond per executed instruction, and the board's"
    echo "CMSDK APB timer 0 counts at 25 MHz of that clock, so one tick is 40 instructions (a"
    echo "calibration loop of exactly 2,000,000 instructions reads ${cm[$K4,calibration]}). M0+ images are"
    echo "ARMv6-M code (\`-mcpu=cortex-m0plus\`): the M4 executes it instruction for instruction, and"
    echo "QEMU has no M0+ board. Built with \`$(cm_cmd cortex-m4 O2)\`"
    echo "(and \`-mcpu=cortex-m4 -Os\`, \`-mcpu=cortex-m0plus -Os\`), run with \`qemu-system-arm -M"
    echo "mps2-an386 -icount shift=0 -semihosting-config enable=on,target=native -kernel ...\`."
    echo
    echo "- **Per byte**: a whole 256 KiB stream, timer read before and after (exact to 40 in"
    echo "  millions). Byte loops (store-and-sum, classic parser, \`tase_rx_push\`) are shown net of"
    echo "  the caller's loop: the same loop around a call of an empty function is subtracted."
    echo "  \`tase_rx_feed\` is called once per 4096, 64 or 16 bytes (loop included)."
    echo "- **Longest call, exact**: every call of the first 8 KiB of the stream is timed once"
    echo "  (+-39 instructions); then the stream is replayed and each call whose coarse count is within"
    echo "  79 of the largest (no other can be longer) is repeated 200 times from a copy of the"
    echo "  receiver taken before it, against the same loop around an empty function: the"
    echo "  difference / 200 is exact after rounding (error < 0.4). At most 64 such calls per stream"
    echo "  are counted exactly (the column says how many of how many candidates)."
    echo
    for t in "${targets[@]}"; do
        set -- $t
        key="$1-$2"
        echo "### $1 -$2"
        echo
        echo "| stream | classic net/byte | push net/byte | feed 4096 /byte | feed 64 /byte | feed 16 /byte | longest push (call #, exact/candidates) | longest feed 16 | longest feed 64 | frames |"
        echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        for s in "${streams[@]}"; do
            echo "| $s | $(net classic "$s" "$key") | $(net tase_rx_push "$s" "$key") | $(perb tase_rx_feed/4096 "$s" "$key") | $(perb tase_rx_feed/64 "$s" "$key") | $(perb tase_rx_feed/16 "$s" "$key") | ${cm[$key,max,tase_rx_push,$s]} (#${cm[$key,maxat,tase_rx_push,$s]}, ${cm[$key,maxn,tase_rx_push,$s]}) | ${cm[$key,max,tase_rx_feed/16,$s]} | ${cm[$key,max,tase_rx_feed/64,$s]} | ${cm[$key,frames,tase_rx_push,$s]} |"
        done
        echo
    done
    echo "Push-path stack by painting (M4 -Os, bytes below the caller's stack pointer, trivial"
    echo "callback):$(for s in "${streams[@]}"; do printf ' %s %s;' "$s" "${cm[$K4s,stack,tase_rx_push/$s]}"; done)"
    echo
    echo "## Byte at a time beside a classic parser (x86-64, one program run per stream)"
    echo
    echo "\`bench_rx STREAM 4096 compare\` (\`bench/bench_rx.c\`, built with"
    echo "\`$build_cmd\`)"
    echo "feeds each stream, in one run, to the classic single-state parser of"
    echo "\`bench/classic_rx.c\` (a switch over sync1, sync2, sync3, Size, body and checksum, no"
    echo "window: it loses the frames behind a false sync or a corrupted Size), to the"
    echo "store-and-sum loop there (store the byte, add it to a sum: the floor of any byte-at-a-time"
    echo "receiver), to \`tase_rx_push()\` one byte per call, and to \`tase_rx_feed()\` in 4096-byte"
    echo "calls. Instructions per byte = callgrind's inclusive cost of each function (the frame"
    echo "callback included) / stream bytes; the caller's loop is not counted."
    echo
    echo "| stream | bytes | frames (classic) | frames (tase) | store-and-sum | classic parser | tase_rx_push | push / classic | tase_rx_feed (4096) |"
    echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    printf '%s\n' "${cmp_rows[@]}"
    echo
    echo "## Per stream and chunk size (x86-64)"
    echo
    echo "**Instructions per byte** are counted by"
    echo "\`valgrind --tool=callgrind --toggle-collect=tase_rx_feed bench_rx STREAM CHUNK once\`"
    echo "(\`--toggle-collect=tase_rx_push\` for chunk 1, which feeds one byte per"
    echo "\`tase_rx_push()\` call): only instructions executed inside that function (and what it"
    echo "calls: libc's memchr/memcpy, the frame callback) count, divided by the stream length."
    echo "They are repeatable on any machine with the same compiler and libc. The cross-check"
    echo "column counts the whole program instead and subtracts a run that builds the stream but"
    echo "feeds nothing (it also includes \`tase_rx_init\`/\`tase_rx_flush\`). **MB/s** is wall clock"
    echo "on a shared machine: informational only. CHUNK is the number of bytes per call: 4096 is a"
    echo "\`read()\` from a tty or socket, 64 a DMA half-buffer, 1 a firmware that feeds each byte"
    echo "from its UART interrupt ring. Variant **framing** = a trivial callback; **dispatch** ="
    echo "frames through \`tase_dispatch_frame\` (typed decode + one trivial handler per packet"
    echo "type)$( [ ${#variants[@]} -eq 1 ] && echo ": not measured, include/tase/dispatch.h is not in this tree yet")."
    echo
    echo "| stream | variant | bytes | frames | instr/byte chunk 4096 | chunk 64 | chunk 1 | cross-check (4096) | MB/s chunk 4096 | MB/s chunk 1 |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    printf '%s\n' "${rows[@]}"
    echo
    echo "On x86-64 (gcc -O2, callgrind) the telemetry stream costs $t_push instructions per byte"
    echo "through \`tase_rx_push\` against the classic parser's $t_classic (store-and-sum floor"
    echo "$t_store), and $tele per byte through 4096-byte \`tase_rx_feed\` calls$( [ -n "${tele_dispatch:-}" ] && echo " ($tele_dispatch with typed decode and dispatch)")."
    echo "Where the telemetry stream's instructions go (chunk 4096, exclusive cost per function;"
    echo "static functions of src/tase_frame.c that gcc inlined are counted in their caller):"
    echo
    echo "$profile"
} > "$out"
if [ -n "$kept" ]; then
    printf '\n%s\n' "$kept" >>"$out"
fi
echo "wrote $out"

{
    echo "# Worst case per call"
    echo
    echo "<!-- GENERATED by bench/bench.sh; do not edit by hand. -->"
    echo "Generated by \`bench/bench.sh\` with $(arm-none-eabi-gcc --version | head -1) and"
    echo "$(qemu-system-arm --version | head -1)."
    echo
    echo "Exact instruction counts of one call (Thumb instructions, QEMU \`mps2-an386\` with"
    echo "\`-icount shift=0\`; M0+ is ARMv6-M code run on that board, see PERFORMANCE.md), each on"
    echo "the input built to be its worst, named in the last column. A call is counted as a caller"
    echo "makes it (its argument setup and branch included), from a state put back before every"
    echo "repetition (\`bench/cm/measure.c\`: 200 repetitions against the same loop around an empty"
    echo "function, exact after rounding). Callbacks are trivial (add a length to a counter)."
    echo "Programs: \`bench/cm/timing*.c\` (\`timing.c\` and its parts, built with \`$(timing_cmd cortex-m4 O2)\`) and, for"
    echo "\`tase_rx_push\`/\`tase_rx_feed\`, \`bench/cm/bench_cm.c\` (the longest call over every"
    echo "call of the first 8 KiB of each stream of PERFORMANCE.md)."
    echo
    echo "| function | M4 -O2 | M0+ -Os | worst-case input |"
    echo "|---|---:|---:|---|"
    for f in tase_rx_push tase_rx_feed/16 tase_rx_feed/64; do
        read -r a a_at <<<"$(maxof "$f" cortex-m4-O2)"
        read -r b b_at <<<"$(maxof "$f" cortex-m0plus-Os)"
        echo "| \`$f\` | $a | $b | one call of the $a_at stream (M4), $b_at (M0+); bench/streams.h |"
    done
    for f in "${timing_fns[@]}"; do
        echo "| \`$f\` | ${tm[cortex-m4-O2,$f]} | ${tm[cortex-m0plus-Os,$f]:-?} | $(both_inputs "$f") |"
    done
    echo
    echo "\`tase_rx_flush\` and a settling \`tase_rx_tick\` decide the whole window at once (end of"
    echo "input); every other receiver call spends at most the scan's credit: a capped bank and a"
    echo "fixed amount per byte it takes in (include/tase/frame.h, COST), so a \`tase_rx_feed\` of n"
    echo "bytes costs about the longest \`tase_rx_push\` plus n - 1 bytes' credit and its copying."
    echo "The credit is counted in units of about one Cortex-M4 instruction, and some work is"
    echo "charged less than it costs (docs/DESIGN.md, \"The units under-charge\"): the figures of the"
    echo "receiver are the longest calls found on the inputs named, not proven bounds."
    echo
    echo "How the inputs are built (\`bench/cm/timing*.c\`):"
    echo
    echo "- **Per packet**: the codec, the typed senders and the typed requests are measured on every"
    echo "  packet of the schema at its longest form (every member set; CAMERA_PASS with 249 camera"
    echo "  bytes, 253 data bytes) and the slowest packet is named."
    echo "- **Fake port**: the send path and the roles run over an in-memory port whose write() copies"
    echo "  what it is given to RAM and takes it all, whose read() hands over scripted bytes at once"
    echo "  (at most as many as asked), and whose now_ms() is a constant. The port's own cost is"
    echo "  inside the count, as the input says; a real driver's write() and read() replace it."
    echo "  \`tase_host_transact*\` block on the port's read() by design; measured here with a port"
    echo "  that has the reply waiting, they are one request, its reply and the polls around it."
    echo "  The rows without a suffix hold only for a port that takes whole writes and hands over"
    echo "  whole reads: the \`/bytewise\` rows are the same calls on the same port taking 1 byte a"
    echo "  write() and handing over 1 byte a read(), the \`/stalled\` ones on a port that takes"
    echo "  nothing or reads nothing while its clock stands still (below the list)."
    echo "- **Roles**: the gimbal has three ports with receivers; every setup packet is tried at each"
    echo "  length it takes, with data bytes 0x01 and 0xFF (\"do not change\"), with typed and with byte"
    echo "  callbacks (trivial: accept, leave the data; telemetry is a struct left zero or a memset)."
    echo "  \`tase_gimbal_poll\` is tried with the default rates and with rate 1, 3 or 255 on all nine"
    echo "  streams at a capacity of 1 B/s or unlimited, at moments from 100 ms to 2^31 - 1 ms after"
    echo "  init; \`tase_gimbal_service\` runs in the set-up and at the moment found worst for the"
    echo "  poll, and reads its cap: 64 reads of 64 bytes on each of the 3 ports"
    echo "  (\`TASE_GIMBAL_SERVICE_READS\`, tase/config.h, at its default; at 1 a call reads 64 bytes a port)."
    echo "  \`tase_host_poll\` re-sends every packet the host may re-send (at its longest and as a"
    echo "  query) and fails the longest request, alone or just after an identical one timed out."
    echo "- **Searches**: where a call's cost depends on what came before it, every state of a"
    echo "  search is timed once (to the timer's 40-instruction tick) and those within a tick of the"
    echo "  longest are counted exactly (no other can be longer): \`tase_can_rx_feed\` on every CAN"
    echo "  frame of the first 3072 bytes of every stream of PERFORMANCE.md split from each of its bytes"
    echo "  0..7, \`tase_host_feed\` with the reply after the first 16 * k bytes of every stream"
    echo "  (k = 0..127), \`tase_gimbal_poll\` over its set-ups and moments."
    echo "- **Addresses**: where a call sums, copies, compares or scans bytes (a word loop, or the C"
    echo "  library's memcpy, memchr, strcmp: other paths at other alignments), its buffers are placed"
    echo "  at each address mod 4 or mod 8 and the row names the worst (the sum and the frame encoders,"
    echo "  the packet encoders' output and camera bytes, the senders' data, CAN frames, KLV packets and"
    echo "  the scanner, candump lines, schema names); the other rows, the fake port's RAM among them,"
    echo "  hold for the bench image's own placement."
    echo "- **O(n) calls** (feed, service, write_all, candump_parse, ...) have no worst case"
    echo "  independent of their input's length: the count holds for the input named (one frame, one"
    echo "  read, the costliest line tried), and grows with it as their headers state."
    echo "- **Numbers** (KLV units, \`tase/units.h\`, the GPS status word): the slowest of a spread of"
    echo "  inputs (zero, signs, fractions, extremes, a subnormal, huge values, NaN, infinity, angles"
    echo "  of 360 to 1e9 degrees whose whole turns are taken off, and the slowest a review's random"
    echo "  search found for each function); both cores here use soft-float, whose library calls are"
    echo "  part of the call. Functions defined \`static inline\` in a header are called through a"
    echo "  noinline wrapper, as said in the input."
    echo "- **Bare-metal port** (port/baremetal, \`bench/cm/timing_port.c\`): a 512-byte ring (the"
    echo "  example of tase/bm_uart.h) and a 256-byte DMA buffer (tase/bm_dma.h's), trivial hooks (tx"
    echo "  copies to RAM, millis reads a variable). \`tase_bm_uart_rx_isr\` is the cost of one byte:"
    echo "  an RXNE interrupt pays it once per byte it takes. The two polls drain into a receiver, so"
    echo "  their rows include the receiver's calls (\`tase_rx_feed\`, \`tase_rx_tick\`, rows of their"
    echo "  own): the worst over a window at every 32-byte offset of the first 8 KiB of every stream"
    echo "  of PERFORMANCE.md (the receiver as the bytes before it left it) and a poll that finds"
    echo "  nothing after 100 s of quiet; their \`/own\` rows are the same call less those receiver"
    echo "  calls, made directly on the same state. Both polls are O(ring or buffer size): the row"
    echo "  holds for the size named, and a poll takes at most one size's worth of bytes. The port's"
    echo "  \`tase_bm_uart_ops\` functions (write, read, now_ms) are measured through the table;"
    echo "  the other ports (POSIX UART, SocketCAN) run on an OS and are not measured here: their"
    echo "  bounds are times, in each header's contract (a read's timeout, the write bound, close's"
    echo "  drain), and their other calls make a fixed number of system calls and never wait."
    echo
    echo "**Partial writes and reads.** A port's write() may take part of what it is given and its"
    echo "read() may hand over less than asked (tase/port.h); the library calls them again, so every"
    echo "call that writes a frame (the senders, a request, its re-send, a gimbal's echo and telemetry)"
    echo "or reads one (\`tase_host_transact*\`) costs more with such a port. Measured with the fake"
    echo "port taking 1 byte a write() and handing over 1 byte a read() (the \`/bytewise\` rows):"
    echo "every further write() call costs $(per_call tase_port_send_frame 244 cortex-m4-O2) instructions on M4 -O2 and"
    echo "$(per_call tase_port_send_frame 244 cortex-m0plus-Os) on M0+ -Os (\`tase_port_send_frame\`: its \`/bytewise\` row less its own,"
    echo "over the 244 further calls of a 261-byte frame it otherwise writes in 17 pieces; through"
    echo "\`tase_port_write_all\`, over 260: $(per_call tase_port_write_all 260 cortex-m4-O2) and $(per_call tase_port_write_all 260 cortex-m0plus-Os)), this fake port's write() and"
    echo "now_ms() included (a real driver's replace them). A call that writes a frame of n bytes in"
    echo "k write() calls (1 for \`tase_port_write_all\`, n / 16 rounded up for the senders, which"
    echo "write 16-byte pieces) costs about n - k times that more. Every further read() in"
    echo "\`tase_host_transact\` (a \`tase_host_service\` of 1 byte and a poll) costs $(per_read cortex-m4-O2) on M4"
    echo "-O2 and $(per_read cortex-m0plus-Os) on M0+ -Os (its \`/bytewise\` row less its own and less the writes' share,"
    echo "\`tase_port_send_frame\`'s, over the 256 further reads of a 261-byte reply it otherwise"
    echo "reads in 5)."
    echo
    echo "**A port that stalls.** A read() that returns nothing at once while the port's clock"
    echo "stands still never lets the request of \`tase_host_transact*\` time out: the wait ends after"
    echo "\`TASE_PORT_WRITE_SPINS\` such loops in a row (tase/config.h, default 2^20) with"
    echo "TASE_ETIMEOUT; a write() that takes nothing under such a clock is called"
    echo "\`TASE_PORT_WRITE_SPINS\` times by \`tase_port_write_all\` and the senders before they give"
    echo "up (tase/port_io.h). These calls are bounded in loops, not by a fixed count of instructions:"
    echo "the \`/stalled\` rows are one run of each at the default (timed once, to 40 instructions),"
    echo "and scale with the setting. With a clock that moves, their time bounds end them instead"
    echo "(the request's timeout, \`TASE_PORT_WRITE_TIMEOUT_MS\`), after as many loops as fit."
    echo
    unmeasured=()
    for f in "${public_fns[@]}"; do
        case " ${timing_fns[*]} tase_rx_push tase_rx_feed " in
            *" $f "* | *" $f/"*) ;;
            *) unmeasured+=("\`$f\`") ;;
        esac
    done
    if [ ${#unmeasured[@]} -eq 0 ]; then
        echo "Every public function of src/ and of port/baremetal (every function the headers of"
        echo "include/tase/ and port/baremetal/tase/ declare) is measured above."
    else
        echo "Public functions of src/ and port/baremetal not measured here yet (their headers state"
        echo "their bounds in O() terms):"
        echo
        echo "${unmeasured[*]}"
    fi
} > "$timing_out"
echo "wrote $timing_out"
