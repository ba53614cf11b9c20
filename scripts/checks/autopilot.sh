#!/usr/bin/env bash
# Build the example autopilot firmware (examples/autopilot) for Cortex-M4F
# and fly its SPOI mission under QEMU's mps2-an386 against a live tase-sim:
# the simulator serves a pty, QEMU connects the guest's UART0 to it, and
# both run on the real clock (no -icount: SysTick follows host time).
# Passes only when the image reports PASS and exits 0, and the simulator's
# log shows the PACKET_RATE setting and the SPOI command the image sent.
# Everything it starts is stopped and the link removed, also on failure.
# Packages: scripts/packages.d/firmware.txt.
# Usage: scripts/checks/autopilot.sh TASE_SIM [outdir [TASE]]
# (TASE, the CLI, defaults to the tase beside TASE_SIM)
set -uo pipefail
. "$(dirname "$0")/../lib.sh"
sim=${1:?usage: scripts/checks/autopilot.sh TASE_SIM [outdir [TASE]]}
out=${2:-$TASE_ROOT/build-autopilot}
cli=${3:-$(dirname "$sim")/tase}
[ -x "$cli" ] || { echo "FAIL: no tase CLI at $cli"; exit 1; }
dir=$(mktemp -d)
sim_pid=""
qemu_pid=""
cleanup() {
    [ -n "$qemu_pid" ] && kill "$qemu_pid" 2>/dev/null
    [ -n "$sim_pid" ] && kill "$sim_pid" 2>/dev/null
    wait 2>/dev/null
    rm -rf "$dir"
}
trap cleanup EXIT
fail() {
    echo "FAIL: $*"
    echo "--- image output:"; cat "$dir/image.log" 2>/dev/null
    echo "--- tase-sim log:"; cat "$dir/sim.log" 2>/dev/null
    exit 1
}

# build DIR [CMAKE_ARG...]: the image in DIR
build() {
    local b=$1
    shift
    cmake -S "$TASE_ROOT/examples/autopilot" -B "$b" \
          -DCMAKE_TOOLCHAIN_FILE="$TASE_ROOT/cmake/arm-none-eabi.cmake" -DTASE_CPU=cortex-m4 \
          "$@" >/dev/null || exit 1
    cmake --build "$b" -j2 || exit 1
}
# start_sim: a simulator serving $dir/gimbal (sim_pid), its log sim.log;
# --seconds bounds it even if this script is killed outright. Ready once
# its first log line is out (written after the pty's line settings): the
# link appears before those, and a simulator stopped in between had the
# bytes sent to it meanwhile flushed by them (CI: 8 frames fewer received
# than sent)
start_sim() {
    "$sim" --link "$dir/gimbal" --seconds 150 >"$dir/sim.log" 2>&1 &
    sim_pid=$!
    for _ in $(seq 100); do
        [ -L "$dir/gimbal" ] && grep -q '^tase-sim: simulated gimbal on' "$dir/sim.log" && break
        sleep 0.05
    done
    [ -L "$dir/gimbal" ] || fail "tase-sim did not create its link"
    grep -q '^tase-sim: simulated gimbal on' "$dir/sim.log" || fail "tase-sim did not start"
}
# stop_sim: so that it writes its closing counters
stop_sim() {
    kill "$sim_pid" 2>/dev/null
    wait "$sim_pid" 2>/dev/null
    sim_pid=""
}
# image SECONDS ELF LOG QEMU_ARG...: QEMU's mps2-an386 running ELF in the
# background (qemu_pid: its timeout, which cleanup stops), output in LOG;
# image_wait waits for it and returns its status (the image bounds its own
# mission; SECONDS a hung guest)
image() {
    local secs=$1 elf=$2 log=$3
    shift 3
    timeout "$secs" qemu-system-arm -M mps2-an386 -nographic -monitor none "$@" \
        -semihosting-config enable=on,target=native -kernel "$elf" >"$log" 2>&1 &
    qemu_pid=$!
}
image_wait() {
    local rc
    wait "$qemu_pid"
    rc=$?
    qemu_pid=""
    return "$rc"
}
to_sim=(-chardev "serial,id=gimbal,path=$dir/gimbal" -serial chardev:gimbal)

build "$out"
start_sim

# The image bounds its own mission (30 s); timeout covers a hung guest.
# The gimbal "boots" 2.5 s after the autopilot (the simulator stopped
# until then): the image asks again until it answers (a review: one
# unanswered request ended the mission).
kill -STOP "$sim_pid"
image 120 "$out/tase_autopilot.elf" "$dir/image.log" "${to_sim[@]}"
sleep 2.5
kill -CONT "$sim_pid"
image_wait
rc=$?
stop_sim

cat "$dir/image.log"
[ "$rc" -eq 0 ] || fail "the image exited with status $rc"
grep -q '^PASS: 0 of [0-9]* checks failed' "$dir/image.log" || fail "the image did not report PASS"
grep -q '^gimbal not answering yet: asking again' "$dir/image.log" ||
    fail "the image did not wait for the gimbal to boot"

# The simulator saw the setup exchange and the SPOI command the image sent.
grep -q 'PACKET_RATE: port 2 (this link) angle 20/s, rate 10/s, georef 10/s' "$dir/sim.log" ||
    fail "tase-sim's log lacks the PACKET_RATE setting"
spoi=$(sed -n 's/^SPOI_CMD at \([-0-9.]*, [-0-9.]*, [-0-9.]* m\), echo confirmed.*/\1/p' \
       "$dir/image.log")
[ -n "$spoi" ] || fail "the image did not report its SPOI command"
grep -q "SPOI_CMD: pointing at $spoi" "$dir/sim.log" ||
    fail "tase-sim's log lacks the SPOI command at $spoi"
frames=$(sed -n 's/.*stopped: \([0-9]*\) frames in.*/\1/p' "$dir/sim.log")
sent=$(sed -n 's/^host role: \([0-9]*\) frames sent.*/\1/p' "$dir/image.log")
[ -n "$frames" ] && [ "$frames" = "$sent" ] ||
    fail "tase-sim received ${frames:-?} frames, the image sent ${sent:-?}"
echo "--- tase-sim log:"
cat "$dir/sim.log"

# A gimbal that never answers (its UART wired to nothing): the mission is
# aborted at its first request and the summary reports no step after it
# (a review: it confirmed the PACKET_RATE, NAV_SOURCE and SPOI echoes of
# steps never reached).
image 60 "$out/tase_autopilot.elf" "$dir/mute.log" -serial null
image_wait
rc=$?
cat "$dir/mute.log"
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "with no gimbal the image exited with status $rc (want a failure)"
grep -q '^FAIL SYSTEM_VERSION query: timed out' "$dir/mute.log" ||
    fail "with no gimbal: no 'FAIL SYSTEM_VERSION query: timed out'"
! grep -q 'echo confirmed' "$dir/mute.log" ||
    fail "with no gimbal the summary confirms echoes of steps never reached"
grep -q '^FAIL mission completed (the step reached): got 0, want' "$dir/mute.log" ||
    fail "with no gimbal: the mission check does not name the step reached"
grep -q 'NAV_SOURCE: external attitude and GPS, echo confirmed' "$dir/image.log" ||
    fail "the mission did not set NAV_SOURCE (the simulator starts with its own)"

# A gimbal that stops reporting while the mission tracks (the simulator
# stopped for 3 s once the SPOI command reached it): the image aborts
# after TELEMETRY_LOST_MS without a telemetry frame (a review: a 3 s
# silence passed unnoticed).
rm -f "$dir/gimbal"
start_sim
image 120 "$out/tase_autopilot.elf" "$dir/stall.log" "${to_sim[@]}"
for _ in $(seq 400); do
    grep -q 'SPOI_CMD: pointing at' "$dir/sim.log" && break
    sleep 0.05
done
grep -q 'SPOI_CMD: pointing at' "$dir/sim.log" || fail "the stall run: no SPOI command reached tase-sim"
sleep 1
kill -STOP "$sim_pid"
sleep 3
kill -CONT "$sim_pid"
image_wait
rc=$?
stop_sim
cat "$dir/stall.log"
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] ||
    fail "with the gimbal silent for 3 s the image exited with status $rc (want a failure)"
grep -q '^FAIL gimbal telemetry stopped' "$dir/stall.log" ||
    fail "with the gimbal silent for 3 s: no 'FAIL gimbal telemetry stopped'"
grep -q '^SPOI_CMD at .*echo confirmed' "$dir/stall.log" ||
    fail "the stall run did not reach tracking before the silence"
# The mission across the clock's wrap: the board's millisecond clock
# starts 4 s before 2^32 (a review: the mission limit compared the clock
# itself, so a clock not near 0 at the start aborted it at once, and the
# flight model jumped at the wrap).
# The gimbal has external navigation already (set by tase before the
# image starts): the image queries NAV_SOURCE and does not send it again
# (no temporary byte: a gimbal may store it in flash every time).
build "$out/wrap" -DAUTOPILOT_CLOCK_START_MS=4294963296 >/dev/null
rm -f "$dir/gimbal"
start_sim
"$cli" send NAV_SOURCE external_attitude=1 external_gps=1 --serial "$dir/gimbal" >"$dir/nav.log" 2>&1 ||
    fail "tase send NAV_SOURCE: $(cat "$dir/nav.log")"
image 120 "$out/wrap/tase_autopilot.elf" "$dir/wrap.log" "${to_sim[@]}"
image_wait
rc=$?
stop_sim
cat "$dir/wrap.log"
[ "$rc" -eq 0 ] && grep -q '^PASS: 0 of [0-9]* checks failed' "$dir/wrap.log" ||
    fail "the mission across the clock's 2^32 ms wrap did not pass (status $rc)"
grep -q 'NAV_SOURCE: external attitude and GPS, already (not sent)' "$dir/wrap.log" ||
    fail "the image did not find NAV_SOURCE already set"
n=$(grep -c 'NAV_SOURCE: attitude from' "$dir/sim.log")
[ "$n" -eq 1 ] || fail "tase-sim's log shows NAV_SOURCE set $n times, want once (by tase)"
echo "autopilot mission against tase-sim: ok; with no gimbal: aborted, nothing confirmed;" \
     "gimbal silent 3 s while tracking: aborted; across the clock's wrap with NAV_SOURCE set: ok"
