#!/bin/busybox sh
# /init of the CAN test VM (busybox sh). Loads the CAN modules, creates
# vcan0, runs the project's agent against can-utils, prints one
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

for m in can can-raw can-dev vcan; do
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

echo "CAN-VM: PASS"
poweroff -f
