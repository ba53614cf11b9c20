#!/usr/bin/env bash
# The project's main job: on a machine with no gimbal, build the tools,
# start a simulated TASE gimbal (tase-sim) on a pseudo-terminal and run a
# scripted host session against it with the `tase` command line: queries,
# setup echoes, the bench verbs (point, rate, camera, retract/deploy),
# telemetry with time and units, and the KLV output.
# Exits 0 when every step worked, non-zero (with the reason) otherwise.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
tase_need base python

build="$TASE_ROOT/build"
work=$(mktemp -d)
sim_pid=""
finish() {
    local rc=$?
    if [ -n "$sim_pid" ] && kill "$sim_pid" 2>/dev/null; then
        wait "$sim_pid" 2>/dev/null || true
    fi
    rm -rf "$work"
    if [ $rc -ne 0 ]; then
        echo
        echo "demo FAILED (exit $rc)"
    fi
    exit $rc
}
trap finish EXIT

if [ -t 1 ]; then bold=$'\033[1m' plain=$'\033[0m'; else bold="" plain=""; fi
step() { printf '\n%s== %s%s\n' "$bold" "$*" "$plain"; }
show() { printf '$ %s\n' "$*"; "$@"; }
fail() { echo "demo: $*" >&2; exit 1; }

step "Building the library and the tools (cmake, $(nproc) jobs)"
cmake -S "$TASE_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"$(nproc)" --target tase_cli tase_sim >/dev/null
TASE="$build/tools/tase"
SIM="$build/tools/tase-sim"
echo "built $TASE and $SIM"

step "Starting a simulated gimbal on a pseudo-terminal"
"$SIM" --link "$work/gimbal" --klv-link "$work/klv" >"$work/sim.log" 2>&1 &
sim_pid=$!
for _ in $(seq 100); do
    [ -L "$work/gimbal" ] && break
    sleep 0.05
done
[ -L "$work/gimbal" ] || fail "tase-sim did not start: $(cat "$work/sim.log")"
head -2 "$work/sim.log"
# --record: every command also appends its bytes, both ways and timestamped,
# to one pcap capture (decoded at the end)
link=(--serial "$work/gimbal" --record "$work/session.pcap")

step "Host: who are you? (zero-length SYSTEM_VERSION query, answered by the gimbal)"
show "$TASE" query SYSTEM_VERSION "${link[@]}"
echo "(camera_a=68 is a Sony FCB-EX1010, camera_b=97 a FLIR Photon 320; HFOVs in 1/100 deg)"

step "Host: slow the telemetry down to 5 angle, 2 rate, 1 georef packets per second"
show "$TASE" send PACKET_RATE angle_1=5 rate_1=2 geo_ref_1=1 "${link[@]}"
echo "(the gimbal echoes a setup packet; unspecified fields kept their current values)"

step "Host: point the camera at pan 45 deg, tilt -20 deg, stabilised (GIMBAL_CMD position)"
show "$TASE" point 45 -20 "${link[@]}"
echo "(the verb states the mode; 'tase send GIMBAL_CMD' without flags= is refused)"

step "Telemetry for 3 seconds, with host time and engineering units"
show "$TASE" monitor "${link[@]}" --seconds 3 --time --units | tee "$work/mon.txt"
last=$(grep 'GIMBAL_ANGLE' "$work/mon.txt" | tail -1)
case $last in
    *"GIMBAL_ANGLE pan=4500 (45.00 deg) tilt=-2000 (-20.00 deg) roll=0"*) ;;
    *) fail "the gimbal did not reach pan 45, tilt -20 (last: $last)" ;;
esac
echo "-> the gimbal reached pan 45.00 deg, tilt -20.00 deg (the summary line is on stderr)"

step "Host: pan right at 10 deg/s (GIMBAL_CMD rate), one second of telemetry as JSON"
show "$TASE" rate 10 0 "${link[@]}"
show "$TASE" monitor "${link[@]}" --json --seconds 1.1 | tee "$work/mon.json"
grep -q '"name":"GIMBAL_RATE".*"pan_rate":1000,' "$work/mon.json" ||
    fail "GIMBAL_RATE does not report the commanded 10 deg/s"
show "$TASE" rate 0 0 "${link[@]}"

step "Host: camera B, then camera A zoomed to 10 deg of horizontal field of view"
show "$TASE" camera B "${link[@]}"
show "$TASE" camera A --hfov 10 "${link[@]}"
echo "(every other camera setting goes as the spec's \"do not change\" value)"

step "Host: a setting the gimbal refuses is not a success (exit 3 names the field)"
echo "\$ $TASE send AXIS_SETTING pan_max_rate=0 ${link[*]}"
rc=0
"$TASE" send AXIS_SETTING pan_max_rate=0 "${link[@]}" || rc=$?
[ $rc = 3 ] || fail "a refused AXIS_SETTING exited $rc, not 3"
echo "-> exit 3: the gimbal kept its max rate"

step "Host: retract the gimbal and wait for the echo that says the move is complete"
show "$TASE" retract "${link[@]}" --wait 5
show "$TASE" deploy "${link[@]}" --wait 5

step "KLV metadata output (second pty, one packet about every 900 ms)"
timeout 2 cat "$work/klv" >"$work/klv.bin" 2>/dev/null || true
echo "\$ $TASE klv $work/klv.bin"
"$TASE" klv "$work/klv.bin" >"$work/klv.json"
grep -q '"fields":{"utc"' "$work/klv.json" || fail "no KLV packet decoded"
head -1 "$work/klv.json"
echo "($(wc -l <"$work/klv.json") packet(s) in 2 s; raw values in fields, engineering units in units)"

step "The session as recorded by --record (pcap; Wireshark: tools/wireshark/tase.lua)"
echo "\$ $TASE decode $work/session.pcap | head -3"
"$TASE" decode "$work/session.pcap" >"$work/session.json"
head -3 "$work/session.json"
nin=$(grep -c '"dir":"in"' "$work/session.json" || true)
nout=$(grep -c '"dir":"out"' "$work/session.json" || true)
grep -q '"dir":"in".*"name":"GIMBAL_CMD","size":8,"fields":{"pan":4500,"tilt":-2000,' "$work/session.json" ||
    fail "the recorded session lacks the position command"
echo "($nin packets to the gimbal and $nout from it, each with its capture time in seconds)"

step "Python: the same gimbal and the same capture from a script (python/, docs/PYTHON.md)"
cmake --build "$build" --target tase_python >/dev/null
py=$(sed -n 's/^TASE_PYTHON:FILEPATH=//p' "$build/CMakeCache.txt")
cat >"$work/bench.py" <<'PY'
import sys
import tase

with tase.connect("serial:%s:57600" % sys.argv[1]) as link:
    rates = link.query("PACKET_RATE")          # the host role: echo matching, retries
    print("PACKET_RATE answered:", rates.raw["angle_1"], "angle packets/s")
    link.point(-30, 10)                        # tase point -30 10
    for p in link.packets(timeout=3.0):
        if p.name == "GIMBAL_ANGLE" and abs(p.fields["pan"] + 30) < 0.5:
            print("reached", p)
            break
    else:
        sys.exit("the gimbal did not reach pan -30")
packets = list(tase.read_capture(sys.argv[2]))  # the --record capture above
print("capture: %d packets, first %s %s" % (len(packets), packets[0][1].dir, packets[0][1].name))
PY
echo "\$ PYTHONPATH=$build/python $py bench.py $work/gimbal $work/session.pcap"
PYTHONPATH="$build/python" "$py" "$work/bench.py" "$work/gimbal" "$work/session.pcap"

step "Stopping the simulator; its log of what it was asked to do:"
kill "$sim_pid"
wait "$sim_pid" 2>/dev/null || true
sim_pid=""
cat "$work/sim.log"

step "Demo finished: every step worked"
