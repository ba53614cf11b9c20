#!/usr/bin/env bash
# End-to-end test of the bench tools: a real tase-sim process on a pty and
# the tase command line against it, plus every error path.
# Usage: scripts/tools-e2e.sh TASE TASE_SIM   (registered by tests/checks/tools.cmake)
set -uo pipefail
TASE=$1
SIM=$2
dir=$(mktemp -d)
sim_pid=""
fails=0
cleanup() {
    [ -n "$sim_pid" ] && kill -CONT "$sim_pid" 2>/dev/null && kill "$sim_pid" 2>/dev/null
    wait 2>/dev/null
    rm -rf "$dir"
}
trap cleanup EXIT

ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fails=$((fails + 1)); }

# check NAME CONDITION-COMMAND...: a named assertion
check() {
    local name=$1
    shift
    if "$@"; then ok "$name"; else bad "$name"; fi
}

# quiet CMD...: run CMD, its output to the log only
quiet() { "$@" >>"$dir/quiet.log" 2>&1; }

# json_int LINE KEY: the integer value of "KEY": in a JSON line
json_int() { sed -n "s/.*\"$2\":\(-\{0,1\}[0-9][0-9]*\).*/\1/p" <<<"$1"; }

# near A B TOL: |A - B| <= TOL (integers)
near() { local d=$(($1 - $2)); [ "${d#-}" -le "$3" ]; }

# expect_error NAME STATUS PATTERN CMD...: CMD exits with STATUS (any
# non-zero if STATUS is "nz") and prints exactly one line on stderr that
# matches PATTERN.
expect_error() {
    local name=$1 want=$2 pat=$3 rc lines
    shift 3
    "$@" >"$dir/out" 2>"$dir/err" </dev/null
    rc=$?
    lines=$(wc -l <"$dir/err")
    if { [ "$want" = nz ] && [ $rc -ne 0 ] || [ "$rc" = "$want" ]; } &&
        [ "$lines" -eq 1 ] && grep -q -- "$pat" "$dir/err"; then
        ok "$name: exit $rc, $(cat "$dir/err")"
    else
        bad "$name: exit $rc, $lines stderr lines: $(head -c 300 "$dir/err")"
    fi
}

start_sim() {
    "$SIM" --quiet --link "$dir/gimbal" --klv-link "$dir/klv" --seconds 120 >"$dir/sim.log" 2>&1 &
    sim_pid=$!
    for _ in $(seq 100); do
        [ -L "$dir/gimbal" ] && [ -L "$dir/klv" ] && return 0
        sleep 0.05
    done
    echo "tase-sim did not start: $(cat "$dir/sim.log")"
    exit 1
}

L=(--serial "$dir/gimbal")
start_sim

# ---- version query ----
v=$("$TASE" query SYSTEM_VERSION "${L[@]}" --json)
check "query SYSTEM_VERSION answers with the version and cameras" \
    grep -q '"name":"SYSTEM_VERSION","size":42,"fields":{"major":2,"minor":5,.*"camera_a":68,' <<<"$v"

# ---- setup echo and persistence ----
e=$("$TASE" send PACKET_RATE angle_1=20 rate_1=5 geo_ref_1=2 "${L[@]}" --json)
check "send PACKET_RATE prints the gimbal's echo" \
    test "$(json_int "$e" angle_1)/$(json_int "$e" rate_1)/$(json_int "$e" geo_ref_1)" = 20/5/2
q=$("$TASE" query PACKET_RATE "${L[@]}" --json)
check "PACKET_RATE persists (query after set)" test "$(json_int "$q" angle_1)" = 20
check "read-modify-write kept the other ports' rates" test "$(json_int "$q" angle_2)" = 10
mon=$("$TASE" monitor "${L[@]}" --json --seconds 2)
na=$(grep -c '"name":"GIMBAL_ANGLE"' <<<"$mon")
nr=$(grep -c '"name":"GIMBAL_RATE"' <<<"$mon")
check "telemetry follows PACKET_RATE (2 s: $na angle ~40, $nr rate ~10)" \
    eval 'near $na 40 10 && near $nr 10 4'

# ---- pan/tilt position command ----
"$TASE" send GIMBAL_CMD pan=3000 tilt=-1500 flags=0xA0 "${L[@]}" >/dev/null
sleep 2.5
last=$("$TASE" monitor "${L[@]}" --json --count 40 | grep '"GIMBAL_ANGLE"' | tail -1)
check "GIMBAL_CMD position moves the gimbal to 30/-15 deg ($last)" \
    eval 'near "$(json_int "$last" pan)" 3000 2 && near "$(json_int "$last" tilt)" -1500 2'
rate=$("$TASE" monitor "${L[@]}" --json --count 40 | grep '"GIMBAL_RATE"' | tail -1)
mode=$(json_int "$rate" mode)
check "GIMBAL_RATE mode: stabilised, deployed, position ($mode)" test "$mode" = $((128 + 64 + 1))

# ---- no-go zone: a rate command stops at its edge ----
"$TASE" send AXIS_SETTING pan_nogo_center=6000 pan_nogo_range=2000 "${L[@]}" >/dev/null
"$TASE" send GIMBAL_CMD pan=5000 tilt=0 flags=0x10 "${L[@]}" >/dev/null
sleep 1.5
last=$("$TASE" monitor "${L[@]}" --json --count 40 | grep '"GIMBAL_ANGLE"' | tail -1)
check "rate command stops at the pan no-go edge 50 deg ($last)" \
    near "$(json_int "$last" pan)" 5000 2
ax=$("$TASE" query AXIS_SETTING "${L[@]}" --json)
check "AXIS_SETTING 0xFF fields kept their values (tilt no-go 90/60)" \
    test "$(json_int "$ax" tilt_nogo_center)/$(json_int "$ax" tilt_nogo_range)" = 9000/6000

# ---- SPOI: host at 0/0, 100 m up, heading north; target 100 m east on the ground ----
# (each step is checked, so a failure names its cause, not just the angle)
check "HOST_GPS_DATA sent" quiet "$TASE" send HOST_GPS_DATA lat=0 lon=0 height=10000 valid=1 "${L[@]}"
check "HOST_ATTITUDE sent" quiet "$TASE" send HOST_ATTITUDE roll=0 pitch=0 yaw=0 "${L[@]}"
check "AXIS_SETTING pan no-go range 0 echoed" quiet "$TASE" send AXIS_SETTING pan_nogo_range=0 "${L[@]}"
# 100 m east at the equator = 100 / 6371000 rad = 3237.58 mas
check "SPOI_CMD echoed" quiet "$TASE" send SPOI_CMD lat=0 lon=3238 height=0 flags=0x80 "${L[@]}"
sleep 2
last=$("$TASE" monitor "${L[@]}" --json --count 40 | grep '"GIMBAL_ANGLE"' | tail -1)
check "SPOI points at 90 deg pan, -45 deg tilt ($last)" \
    eval 'near "$(json_int "$last" pan)" 9000 3 && near "$(json_int "$last" tilt)" -4500 3'
sq=$("$TASE" query SPOI_CMD "${L[@]}" --json)
check "SPOI_CMD query returns the SPOI ($sq)" test "$(json_int "$sq" lon)" = 3238

# ---- retract/deploy: echoed when the move completes ----
"$TASE" send RETRACT_DEPLOY_CMD deploy=0 "${L[@]}" >/dev/null
echo_line=$("$TASE" monitor "${L[@]}" --json --seconds 3.5 | grep '"RETRACT_DEPLOY_CMD"' | head -1)
check "RETRACT_DEPLOY_CMD echoed after the retraction ($echo_line)" \
    test "$(json_int "$echo_line" deploy)" = 0

# ---- camera command changes the reported field of view ----
"$TASE" send CAMERA_CMD camera=0 hfov=1000 focus=0 exposure=255 shutter_speed=255 bright=255 \
    flags=128 "${L[@]}" >/dev/null
geo=$("$TASE" monitor "${L[@]}" --json --seconds 1.2 | grep '"GEOREFERENCE_DATA"' | tail -1)
check "CAMERA_CMD HFOV 10 deg shows in GEOREFERENCE_DATA" test "$(json_int "$geo" hfov)" = 1000

# ---- KLV output ----
timeout 2.5 cat "$dir/klv" >"$dir/klv.bin" 2>/dev/null
k=$("$TASE" klv "$dir/klv.bin")
nk=$(grep -c '"fields":{"utc"' <<<"$k")
check "KLV output: $nk packets in 2.5 s (about one per 900 ms)" eval '[ $nk -ge 2 ] && [ $nk -le 4 ]'
check "KLV packet carries the simulated pan (90 deg = raw 16384)" \
    grep -q '"pan":1638[3-5],' <<<"$k"

# ---- human-readable monitor ----
t=$("$TASE" monitor "${L[@]}" --count 3)
check "monitor prints readable lines" grep -q '^GIMBAL_ANGLE pan=' <<<"$t"

# ---- timeout: a gimbal that does not answer ----
kill -STOP "$sim_pid"
expect_error "query timeout" 1 "timeout: no answer to PACKET_RATE after 2 attempts" \
    "$TASE" query PACKET_RATE "${L[@]}" --timeout 100 --retries 1
kill -CONT "$sim_pid"

# ---- error paths ----
expect_error "no command" 2 "no command" "$TASE"
expect_error "unknown command" 2 "unknown command 'frobnicate'" "$TASE" frobnicate
expect_error "missing device" 1 "cannot open serial device /nonexistent/tty" \
    "$TASE" query SYSTEM_VERSION --serial /nonexistent/tty
expect_error "monitor missing device" 1 "cannot open serial device" \
    "$TASE" monitor --serial /nonexistent/tty
expect_error "not a tty" 1 "cannot open serial device /dev/null" \
    "$TASE" query SYSTEM_VERSION --serial /dev/null
expect_error "no link" 2 "no link given" "$TASE" query SYSTEM_VERSION
expect_error "both links" 2 "either --serial or --can" \
    "$TASE" monitor --serial "$dir/gimbal" --can can0
expect_error "unknown packet" 2 "unknown packet name 'GIMBAL_FOO'" \
    "$TASE" send GIMBAL_FOO "${L[@]}"
expect_error "unknown field" 2 "GIMBAL_CMD has no field 'yaw'" \
    "$TASE" send GIMBAL_CMD yaw=3 "${L[@]}"
expect_error "value out of range" 2 "bad value '40000' for GIMBAL_CMD.pan" \
    "$TASE" send GIMBAL_CMD pan=40000 "${L[@]}"
expect_error "not a number" 2 "bad value 'ten'" "$TASE" send GIMBAL_CMD pan=ten "${L[@]}"
expect_error "out packet" 2 "GIMBAL_ANGLE is sent by the gimbal" \
    "$TASE" send GIMBAL_ANGLE pan=1 "${L[@]}"
expect_error "query of a command" 2 "GIMBAL_CMD has no zero-length query" \
    "$TASE" query GIMBAL_CMD "${L[@]}"
expect_error "unknown option" 2 "unknown option '--bogus'" "$TASE" monitor --bogus
expect_error "missing option value" 2 "option --baud needs a value" \
    "$TASE" monitor --serial "$dir/gimbal" --baud
expect_error "bad baud" 2 "unsupported baud rate 12345" \
    "$TASE" monitor --serial "$dir/gimbal" --baud 12345
expect_error "bad count" 2 "bad --count value" "$TASE" monitor "${L[@]}" --count 0
expect_error "bad length" 2 "does not accept a data length of 3" \
    "$TASE" send CAMERA_CMD --len 3 "${L[@]}"
expect_error "missing capture" 1 "cannot open /nonexistent.bin" "$TASE" decode /nonexistent.bin
expect_error "missing KLV capture" 1 "cannot open /nonexistent.klv" "$TASE" klv /nonexistent.klv
printf 'this is not candump\n' >"$dir/bad.log"
expect_error "malformed candump" 1 "bad.log:1: not a candump log line" \
    "$TASE" decode --candump "$dir/bad.log"
expect_error "CAN interface missing" 1 "cannot open CAN interface nosuchcan0" \
    "$TASE" monitor --can nosuchcan0
expect_error "sim bad argument" 2 "unknown argument '--bogus'" "$SIM" --bogus
expect_error "sim symlink over a file" 1 "exists and is not a symlink" \
    "$SIM" --link "$dir/sim.log" --seconds 1

# ---- --help on every command ----
for c in monitor send query decode klv list; do
    check "tase $c --help" eval '"$TASE" $c --help | grep -q "^usage: tase $c"'
done
check "tase --help" eval '"$TASE" --help | grep -q "^usage: tase <command>"'
check "tase-sim --help" eval '"$SIM" --help | grep -q "^usage: tase-sim"'

echo "$fails failure(s)"
[ $fails -eq 0 ]
