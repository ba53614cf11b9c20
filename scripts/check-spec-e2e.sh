#!/usr/bin/env bash
# End-to-end checks of issue 16 (spec fidelity) with the built tools:
#  - `tase decode` prints typed fields for an AXIS_SETTING of 22 bytes
#    (table 22 read as a numbering slip) and of 23 bytes, the same values;
#  - a running tase-sim echoes a PACKET_RATE whose reserved bytes 4, 9, 14
#    were 0xAA/0xBB/0xCC with zeros there, answers a SPOI_CMD echo request
#    with its own flags (SPOI mode in bits 3-7), reports NavHealth with
#    filter mode "normal" and no reserved bit, and CAMERA_TYPE its cameras.
# Frames are built here byte by byte (checksums computed by this script)
# and written to the simulator's pty raw, as a host of any make would.
# Usage: scripts/check-spec-e2e.sh TASE TASE_SIM (tests/checks/spec.cmake)
set -uo pipefail
TASE=$1
SIM=$2
dir=$(mktemp -d)
sim_pid=""
# shellcheck source=scripts/check-lib.sh
. "$(dirname "$0")/check-lib.sh" # ok, bad, check, under_valgrind, check_summary
under_valgrind TASE SIM
cleanup() {
    [ -n "$sim_pid" ] && kill "$sim_pid" 2>/dev/null
    wait 2>/dev/null
    rm -rf "$dir"
}
trap cleanup EXIT

# frame GROUP TYPE BYTE...: one datalink frame (spec 3.1) on stdout
frame() {
    local b sum=0 out=""
    local bytes=(0x00 0xFF 0x5A $(($# - 2 + 2)) "$@")
    for b in "${bytes[@]}"; do sum=$((sum + b)); done
    bytes+=($(((sum >> 8) & 0xFF)) $((sum & 0xFF)))
    for b in "${bytes[@]}"; do out+=$(printf '\\x%02x' $((b))); done
    printf '%b' "$out"
}

# json_int LINE KEY: the integer value of "KEY": in a JSON line
json_int() { sed -n "s/.*\"$2\":\(-\{0,1\}[0-9][0-9]*\).*/\1/p" <<<"$1"; }
# fields LINE: the "fields" object of a JSON line
fields() { sed -n 's/.*"fields":\({[^}]*}\).*/\1/p' <<<"$1"; }

# ---- tase decode: both AXIS_SETTING layouts ----
# no-go zones -180.00 / unchanged / 90.00 / 60.00, max rates 60 60 0xFF,
# accelerations 50 50 0xFF, gains 40 40 0xFF, temporary 1
head12=(0xB9 0xB0 0xFF 0xFF 0x23 0x28 0x17 0x70 0 0 0 0)
tail9=(0x3C 0xFF 0x32 0x32 0xFF 0x28 0x28 0xFF 0x01)
{
    frame 0x48 0x02 "${head12[@]}" 0x3C "${tail9[@]}"      # 22 bytes
    frame 0x48 0x02 "${head12[@]}" 0x3C 0x00 "${tail9[@]}" # 23 bytes
} >"$dir/axis.bin"
out=$("$TASE" decode "$dir/axis.bin")
l22=$(sed -n 1p <<<"$out")
l23=$(sed -n 2p <<<"$out")
want='{"pan_nogo_center":-18000,"pan_nogo_range":65535,"tilt_nogo_center":9000,"tilt_nogo_range":6000,"roll_nogo_center":0,"roll_nogo_range":0,"pan_max_rate":60,"tilt_max_rate":60,"roll_max_rate":255,"pan_max_accel":50,"tilt_max_accel":50,"roll_max_accel":255,"pan_pos_gain":40,"tilt_pos_gain":40,"roll_pos_gain":255,"temporary":1}'
check "decode: 22-byte AXIS_SETTING has typed fields ($l22)" \
    eval '[ "$(json_int "$l22" size)" = 22 ] && [ "$(fields "$l22")" = "$want" ]'
check "decode: 23-byte AXIS_SETTING, the same fields ($l23)" \
    eval '[ "$(json_int "$l23" size)" = 23 ] && [ "$(fields "$l23")" = "$want" ]'

# ---- tase-sim ----
"$SIM" --quiet --link "$dir/gimbal" --seconds 30 >"$dir/sim.log" 2>&1 &
sim_pid=$!
for _ in $(seq 100); do
    [ -L "$dir/gimbal" ] && break
    sleep 0.05
done
[ -L "$dir/gimbal" ] || { echo "tase-sim did not start: $(cat "$dir/sim.log")"; exit 1; }
stty -F "$dir/gimbal" raw -echo || { echo "cannot set the pty raw"; exit 1; }
exec 3<>"$dir/gimbal"
timeout 2.5 cat <&3 >"$dir/raw.bin" &
cat_pid=$!
sleep 0.3
rates=(20 5 2 7 0xAA 10 10 4 8 0xBB 10 10 4 9 0xCC 0)
frame 0x48 0x00 "${rates[@]}" >&3
sleep 0.2
# SPOI 100 m east of 0/0 on the ground, echo requested (bit 0 only)
frame 0x10 0x40 0 0 0 0 0 0 0x0C 0xA6 0 0 0 0 0 0 0 0 0 0 0x80 >&3
wait "$cat_pid"
exec 3>&-

hex=$(od -An -v -tx1 "$dir/raw.bin" | tr -d ' \n')
# the echo: 00 FF 5A, size 0x12, group 0x48, type 0x00, 16 data bytes
echo_hex=$(grep -o '00ff5a124800[0-9a-f]\{32\}' <<<"$hex" | head -1)
data=${echo_hex:12:32}
want_hex=$(printf '%02x' 20 5 2 7 0 10 10 4 8 0 10 10 4 9 0 0)
check "tase-sim echoes PACKET_RATE with reserved bytes 4, 9, 14 zero (${data:-none})" \
    test "$data" = "$want_hex"

dec=$("$TASE" decode "$dir/raw.bin")
spoi=$(grep '"name":"SPOI_CMD"' <<<"$dec" | head -1)
flags=$(json_int "$spoi" flags)
check "SPOI echo carries the gimbal's flags: mode SPOI in bits 3-7 ($spoi)" \
    eval '[ -n "$flags" ] && [ $((flags & 0x1F)) -eq 2 ]'
geo=$(grep '"name":"GEOREFERENCE_DATA"' <<<"$dec" | tail -1)
h=$(json_int "$geo" nav_health)
check "NavHealth: filter mode normal (bits 12-15 = 3), reserved bits 2-5 and 11 clear ($h)" \
    eval '[ -n "$h" ] && [ $((h & 0xF)) -eq 3 ] && [ $((h & 0x3C10)) -eq 0 ]'

ct=$("$TASE" query CAMERA_TYPE --serial "$dir/gimbal" --json)
check "CAMERA_TYPE reports the simulated cameras, not \"do not change\" ($ct)" \
    test "$(json_int "$ct" camera_a)/$(json_int "$ct" camera_b)/$(json_int "$ct" camera_c)" = 68/97/255

check_summary "spec fidelity end to end"
