#!/bin/busybox sh
# /init of the CAN test VM (busybox sh). Loads the CAN modules, creates
# vcan0, runs the project's agent against can-utils, then the bench tools
# (tase-sim --can, tase --can) with candump recording, prints one
# "CAN-VM: PASS" or "CAN-VM: FAIL <why>" line and powers off.
export PATH=/bin:/sbin:/usr/bin:/usr/sbin
/bin/busybox --install -s /bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev 2>/dev/null
mkdir -p /tmp

fail() {
    echo "CAN-VM: FAIL $*"
    poweroff -f
    exit 1
}
# wait_for FILE PATTERN: up to ~5 s for PATTERN to appear in FILE
wait_for() {
    i=0
    while ! grep -q "$2" "$1" 2>/dev/null; do
        i=$((i + 1))
        [ $i -gt 500 ] && return 1
        usleep 10000
    done
}
step() { echo "== $*"; }

for m in can can-raw can-dev vcan sch_plug; do
    insmod /lib/modules/$m.ko || fail "insmod $m"
done
ip link add dev vcan0 type vcan || fail "ip link add vcan0"
ip link set up vcan0 || fail "ip link set up vcan0"
ip link add dev vcan1 type vcan || fail "ip link add vcan1"

A=/bin/agent
step "open errors"
[ "$($A open tasenosuch0 host)" = "open -12" ] || fail "missing interface is not TASE_ENODEV"
[ "$($A open vcan1 host)" = "open -13" ] || fail "down interface is not TASE_EDOWN"
[ "$($A open vcan0 gimbal)" = "open 0" ] || fail "open vcan0"
# bind() says ENODEV for a non-CAN interface too; the port tells them apart
[ "$($A open lo host)" = "open -1" ] || fail "lo (not CAN) is not TASE_EARG: $($A open lo host)"

step "(a) frames the project sends, as candump sees them"
candump -L vcan0 > /tmp/dump.log &
dump=$!
# Start marker: repeat until candump shows it, so nothing is missed.
i=0
until grep -q ' 7FF#01' /tmp/dump.log; do
    cansend vcan0 7FF#01; usleep 20000; i=$((i + 1)); [ $i -gt 200 ] && fail "candump never started"
done
{
    $A send vcan0 gimbal angle || fail "send angle (gimbal)"
    $A send vcan0 host angle || fail "send angle (host)"
    $A send vcan0 host max || fail "send max (host)"
    $A send vcan0 gimbal max || fail "send max (gimbal)"
    $A send vcan0 gimbal retract || fail "send 3AX move"
} > /tmp/sent.txt
cansend vcan0 7FF#02
wait_for /tmp/dump.log ' 7FF#02' || fail "end marker not seen"
kill $dump
grep -v ' 7FF#0[12]' /tmp/dump.log | cut -d' ' -f2- > /tmp/seen.txt
# Independent of the project's code: the GIMBAL_ANGLE packet framed by
# hand (checksum 0x036E), 8 + 6 bytes in each direction's ID, and the 3AX
# move command.
cat > /tmp/hand.txt <<'X'
vcan0 10000000#00FF5A08081003E8
vcan0 10000000#FE0C0000036E
vcan0 11000000#00FF5A08081003E8
vcan0 11000000#FE0C0000036E
X
head -4 /tmp/seen.txt | cmp -s - /tmp/hand.txt || { cat /tmp/seen.txt; fail "angle frames differ from the hand-made ones"; }
tail -1 /tmp/seen.txt | grep -qx 'vcan0 12010000#FE00' || fail "3AX move command not seen"
cmp -s /tmp/seen.txt /tmp/sent.txt || { diff /tmp/sent.txt /tmp/seen.txt; fail "candump saw other frames than were sent"; }
[ "$(grep -c '^vcan0 11000000#' /tmp/seen.txt)" = 35 ] || fail "max packet host->gimbal is not 33 frames"
[ "$(grep -c '^vcan0 10000000#' /tmp/seen.txt)" = 35 ] || fail "max packet gimbal->host is not 33 frames"
step "candump's own log lines read back by the project's parser"
$A reformat /tmp/dump.log > /tmp/reformat.log
cmp -s /tmp/reformat.log /tmp/dump.log || { diff /tmp/dump.log /tmp/reformat.log | head; fail "candump log parse/format differs"; }

step "(b) packets sent with cansend, decoded by the project"
$A recv vcan0 host 2 5000 > /tmp/host.out &
h=$!
wait_for /tmp/host.out READY || fail "host receiver not ready"
cansend vcan0 10000000#00FF5A08081003E8
cansend vcan0 11000000#DEADBEEF
cansend vcan0 123#00FF5A
cansend vcan0 12020000#0000
cansend vcan0 10000000#FE0C0000036E
cansend vcan0 10000000#00FF5A
cansend vcan0 10000000#080810
cansend vcan0 10000000#FFFF0064000003DB
wait $h || { cat /tmp/host.out; fail "host receiver did not get both packets"; }
grep -v -e READY -e END /tmp/host.out > /tmp/host.pkts
printf 'PKT 08 10 6 03E8FE0C0000\nPKT 08 10 6 FFFF00640000\n' | cmp -s - /tmp/host.pkts ||
    { cat /tmp/host.out; fail "host decoded wrong packets"; }

step "(c) 3AX status in (the move command went out in (a)) and a host command, gimbal side"
$A recv vcan0 gimbal 3 5000 > /tmp/gimbal.out &
g=$!
wait_for /tmp/gimbal.out READY || fail "gimbal receiver not ready"
cansend vcan0 11000000#00FF5A0400430100
cansend vcan0 10000000#00FF5A04
cansend vcan0 12020000#80F6
cansend vcan0 11000000#01A1
cansend vcan0 12020000#FE00
wait $g || { cat /tmp/gimbal.out; fail "gimbal receiver did not get 3 items"; }
# The statuses are frames of their own: their order relative to the
# packet depends on when read() returned, so compare sorted.
grep -v -e READY -e END /tmp/gimbal.out | sort > /tmp/gimbal.items
printf '3AX position=128 speed_dps=-50\n3AX position=254 speed_dps=0\nPKT 00 43 2 0100\n' |
    cmp -s - /tmp/gimbal.items || { cat /tmp/gimbal.out; fail "gimbal decoded wrong items"; }

step "project to project over vcan0 (kernel filters, max packet)"
$A recv vcan0 gimbal 1 5000 > /tmp/p2p.out &
p=$!
wait_for /tmp/p2p.out READY || fail "p2p receiver not ready"
$A send vcan0 gimbal max > /dev/null || fail "send (gimbal, must be filtered)"
$A send vcan0 host max > /dev/null || fail "send (host)"
wait $p || { cat /tmp/p2p.out; fail "p2p max packet not received"; }
grep -q '^PKT 00 42 253 070A0D' /tmp/p2p.out || fail "p2p packet content"
grep -q 'END items=1 checksum_errors=0 ignored=0' /tmp/p2p.out || { cat /tmp/p2p.out; fail "p2p counters"; }

# ---- faults (issue 14): signals, a full transmit queue, bus errors
t_faults=$(cut -d' ' -f1 /proc/uptime)
step "host queries over vcan0 under a SIGALRM every millisecond"
$A gimbal vcan0 gimbal 8000 > /tmp/gimbal2.out &
g2=$!
wait_for /tmp/gimbal2.out READY || fail "gimbal agent not ready"
q=$($A query vcan0 host)
echo "   $q"
kill $g2 2>/dev/null
wait $g2
n=$(echo "$q" | sed -n 's/.*alarms=\([0-9]*\).*/\1/p')
echo "$q" | grep -q '^QUERY rc=16 .* angle_1=10 retries=0 errno=0$' || fail "queries under SIGALRM: $q"
[ "${n:-0}" -ge 300 ] || fail "the queries were not interrupted by signals: $q"

step "a full transmit queue: vcan2 behind a plugged qdisc"
ip link add dev vcan2 type vcan || fail "ip link add vcan2"
ip link set up vcan2 || fail "ip link set up vcan2"
/usr/sbin/tc qdisc add dev vcan2 root plug limit 1024 || fail "tc qdisc add plug"
f=$($A fill vcan2 host)
echo "   $f"
ms=$(echo "$f" | sed -n 's/.* ms=\([0-9]*\) .*/\1/p')
# TASE_ENOBUFS within the frame bound: tx_timeout_ms (100) is the
# SocketCAN port's W, and write_all does not call it again after that;
# up to 300 ms more for the emulated machine's scheduling.
echo "$f" | grep -q '^FULL rc=-16 .* (transmit queue full)$' || fail "full queue: $f"
[ "${ms:-0}" -ge 100 ] && [ "${ms:-0}" -le 400 ] || fail "full queue: not within the bound: $f"
# the one frame refused, not each of its retries (one every millisecond)
echo "$f" | grep -q ' enobufs=1 ' || fail "full queue: not one refused frame counted: $f"
ip link del dev vcan2

step "an interface that goes down while a read has bytes in hand, and one removed"
# The kernel reports ENETDOWN to the socket once: the read that holds 3
# bytes of the frame returns them, and the next one the error (TASE_EDOWN).
ip link add dev vcan3 type vcan && ip link set up vcan3 || fail "ip link add vcan3"
$A downread vcan3 host > /tmp/down.out &
d=$!
wait_for /tmp/down.out READY || fail "downread agent not ready"
cansend vcan3 10000000#0102030405060708
wait $d
echo "   $(tail -1 /tmp/down.out)"
grep -q '^DOWNREAD r1=5 r2=3 r3=-13 errno=100$' /tmp/down.out || fail "interface down: the error was lost"
ip link set up vcan3 || fail "ip link set up vcan3"
# removed: ENODEV once to a reader, ENXIO to a writer of the unbound socket
d=$($A gone vcan3 host)
echo "   $d"
echo "$d" | grep -q '^GONE read=-12 write=-12 errno=6$' || fail "interface removed: not TASE_ENODEV"

step "two senders on one ID: interleaved, both packets are lost (the limit can.h states)"
# Two GIMBAL_CMD packets of 16 bytes, 8 + 8 each, as an autopilot and a
# bench tool would send them at once on 0x11000000. Each alone decodes.
$A recv vcan0 gimbal 2 3000 > /tmp/one.out &
o=$!
wait_for /tmp/one.out READY || fail "receiver not ready (one sender)"
cansend vcan0 11000000#00FF5A0A00800BB8
cansend vcan0 11000000#00000000000002A6
cansend vcan0 11000000#00FF5A0A0080F448
cansend vcan0 11000000#FC18000020000453
wait $o || { cat /tmp/one.out; fail "one sender at a time: both packets expected"; }
$A recv vcan0 gimbal 1 1000 > /tmp/two.out &
o=$!
wait_for /tmp/two.out READY || fail "receiver not ready (two senders)"
cansend vcan0 11000000#00FF5A0A00800BB8
cansend vcan0 11000000#00FF5A0A0080F448
cansend vcan0 11000000#00000000000002A6
cansend vcan0 11000000#FC18000020000453
wait $o && fail "two interleaved senders: a packet got through"
echo "   $(tail -1 /tmp/two.out)"
grep -q '^END items=0 checksum_errors=2 ' /tmp/two.out || { cat /tmp/two.out; fail "two senders: 0 of 2 and 2 checksum errors expected"; }

step "bus errors: the error frames vcan can carry"
# vcan has no controller: it never makes error frames itself. A program
# can send them (an 8-digit ID with bit 29 set), and the port must take
# them as bus state, never as data.
$A health vcan0 host 2 5000 > /tmp/bus1.out &
b1=$!
wait_for /tmp/bus1.out READY || fail "health agent not ready"
cansend vcan0 20000204#0020000000008305
cansend vcan0 20000040#0000000000000000
wait $b1
echo "   $(tail -1 /tmp/bus1.out)"
grep -q '^BUS state=3 errors=2 bus_offs=1 passives=1 restarts=0 no_acks=0 tec=131 rec=5 bad=0$' /tmp/bus1.out ||
    fail "bus-off not reported"
$A health vcan0 host 2 5000 > /tmp/bus2.out &
b2=$!
wait_for /tmp/bus2.out READY || fail "health agent not ready (2)"
cansend vcan0 20000100#0000000000000000
cansend vcan0 20000020#0000000000000000
wait $b2
echo "   $(tail -1 /tmp/bus2.out)"
grep -q '^BUS state=0 errors=2 bus_offs=0 passives=0 restarts=1 no_acks=1 tec=0 rec=0 bad=0$' /tmp/bus2.out ||
    fail "restart / missing ACK not reported"
echo "   (the fault checks took $t_faults .. $(cut -d' ' -f1 /proc/uptime) s of guest uptime)"

# ---- the bench tools over vcan0 (issue 6): tase-sim is the gimbal, tase
# the host, candump the independent recorder. Each check prints a PASS or
# FAIL line; any FAIL fails the VM.
if [ -x /bin/tase ] && [ -x /bin/tase-sim ]; then
    step "bench tools over vcan0: tase-sim --can, tase --can, candump"
    nfail=0
    check() {
        name=$1
        shift
        if "$@"; then echo "PASS tools: $name"; else echo "FAIL tools: $name"; nfail=$((nfail + 1)); fi
    }
    # json_int LINE KEY: the integer value of "KEY": in one JSON line
    json_int() { echo "$1" | sed -n "s/.*\"$2\":\(-\{0,1\}[0-9][0-9]*\).*/\1/p"; }
    # near A B TOL: |A - B| <= TOL
    near() { [ -n "$1" ] && d=$(($1 - $2)) && [ "${d#-}" -le "$3" ]; }
    # one_line_error FILE PATTERN: exactly one stderr line, matching PATTERN
    one_line_error() { [ "$(wc -l < "$1")" -eq 1 ] && grep -q "$2" "$1"; }

    T=/bin/tase
    L="--can vcan0"
    $T monitor --can vcan1 --seconds 1 2> /tmp/t.err
    rc=$?
    check "monitor on a down interface: exit 1, one line ($(cat /tmp/t.err))" \
        eval '[ $rc -eq 1 ] && one_line_error /tmp/t.err "vcan1: interface is down"'
    tase-sim --can tasenosuch0 --seconds 1 > /dev/null 2> /tmp/t.err
    rc=$?
    check "tase-sim on a missing interface: exit 1, one line ($(cat /tmp/t.err))" \
        eval '[ $rc -eq 1 ] && one_line_error /tmp/t.err "tasenosuch0: no such device"'
    $T query SYSTEM_VERSION $L --timeout 200 --retries 0 2> /tmp/t.err
    rc=$?
    check "query with no gimbal on the bus times out ($(cat /tmp/t.err))" \
        eval '[ $rc -eq 1 ] && one_line_error /tmp/t.err "timeout: no answer to SYSTEM_VERSION"'

    candump -L vcan0 > /tmp/tools.log &
    tdump=$!
    i=0
    until grep -q ' 7FF#03' /tmp/tools.log 2>/dev/null; do
        cansend vcan0 7FF#03; usleep 20000; i=$((i + 1)); [ $i -gt 200 ] && fail "candump never started (tools)"
    done
    # tase record --can beside candump: the same session as a pcap capture
    $T record --can vcan0 -o /tmp/tools.pcap > /tmp/rec.out 2>&1 &
    trec=$!
    wait_for /tmp/rec.out recording || { cat /tmp/rec.out; fail "tase record --can did not start"; }
    tase-sim --can vcan0 --seconds 40 > /tmp/sim.log 2>&1 &
    sim=$!
    wait_for /tmp/sim.log 'simulated gimbal on CAN interface vcan0' || { cat /tmp/sim.log; fail "tase-sim --can vcan0 did not start"; }

    v=$($T query SYSTEM_VERSION $L --json)
    echo "   $v"
    check "query SYSTEM_VERSION: version 2.5.1, cameras 68/97/255 (none)" \
        eval '[ "$(json_int "$v" major)/$(json_int "$v" minor)/$(json_int "$v" sub)" = 2/5/1 ] &&
              [ "$(json_int "$v" camera_a)/$(json_int "$v" camera_b)/$(json_int "$v" camera_c)" = 68/97/255 ] &&
              echo "$v" | grep -q "\"name\":\"SYSTEM_VERSION\",\"size\":42,"'

    e=$($T send PACKET_RATE angle_3=20 rate_3=5 geo_ref_3=2 $L --json | grep '"dir":"out"')
    check "send PACKET_RATE (port 3, the CAN link): the gimbal echoes 20/5/2" \
        eval '[ "$(json_int "$e" angle_3)/$(json_int "$e" rate_3)/$(json_int "$e" geo_ref_3)" = 20/5/2 ]'
    $T monitor $L --json --time --seconds 2 > /tmp/mon.json 2> /tmp/mon.err
    na=$(grep -c '"name":"GIMBAL_ANGLE"' /tmp/mon.json)
    nr=$(grep -c '"name":"GIMBAL_RATE"' /tmp/mon.json)
    ng=$(grep -c '"name":"GEOREFERENCE_DATA"' /tmp/mon.json)
    check "monitor 2 s follows PACKET_RATE: $na GIMBAL_ANGLE (40+-8), $nr GIMBAL_RATE (10+-3), $ng GEOREFERENCE_DATA (4+-2)" \
        eval 'near $na 40 8 && near $nr 10 3 && near $ng 4 2'
    check "monitor's summary has the frames and the CAN bus state ($(cat /tmp/mon.err))" \
        grep -q "^tase: summary: [0-9]* frames .*, CAN bus error-active (0 error frames, 0 bus-off" /tmp/mon.err
    check "monitor --time on CAN: the kernel's receive time, close to now" \
        eval 't=$(json_int "$(head -1 /tmp/mon.json)" time); now=$(date +%s); near "$t" "$now" 5'

    # The monitor runs while the position command goes out on the bus.
    # (--margin 250 here and in the decodes of this session: the VM runs
    # under TCG beside the other checks, and a sender starved for 20 ms
    # between the CAN frames of one packet had the 40-byte CAMERA_PASS
    # echo cut as a pause, once in CI; the time bound is tested elsewhere)
    $T monitor $L --json --seconds 3.5 --margin 250 > /tmp/move.json &
    mon=$!
    usleep 400000
    s=$($T point 30 -15 $L | head -1)
    check "tase point 30 -15 sends GIMBAL_CMD position, stabilised ($s)" \
        [ "$s" = "sent GIMBAL_CMD pan=3000 tilt=-1500 roll=0 flags=160 impulse_time=0" ]
    # A long packet both ways: 44 data bytes = 52 bytes = 7 CAN frames to the
    # gimbal, whose simulated camera echoes the bytes back.
    pass=$(seq -s, 201 240)
    s=$($T send CAMERA_PASS camera=1 baud=8 data=$pass $L)
    check "send CAMERA_PASS, 40 camera bytes ($s)" [ "$s" = "sent CAMERA_PASS camera=1 baud=8 +40 data bytes" ]
    wait $mon
    check "monitor got the CAMERA_PASS echo with the 40 bytes" \
        grep -q "\"name\":\"CAMERA_PASS\",\"size\":44,\"fields\":{\"camera\":1,\"baud\":8},\"data\":\[$pass\]}" /tmp/move.json
    first=$(grep '"GIMBAL_ANGLE"' /tmp/move.json | head -1)
    last=$(grep '"GIMBAL_ANGLE"' /tmp/move.json | tail -1)
    echo "   first $first"
    echo "   last  $last"
    check "GIMBAL_CMD position: the monitored angle goes from 0/0 to 30/-15 deg" \
        eval 'near "$(json_int "$first" pan)" 0 2 && near "$(json_int "$first" tilt)" 0 2 &&
              near "$(json_int "$last" pan)" 3000 15 && near "$(json_int "$last" tilt)" -1500 15'

    kill $sim
    wait $sim
    check "tase-sim stopped cleanly and logged the session" \
        eval 'grep -q "GIMBAL_CMD" /tmp/sim.log && grep -q "stopped:" /tmp/sim.log'
    cansend vcan0 7FF#04
    wait_for /tmp/tools.log ' 7FF#04' || fail "end marker not seen (tools)"
    kill $tdump
    kill -INT $trec
    wait $trec

    # candump's record, first raw, then decoded offline by the tool. The
    # SYSTEM_VERSION query framed by hand: 00 FF 5A, size 2, group 0x48,
    # type 0x03, checksum 0x01A6 (sum of all bytes before it): one frame.
    check "candump saw the SYSTEM_VERSION query frame 11000000#00FF5A02480301A6" \
        grep -q ' vcan0 11000000#00FF5A02480301A6$' /tmp/tools.log
    check "candump saw the SYSTEM_VERSION answer start 10000000#00FF5A2C4803" \
        grep -q ' vcan0 10000000#00FF5A2C4803' /tmp/tools.log
    $T decode --candump --margin 250 /tmp/tools.log > /tmp/dec.json 2> /tmp/t.err
    rc=$?
    echo "   candump: $(wc -l < /tmp/tools.log) frames; decoded: $(wc -l < /tmp/dec.json) packets," \
        "$(grep -c '"dir":"in"' /tmp/dec.json) in, $(grep -c '"dir":"out"' /tmp/dec.json) out"
    check "tase decode --candump of the capture exits 0 ($(cat /tmp/t.err))" [ $rc -eq 0 ]
    check "decoded: SYSTEM_VERSION query (in, size 0)" \
        grep -q '"dir":"in","interface":"vcan0","group":72,"type":3,"name":"SYSTEM_VERSION","size":0,"fields":{}}' /tmp/dec.json
    ve=$(grep '"dir":"out","interface":"vcan0","group":72,"type":3,"name":"SYSTEM_VERSION","size":42,' /tmp/dec.json)
    check "decoded: SYSTEM_VERSION answer (out) 2.5.1 as tase query printed it" \
        eval '[ "$(echo "$ve" | wc -l)" = 1 ] && [ "$(json_int "$ve" major)/$(json_int "$ve" minor)/$(json_int "$ve" sub)" = 2/5/1 ] &&
              [ "${ve#*\"fields\"}" = "${v#*\"fields\"}" ]'
    check "decoded: PACKET_RATE in both directions (queries, set 20/5/2 and echoes)" \
        eval '[ "$(grep -c "\"dir\":\"in\".*\"name\":\"PACKET_RATE\",\"size\":16,\"fields\":{.*\"angle_3\":20,\"rate_3\":5,\"geo_ref_3\":2," /tmp/dec.json)" = 1 ] &&
              [ "$(grep -c "\"dir\":\"out\".*\"name\":\"PACKET_RATE\",\"size\":16,\"fields\":{.*\"angle_3\":20,\"rate_3\":5,\"geo_ref_3\":2," /tmp/dec.json)" = 1 ] &&
              grep -q "\"dir\":\"in\".*\"name\":\"PACKET_RATE\",\"size\":0," /tmp/dec.json'
    check "decoded: every packet has the capture's time and the interface" \
        eval '[ "$(grep -c "^{\"offset\":[0-9]*,\"time\":[0-9]*\.[0-9]\{6\},\"dir\":\"[a-z]*\",\"interface\":\"vcan0\"," /tmp/dec.json)" = "$(wc -l < /tmp/dec.json)" ]'
    check "decoded: GIMBAL_CMD in, pan 3000 tilt -1500 flags 0xA0" \
        grep -q '"dir":"in","interface":"vcan0","group":0,"type":128,"name":"GIMBAL_CMD","size":8,"fields":{"pan":3000,"tilt":-1500,.*"flags":160' /tmp/dec.json
    check "decoded: CAMERA_PASS in and its echo out, same 40 bytes" \
        eval '[ "$(grep -c "\"name\":\"CAMERA_PASS\",\"size\":44,\"fields\":{\"camera\":1,\"baud\":8},\"data\":\[$pass\]}" /tmp/dec.json)" = 2 ] &&
              grep -q "\"dir\":\"in\",\"interface\":\"vcan0\",\"group\":0,\"type\":66," /tmp/dec.json &&
              grep -q "\"dir\":\"out\",\"interface\":\"vcan0\",\"group\":0,\"type\":66," /tmp/dec.json'
    nd=$(grep -c '"dir":"out".*"name":"GIMBAL_ANGLE"' /tmp/dec.json)
    check "decoded: $nd GIMBAL_ANGLE out, at least the $na the 2 s monitor printed" [ "$nd" -ge "$na" ]
    check "decoded: no frame with a wrong length" eval '! grep -q "\"error\"" /tmp/dec.json'

    # The capture of tase record --can: the same packets as candump's log,
    # the same kernel receive times (to the microsecond candump keeps).
    check "tase record --can: $(tail -1 /tmp/rec.out)" grep -q '^recorded [1-9][0-9]* records' /tmp/rec.out
    $T decode --margin 250 /tmp/tools.pcap > /tmp/pcap.json
    sed 's/"interface":"[^"]*",//' /tmp/dec.json > /tmp/dec.cmp
    check "tase decode of the record --can capture: the candump log's $(wc -l < /tmp/dec.cmp) packets, times to the microsecond" \
        cmp -s /tmp/pcap.json /tmp/dec.cmp
    # tase replay --can of that capture, seen by candump: every frame, in
    # order, at 4 times the recorded pace; then only the host's frames.
    # replay_seen LOG ARGS...: candump (into LOG) watches tase replay ARGS
    replay_seen() {
        log=$1
        shift
        candump -L vcan0 > $log &
        rdump=$!
        i=0
        until grep -q ' 7FF#05' $log 2>/dev/null; do
            cansend vcan0 7FF#05; usleep 20000; i=$((i + 1)); [ $i -gt 200 ] && fail "candump never started (replay)"
        done
        $T replay /tmp/tools.pcap --can vcan0 "$@" > /tmp/replay.out 2>&1
        cansend vcan0 7FF#06
        wait_for $log ' 7FF#06' || fail "end marker not seen (replay)"
        kill $rdump
        wait $rdump
        grep -v ' 7FF#0' $log | cut -d' ' -f2- > /tmp/replayed.txt
    }
    grep -v ' 7FF#0' /tmp/tools.log | cut -d' ' -f2- > /tmp/recorded.txt
    span=$(grep -v ' 7FF#0' /tmp/tools.log | sed -n '1s/^(\([0-9.]*\)).*/\1/p;$s/^(\([0-9.]*\)).*/\1/p' |
        tr '\n' ' ' | awk '{ printf "%.3f", $2 - $1 }')
    replay_seen /tmp/replay-all.log --dir all --speed 4
    took=$(sed -n 's/.* in \([0-9.]*\) s.*/\1/p' /tmp/replay.out)
    check "replay --can --dir all --speed 4: candump saw the $(wc -l < /tmp/recorded.txt) recorded frames in order ($(cat /tmp/replay.out))" \
        cmp -s /tmp/recorded.txt /tmp/replayed.txt
    check "replay --speed 4 took $took s for a $span s session: a quarter, +-0.3 s" \
        awk -v s="$span" -v t="$took" 'BEGIN { q = s / 4; exit !(t > q - 0.3 && t < q + 0.3) }'
    replay_seen /tmp/replay-in.log --dir in --speed 0
    grep ' 11000000#' /tmp/recorded.txt > /tmp/recorded.in
    check "replay --can --dir in: only the $(wc -l < /tmp/recorded.in) frames sent to the gimbal ($(cat /tmp/replay.out))" \
        eval 'cmp -s /tmp/recorded.in /tmp/replayed.txt || { diff /tmp/recorded.in /tmp/replayed.txt | head; false; }'
    # A serial capture replayed onto CAN: cut into frames of each record's
    # direction's ID (it sent nothing: the loop took the frames' dlc for an
    # error code)
    cp /data/serial.pcap /tmp/tools.pcap
    replay_seen /tmp/replay-serial.log --dir all --speed 0
    check "replay --can of a serial capture: the frames of each direction's ID ($(cat /tmp/replay.out))" \
        eval 'cmp -s /data/serial.expect /tmp/replayed.txt || { diff /data/serial.expect /tmp/replayed.txt | head; false; }'

    # ---- interfaces that are not CAN, go down or go away under the tools
    $T monitor --can lo --seconds 1 2> /tmp/t.err
    rc=$?
    check "monitor --can lo: exit 1, not a CAN interface ($(cat /tmp/t.err))" \
        eval '[ $rc -eq 1 ] && one_line_error /tmp/t.err "lo: not a CAN interface"'
    $T monitor --can "" --seconds 1 2> /tmp/t.err
    rc=$?
    check "monitor --can '': a usage error, exit 2 ($(cat /tmp/t.err))" [ $rc -eq 2 ]
    ip link add dev vcan4 type vcan && ip link set up vcan4 || fail "ip link add vcan4"
    $T monitor --can vcan4 --seconds 20 > /dev/null 2> /tmp/mon4.err &
    m4=$!
    $T record --can vcan4 -o /tmp/down.pcap > /tmp/rec4.out 2>&1 &
    r4=$!
    wait_for /tmp/rec4.out recording || { cat /tmp/rec4.out; fail "tase record --can vcan4 did not start"; }
    usleep 300000
    cansend vcan4 11000000#00FF5A02480301A6
    usleep 300000
    ip link set vcan4 down
    wait $m4
    rc=$?
    check "monitor: the interface going down ends it, exit 1 ($(tail -1 /tmp/mon4.err))" \
        eval '[ $rc -eq 1 ] && tail -1 /tmp/mon4.err | grep -q "cannot read vcan4: the interface went down$"'
    wait $r4
    rc=$?
    check "record --can: the interface going down ends it, exit 1, the capture kept ($(tr '\n' ' ' < /tmp/rec4.out))" \
        eval '[ $rc -eq 1 ] && grep -q "^recorded 1 record (1 frame) to /tmp/down.pcap" /tmp/rec4.out &&
              grep -q "cannot read CAN interface vcan4: the interface went down$" /tmp/rec4.out'
    $T decode /tmp/down.pcap > /tmp/down.dec 2>&1
    rc=$?
    check "the capture of a recording the interface ended decodes ($(head -c 120 /tmp/down.dec))" \
        eval '[ $rc -eq 0 ] && grep -q SYSTEM_VERSION /tmp/down.dec'
    # removed and made again (a USB adapter unplugged and plugged back):
    # tase-sim says so and serves on the new interface
    ip link set vcan4 up
    tase-sim --can vcan4 --seconds 60 > /tmp/sim4.log 2>&1 &
    sim4=$!
    wait_for /tmp/sim4.log "simulated gimbal" || { cat /tmp/sim4.log; fail "tase-sim on vcan4 did not start"; }
    $T query SYSTEM_VERSION --can vcan4 > /dev/null 2> /tmp/t.err
    check "query on vcan4 before it is removed ($(cat /tmp/t.err))" [ $? -eq 0 ]
    ip link del dev vcan4
    ip link add dev vcan4 type vcan && ip link set up vcan4 || fail "ip link add vcan4 (again)"
    wait_for /tmp/sim4.log "is back: serving" || true
    $T query SYSTEM_VERSION --can vcan4 > /dev/null 2> /tmp/t.err
    rc=$?
    check "tase-sim serves an interface removed and made again: query exits 0 ($(cat /tmp/t.err))" [ $rc -eq 0 ]
    check "tase-sim's log says the interface was removed and is back" \
        eval 'grep -q "vcan4: the interface was removed" /tmp/sim4.log && grep -q "vcan4 is back" /tmp/sim4.log'
    kill $sim4
    wait $sim4
    [ $nfail -eq 0 ] || fail "$nfail bench tool check(s) over vcan0 failed"
else
    step "bench tools over vcan0: SKIPPED (tase and tase-sim are not built)"
fi

echo "CAN-VM: PASS"
poweroff -f
