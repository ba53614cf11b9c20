#!/usr/bin/env bash
# The Wireshark dissector (tools/wireshark/tase.lua, issue 15 item 6) under
# Debian's tshark: its packet table must be what the library's schema
# generates, and on a candump log, a SocketCAN pcap, a noisy serial capture
# of both directions and a live tase-sim session recorded with --record it
# must show exactly the packets `tase decode` prints: names, directions,
# offsets, times, field names and values, data bytes, errors. Also the 3AX
# frames against hand-made values, a bad direction byte, a display filter.
# Usage: tests/tools/wireshark.sh TASE TASE_SIM SCHEMA_LUA DATA_DIR
# (capture_util.py imports the tase Python package: PYTHONPATH=build/python and
# TASE_PYTHON, the python3 it was built for, as ctest sets them)
#        tests/tools/wireshark.sh --fix SCHEMA_LUA   (rewrite the table)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
LUA="$here/../../tools/wireshark/tase.lua"

# splice BLOCK: tase.lua with its generated table replaced by BLOCK's lines
splice() {
    awk -v block="$1" '
        /^-- BEGIN GENERATED/ { while ((getline l < block) > 0) print l; skip = 1; next }
        /^-- END GENERATED/ { skip = 0; next }
        !skip { print }' "$LUA"
}
if [ "${1:-}" = --fix ]; then
    block=$(mktemp)
    "$2" >"$block" && splice "$block" >"$LUA.new" && mv "$LUA.new" "$LUA"
    rm -f "$block"
    echo "rewrote the generated table of $LUA"
    exit 0
fi

TASE=$1
SIM=$2
SCHEMA_LUA=$3
DATA=$4
U="${TASE_PYTHON:-python3} $here/capture_util.py"
dir=$(mktemp -d)
sim_pid=""
cleanup() {
    [ -n "$sim_pid" ] && kill "$sim_pid" 2>/dev/null
    wait 2>/dev/null
    rm -rf "$dir"
}
trap cleanup EXIT
. "$here/check-lib.sh"
under_valgrind TASE SIM
# dissect CAPTURE [tshark args]: tshark with the dissector and a clean
# configuration (no personal plugins or preferences), two passes (-2: a
# frame held behind a longer candidate is shown in the packet of its last
# byte only on the second pass; see tase.lua's header)
tshark_clean() {
    HOME="$dir" XDG_CONFIG_HOME="$dir" tshark -X "lua_script:$LUA" "$@" 2>"$dir/tshark.err"
}
dissect() {
    local cap=$1
    shift
    tshark_clean -2 -r "$cap" "$@"
}
# expect NAME CMD...: a capture_util check; its last line shown, all of it
# on failure
expect() {
    local name=$1
    shift
    if "$@" >"$dir/expect.out"; then
        ok "$name: $(tail -1 "$dir/expect.out")"
    else
        bad "$name: $(cat "$dir/expect.out")"
    fi
}
# compare TAG NAME CAPTURE DECODE-ARGS...: the dissector (with tshark
# options dissect_opts) against tase decode
dissect_opts=()
compare() {
    local tag=$1 name=$2 cap=$3
    shift 3
    if ! dissect "$cap" "${dissect_opts[@]}" -T pdml >"$dir/$tag.pdml"; then
        bad "$name: tshark failed: $(grep -v "Running as user" "$dir/tshark.err" | head -3)"
        return
    fi
    if grep -q "Lua: Error" "$dir/tshark.err"; then
        bad "$name: $(grep -m1 -A2 "Lua: Error" "$dir/tshark.err")"
        return
    fi
    "$TASE" decode "$@" >"$dir/$tag.json"
    if $U compare-pdml "$dir/$tag.pdml" "$dir/$tag.json" >"$dir/$tag.cmp"; then
        ok "$name: $(tail -1 "$dir/$tag.cmp")"
    else
        bad "$name: $(cat "$dir/$tag.cmp")"
    fi
}

echo "tshark: $(tshark --version 2>/dev/null | head -1)"
"$SCHEMA_LUA" >"$dir/block.lua"
splice "$dir/block.lua" >"$dir/tase.lua"
check "tase.lua's packet table is the one schema_lua.c generates (fix: $0 --fix SCHEMA_LUA)" \
    diff -u "$LUA" "$dir/tase.lua"
"$TASE" list | awk '{print $1}' | sort >"$dir/list.names"
grep -o '^    {0x[0-9A-F]*, 0x[0-9A-F]*, "[A-Z_]*"' "$LUA" | sed 's/.*"\(.*\)"/\1/' | sort >"$dir/lua.names"
check "the dissector names the $(wc -l <"$dir/list.names") packets of 'tase list'" \
    cmp -s "$dir/list.names" "$dir/lua.names"

compare candump "candump log (tshark's own candump reader)" "$DATA/decode_candump.log" --candump \
    "$DATA/decode_candump.log"
$U can-pcap "$dir/can.pcap" "$DATA/decode_candump.log"
compare canpcap "SocketCAN pcap (Wireshark's CAN dissector)" "$dir/can.pcap" "$dir/can.pcap"
$U serial-pcap "$dir/noisy.pcap" 5 0.001-3 "$DATA/decode_noisy.bin:out" "$DATA/decode_noisy.bin:in"
compare noisy "noisy serial capture, both directions" "$dir/noisy.pcap" "$dir/noisy.pcap"
# AXIS_SETTING's two layouts (docs/PROTOCOL-NOTES.md S2): the 22-byte one
# was "wrong length" in the dissector while tase decode showed its fields
${TASE_PYTHON:-python3} -c '
import sys, tase
f = dict(pan_max_rate=50, tilt_max_rate=21, roll_max_rate=22, pan_pos_gain=7, temporary=1)
out = b"".join(tase.encode(p) for p in (tase.Packet("AXIS_SETTING", raw=f),
                                        tase.Packet("AXIS_SETTING", length=22, raw=f),
                                        tase.Packet.query("AXIS_SETTING")))
open(sys.argv[1], "wb").write(out)' "$dir/axis.bin"
$U serial-pcap "$dir/axis.pcap" 5 0.001-3 "$dir/axis.bin:out" "$dir/axis.bin:in"
compare axis "AXIS_SETTING in its 23- and 22-byte layouts, both directions" "$dir/axis.pcap" \
    "$dir/axis.pcap"
check "... the 22-byte one with its fields, tilt_max_rate 21 one byte earlier" \
    eval '[ "$(grep -c "name=\"tase.axis_setting.tilt_max_rate\" .*show=\"21\"" "$dir/axis.pdml")" -eq 4 ] &&
          ! grep -q "wrong length" "$dir/axis.pdml"'

# Issue 27: a gap in the record times ends a held candidate in both tools
# as the live receiver's time bound did: after the false sync 00 FF 5A FF
# and a GIMBAL_CMD, the 241 bytes still claimed need 42 ms at 57600 baud
# (251 ms at 9600), so a longer gap shows the GIMBAL_CMD, a shorter one
# the 261-byte frame the later bytes complete (capture_util.py quiet).
# want_quiet TAG FIRST: the first frame tase decode printed for TAG
want_quiet() { [ "$(head -1 "$dir/$1.json" | sed 's/.*"name":"\([A-Z_]*\)".*/\1/')" = "$2" ]; }
for gap in 1 0.030 0.2; do
    $U quiet "$dir/quiet-$gap.pcap" "$gap"
done
compare quiet1 "1 s gap after noise at 57600 baud" "$dir/quiet-1.pcap" "$dir/quiet-1.pcap"
check "... it ended the false candidate: the GIMBAL_CMD is shown" want_quiet quiet1 GIMBAL_CMD
compare quiet30 "30 ms gap at 57600 baud" "$dir/quiet-0.030.pcap" "$dir/quiet-0.030.pcap"
check "... below the limit: the 261-byte frame the later bytes complete" want_quiet quiet30 UNKNOWN
compare quiet200 "200 ms gap at 57600 baud" "$dir/quiet-0.2.pcap" "$dir/quiet-0.2.pcap"
check "... past the limit: the GIMBAL_CMD" want_quiet quiet200 GIMBAL_CMD
dissect_opts=(-o tase.baud:9600)
compare quiet200s "200 ms gap at 9600 baud (tshark -o tase.baud:9600, decode --baud 9600)" \
    "$dir/quiet-0.2.pcap" "$dir/quiet-0.2.pcap" --baud 9600
check "... below the limit there: the 261-byte frame" want_quiet quiet200s UNKNOWN
dissect_opts=()

# Issue 12's greedy receiver, in both tools, on a serial capture and a
# candump log each: a CAMERA_PASS whose camera bytes are a valid frame
# shows only the CAMERA_PASS; frames inside longer candidates with Size
# bytes corrupted upwards, split over several records, are held until the
# candidate fails (or the capture ends) and shown in the packet of their
# last byte, with its time, as `tase decode` prints them (capture_util.py
# knows from building the streams which frames, where and decided when).
for sc in camera-pass held; do
    for fmt in pcap candump; do
        cap="$dir/$sc.$fmt"
        $U greedy "$sc" "$fmt" "$cap" "$cap.expect"
        if [ "$fmt" = candump ]; then args=(--candump "$cap"); else args=("$cap"); fi
        compare "$sc-$fmt" "$sc $fmt: the dissector shows what tase decode prints" "$cap" "${args[@]}"
        expect "$sc $fmt: tase decode prints the greedy scan's frames, each with its last byte's time" \
            $U expect-decode "$cap.expect" "$dir/$sc-$fmt.json"
        expect "$sc $fmt: tshark -2 shows each in the packet of its last byte (held ones with tase.decided_in)" \
            $U expect-pdml "$cap.expect" "$dir/$sc-$fmt.pdml" 2
    done
done
# One pass (no -2): a held frame in the packet that decided it, with
# tase.last_byte_in; none of those decided by the end of the capture.
tshark_clean -r "$dir/held.pcap" -T pdml >"$dir/held-1.pdml"
expect "held pcap, single-pass tshark: held frames in their deciding packet with tase.last_byte_in" \
    $U expect-pdml "$dir/held.pcap.expect" "$dir/held-1.pdml" 1
# A pcapng of two capture interfaces (the SocketCAN pcap twice, 0.3 ms
# apart): reassembled per interface when the first pass has a protocol
# tree (-R frame), else merged and flagged with tase.interfaces_merged.
editcap -t 0.0003 "$dir/can.pcap" "$dir/can2.pcap" &&
    mergecap -I none -w "$dir/two.pcapng" "$dir/can.pcap" "$dir/can2.pcap"
n1=$(grep -c . "$dir/canpcap.json")
n=$(dissect "$dir/two.pcapng" -R frame -T fields -e tase.offset | tr ',' '\n' | grep -c .)
m=$(dissect "$dir/two.pcapng" -R frame -T fields -e _ws.expert.message | grep -c merged)
check "two capture interfaces, tshark -2 -R frame: each reassembled ($n packets, twice $n1), no warning" \
    eval '[ "$n" = $((2 * n1)) ] && [ "$m" = 0 ]'
m=$(dissect "$dir/two.pcapng" -T fields -e _ws.expert.message | grep -c "interface merged")
check "two capture interfaces, tshark -2 alone: the merge is flagged ($m packets)" [ "$m" -gt 0 ]

# CAN FD frames on our IDs are not the datalink (classic CAN only: CAN.md):
# tase decode skips them, and the dissector put their bytes into the
# stream, which lost the GIMBAL_ANGLE around one and showed one carried in
# another (a review). Frames by hand: GIMBAL_ANGLE pan 1000 tilt -500,
# checksum 0x036E.
cat >"$dir/fd.log" <<'X'
(1700000000.000000) can0 10000000#00FF5A08081003E8
(1700000000.000100) can0 10000000##01122334455667788
(1700000000.000200) can0 10000000#FE0C0000036E
(1700000000.010000) can0 10000000##000FF5A08081003E8FE0C0000036E0000
X
dissect_opts=(-R frame) # an 8-byte FD frame is told by its flags: a tree in the first pass
compare fd "CAN FD frames on our IDs skipped, as tase decode does" "$dir/fd.log" --candump "$dir/fd.log"
check "... the classic GIMBAL_ANGLE around the FD frame is shown, the one inside an FD frame not" \
    eval '[ "$(grep -c "\"name\":\"GIMBAL_ANGLE\"" "$dir/fd.json")" = 1 ]'
dissect_opts=()
grep -v '##01' "$dir/fd.log" >"$dir/fd16.log" # FD of 16 bytes only: told by its length
compare fd16 "a 16-byte CAN FD frame skipped without a first-pass tree" "$dir/fd16.log" --candump \
    "$dir/fd16.log"
# A GIMBAL_CMD whose two CAN frames come 30 ms apart: past the default
# 20 ms margin both tools judge it cut short; with a margin of 250 ms
# (tshark -o tase.margin:250, decode --margin 250) it is delivered.
cat >"$dir/margin.log" <<'X'
(1700000000.000000) can0 11000000#00FF5A0A00800BB8
(1700000000.030000) can0 11000000#FA240000A0000464
X
compare margin20 "a 30 ms pause inside a packet, the default margin" "$dir/margin.log" --candump \
    "$dir/margin.log"
check "... cut short: no GIMBAL_CMD" eval '! grep -q GIMBAL_CMD "$dir/margin20.json"'
dissect_opts=(-o tase.margin:250)
compare margin250 "the same with a 250 ms margin (tshark -o tase.margin:250, decode --margin 250)" \
    "$dir/margin.log" --candump "$dir/margin.log" --margin 250
check "... delivered: the GIMBAL_CMD" grep -q '"name":"GIMBAL_CMD"' "$dir/margin250.json"
dissect_opts=()
# A margin of 0 is the receiver's default (20 ms; decode refuses 0): the
# dissector took it as no margin, and a 10 ms pause cut the packet.
sed 's/1700000000.030000/1700000000.010000/' "$dir/margin.log" >"$dir/margin10.log"
dissect_opts=(-o tase.margin:0)
compare margin0 "a 10 ms pause inside a packet, margin 0 (tshark -o tase.margin:0, decode's default)" \
    "$dir/margin10.log" --candump "$dir/margin10.log"
check "... delivered: the GIMBAL_CMD" grep -q '"name":"GIMBAL_CMD"' "$dir/margin0.json"
dissect_opts=()
# A pcapng Simple Packet Block has no time (Wireshark gives 0): the gap
# from 1970 ended the frame split across it in the dissector.
$U spb "$dir/spb.pcapng"
compare spb "a frame split across a pcapng Simple Packet Block" "$dir/spb.pcapng" "$dir/spb.pcapng"
check "... the GEOREFERENCE_DATA" grep -q '"offset":0,.*"name":"GEOREFERENCE_DATA"' "$dir/spb.json"
# ... and its time is the record's before it, of any direction (decode's):
# a record to the gimbal 500 ms later before it is a pause in the frame
$U spb "$dir/spb2.pcapng" yes
compare spb2 "a Simple Packet Block after a record of the other direction 500 ms later" \
    "$dir/spb2.pcapng" "$dir/spb2.pcapng"
check "... a pause: no GEOREFERENCE_DATA" eval '! grep -q GEOREFERENCE_DATA "$dir/spb2.json"'

# An unknown packet with no data showed no data field (decode: "data":[]).
$U unknown "$dir/unknown.pcap"
compare unknown "packets of an unknown type, of no data and of 2 bytes" "$dir/unknown.pcap" \
    "$dir/unknown.pcap"
check "... three of them" [ "$(grep -c '"name":"UNKNOWN"' "$dir/unknown.json")" = 3 ]
# A differential review: a valid 38-byte frame of an unknown type carrying
# a whole GIMBAL_ANGLE, its last 18 bytes 20.9996 ms after its first 20
# (a nanosecond pcap), at the 20 ms margin: tase decode truncates to 20 ms
# (no pause: the outer frame), the dissector rounded to 21 (a pause: the
# inner GIMBAL_ANGLE); and 25 days apart, which tase decode read as no
# time (modulo 2^32 ms) where the dissector saw the pause.
${TASE_PYTHON:-python3} -c '
import struct, sys
angle = bytes.fromhex("00ff5a08081004d2ee6c000003a9")
body = bytes([0x28, 0x01]) + angle + bytes(range(1, 17))
frame = b"\x00\xff\x5a" + bytes([len(body)]) + body
frame += struct.pack(">H", sum(frame) & 0xFFFF)
t0 = 1700000000 * 10**9
for path, gap in ((sys.argv[1], 20999600), (sys.argv[2], 25 * 86400 * 10**9)):
    out = struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 147)
    for t, rec in ((t0, b"\x00" + frame[:20]), (t0 + gap, b"\x00" + frame[20:])):
        out += struct.pack("<IIII", t // 10**9, t % 10**9, len(rec), len(rec)) + rec
    open(path, "wb").write(out)' "$dir/edge-ms.pcap" "$dir/gap25d.pcap"
compare edgems "a pause of 20.9996 ms at the 20 ms margin (nanosecond pcap): not a pause" \
    "$dir/edge-ms.pcap" "$dir/edge-ms.pcap"
check "... the outer frame, not the GIMBAL_ANGLE in it" \
    eval 'grep -q "\"group\":40" "$dir/edgems.json" && ! grep -q GIMBAL_ANGLE "$dir/edgems.json"'
compare gap25d "a pause of 25 days inside a frame (2^31 ms and more)" "$dir/gap25d.pcap" \
    "$dir/gap25d.pcap"
check "... a pause: the outer frame cut, the GIMBAL_ANGLE in it shown" \
    grep -q '"offset":6,.*"name":"GIMBAL_ANGLE"' "$dir/gap25d.json"
# Remote frames (RTR) carry no data: the dissector fed their DLC bytes into
# the stream (a GIMBAL_ANGLE around one was lost, one after 8 of them moved).
cat >"$dir/rtr.log" <<'X'
(1700000000.000000) can0 10000000#R8
(1700000000.001000) can0 10000000#00FF5A08081003E8
(1700000000.002000) can0 10000000#R
(1700000000.003000) can0 10000000#FE0C0000036E
X
dissect_opts=(-R frame) # the RTR flag, as the FD one: a tree in the first pass
compare rtr "remote frames on our IDs ignored, as tase decode does" "$dir/rtr.log" --candump \
    "$dir/rtr.log"
check "... the GIMBAL_ANGLE around them at offset 0" \
    grep -q '"offset":0,.*"name":"GIMBAL_ANGLE"' "$dir/rtr.json"
dissect_opts=()

# 3AX frames, values by hand from can.h: move 0 deploy / else retract;
# status position, signed speed in 5 deg/s units; a wrong length.
cat >"$dir/3ax.log" <<'X'
(1700000000.000001) vcan0 12010000#FE00
(1700000000.000002) vcan0 12010000#0000
(1700000000.000003) vcan0 12020000#80F6
(1700000000.000004) vcan0 12020000#FF7F
(1700000000.000005) vcan0 12020000#01
X
printf '3AX_MOVE 254\n3AX_MOVE 0\n3AX_STATUS 128 -10\n3AX_STATUS 255 127\n3AX_STATUS error\n' >"$dir/3ax.expect"
dissect "$dir/3ax.log" -T pdml >"$dir/3ax.pdml"
$U pdml-3ax "$dir/3ax.pdml" >"$dir/3ax.got"
check "3AX move and status frames: position and speed as the spec lays them out" \
    diff -u "$dir/3ax.expect" "$dir/3ax.got"

$U bad-pcap "$dir/bad.pcap"
dissect "$dir/bad.pcap" -T fields -e frame.number -e _ws.expert.message -e tase.name >"$dir/bad.txt"
check "serial records with direction byte 0x07 and with no bytes after it flagged, the good ones dissected" \
    eval 'grep -q "^2	unknown direction byte" "$dir/bad.txt" &&
          grep -q "^3	no datalink bytes in the record" "$dir/bad.txt" &&
          grep -q "^5	no datalink bytes in the record" "$dir/bad.txt" &&
          [ "$(grep -c "GIMBAL_ANGLE" "$dir/bad.txt")" = 2 ]'
n=$(dissect "$dir/noisy.pcap" -Y 'tase.gimbal_angle.tilt == -4500 && tase.dir == "in"' | grep -c .)
check "display filter on a field and the direction: $n frame (the 'in' GIMBAL_ANGLE with tilt -4500)" \
    [ "$n" = 1 ]

# A live session: tase-sim and tase with --record; many packet types.
# Each command's status is checked (once only the last one's was, and a
# type missing from the capture could not be told from a command that
# failed).
"$SIM" --quiet --link "$dir/gimbal" --seconds 120 >"$dir/sim.log" 2>&1 &
sim_pid=$!
for _ in $(seq 400); do [ -L "$dir/gimbal" ] && break; sleep 0.05; done
live_failed=""
live() {
    local rc=0
    echo "== tase $*" >>"$dir/live.log"
    "$TASE" "$@" --serial "$dir/gimbal" --record "$dir/live.pcap" >>"$dir/live.log" 2>&1 || rc=$?
    [ $rc = 0 ] || live_failed+="${live_failed:+; }tase $1 $2 exited $rc ($(tail -1 "$dir/live.log"))"
}
live query SYSTEM_VERSION
live send PACKET_RATE angle_1=20 rate_1=20 geo_ref_1=5
live send GIMBAL_CMD pan=1000 tilt=-500 roll=0 flags=0xA0 impulse_time=0
live send CAMERA_PASS camera=1 baud=8 data=1,2,3,250
live send HOST_GPS_DATA --zero lat=162000000 lon=-442800000 height=10000 valid=1
live send CAMERA_CMD --len 1 camera=1
live query AXIS_SETTING
live monitor --seconds 1
check "live session: every command succeeded${live_failed:+ ($live_failed)}" [ -z "$live_failed" ]
compare live "live tase-sim session recorded with --record" "$dir/live.pcap" "$dir/live.pcap"
names=$(sed -n 's/.*"name":"\([A-Z_]*\)".*/\1/p' "$dir/live.json" | sort -u | tr '\n' ' ')
missing=""
for want in SYSTEM_VERSION PACKET_RATE GIMBAL_CMD CAMERA_PASS HOST_GPS_DATA CAMERA_CMD AXIS_SETTING \
    GIMBAL_ANGLE GIMBAL_RATE GEOREFERENCE_DATA; do
    grep -qw "$want" <<<"$names" || missing+=" $want"
done
check "live session: every packet type sent or asked for is in the capture ($names)${missing:+; missing:$missing}" \
    [ -z "$missing" ]
if [ -n "$missing$live_failed" ]; then
    echo "live session's log:"
    sed 's/^/    /' "$dir/live.log"
    echo "its records:"
    $U records "$dir/live.pcap" | sed 's/^/    /'
fi

check_summary dissector
echo "wireshark: the dissector shows what tase decode prints"
