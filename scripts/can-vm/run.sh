#!/usr/bin/env bash
# Real SocketCAN test: boots Debian's own kernel under qemu (TCG, no KVM)
# with a small initramfs (busybox, iproute2's ip and tc, can-utils' candump and
# cansend, the project's static agent and, when given, static builds of the
# bench tools tase and tase-sim), and runs scripts/can-vm/init.sh in it.
# Passes when the VM prints "CAN-VM: PASS".
# Usage: scripts/can-vm/run.sh AGENT CACHE_DIR [TASE TASE_SIM]
# Exit: 0 pass, 1 fail, 77 skipped (qemu cannot run at all).
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
agent=${1:?path of the static tase_can_vm_agent}
cache=${2:?cache directory (kept between runs)}
tase=${3:-}
tase_sim=${4:-}
if [ -n "$tase" ] && [ -z "$tase_sim" ]; then
    echo "FAIL: give both TASE and TASE_SIM, or neither"; exit 1
fi
here="$TASE_ROOT/scripts/can-vm"
mkdir -p "$cache"
t_start=$(date +%s%N)

tase_need can
qemu=$(command -v qemu-system-x86_64 || true)
if [ -z "$qemu" ] || ! "$qemu" -accel tcg -machine none -display none -S -version >/dev/null 2>&1; then
    echo "SKIP: qemu-system-x86_64 cannot run on this machine"
    exit 77
fi

apt_opts=(-o DPkg::Lock::Timeout=600 -o APT::Sandbox::User=root)

# The kernel: linux-image-amd64 is a metapackage; fetch the real
# linux-image-<abi>-amd64 it depends on.
kpkg() {
    apt-cache depends linux-image-amd64 2>/dev/null |
        sed -n 's/^ *Depends: \(linux-image-[0-9][^ ]*-amd64\)$/\1/p' | head -1
}
pkg=$(kpkg)
if [ -z "$pkg" ]; then
    apt-get "${apt_opts[@]}" update -qq
    pkg=$(kpkg)
fi
[ -n "$pkg" ] || { echo "FAIL: cannot resolve linux-image-amd64"; exit 1; }
kdir="$cache/kernel-$pkg"
# The modules the VM loads: CAN, raw sockets, the CAN device layer, vcan,
# and the plug qdisc that holds frames back to fill a transmit queue.
modules="net/can/can net/can/can-raw drivers/net/can/dev/can-dev drivers/net/can/vcan net/sched/sch_plug"
# An older kernel left by a previous ABI is not needed any more.
find "$cache" -maxdepth 1 -name 'kernel-*' ! -name "kernel-$pkg" -exec rm -rf {} +
# A cache made for fewer modules is made again.
for m in $modules; do
    [ -f "$kdir/modules/$(basename "$m").ko" ] || rm -f "$kdir/.done"
done
if [ ! -f "$kdir/.done" ]; then
    rm -rf "$kdir" && mkdir -p "$kdir/deb" "$kdir/modules"
    (cd "$kdir/deb" && apt-get "${apt_opts[@]}" download "$pkg" -qq) ||
        { apt-get "${apt_opts[@]}" update -qq &&
          (cd "$kdir/deb" && apt-get "${apt_opts[@]}" download "$pkg" -qq); }
    dpkg -x "$kdir"/deb/*.deb "$kdir/x"
    # Keep only what the VM needs (the unpacked package is ~400 MB).
    cp "$kdir"/x/boot/vmlinuz-* "$kdir/vmlinuz"
    mods=$(ls -d "$kdir"/x/lib/modules/* | head -1)
    for m in $modules; do
        f="$mods/kernel/$m.ko"
        if [ -f "$f" ]; then
            cp "$f" "$kdir/modules/"
        elif [ -f "$f.xz" ]; then
            xz -dc "$f.xz" > "$kdir/modules/$(basename "$f")"
        else
            echo "FAIL: $pkg has no $m module"; exit 1
        fi
    done
    rm -rf "$kdir/deb" "$kdir/x"
    touch "$kdir/.done"
fi

# The initramfs, rebuilt each run (a second; the agent changes often).
root="$cache/root"
rm -rf "$root"
mkdir -p "$root"/{bin,sbin,usr/bin,lib/modules,proc,sys,dev,tmp}
# busybox-static provides /bin/busybox (it replaces the dynamic busybox).
cp /bin/busybox "$root/bin/busybox"
cp "$kdir"/modules/*.ko "$root/lib/modules/"
# Dynamic programs with their libraries and loader (from ldd).
for prog in "$(command -v ip)" "$(command -v tc)" "$(command -v candump)" "$(command -v cansend)"; do
    cp "$prog" "$root/bin/"
    # busybox installs its own, smaller tc in /bin: keep iproute2's apart
    [ "$(basename "$prog")" != tc ] || { mkdir -p "$root/usr/sbin" && cp "$prog" "$root/usr/sbin/tc"; }
    for lib in $(ldd "$prog" | grep -o '/[^ ]*'); do
        mkdir -p "$root$(dirname "$lib")"
        cp -L "$lib" "$root$lib"
    done
done
cp "$agent" "$root/bin/agent"
# The bench tools run over vcan0 too; without them init.sh skips that part
# (the tools are not built) and says so.
if [ -n "$tase" ]; then
    for prog in "$tase" "$tase_sim"; do
        if ldd "$prog" >/dev/null 2>&1; then
            echo "FAIL: $prog is not a static executable"; exit 1
        fi
    done
    cp "$tase" "$root/bin/tase"
    cp "$tase_sim" "$root/bin/tase-sim"
    # A serial capture (a GIMBAL_CMD to the gimbal, a GIMBAL_ANGLE from it)
    # for `tase replay --can`, and the CAN frames the spec makes of it
    # (5.1: 0x11000000 to the gimbal, 0x10000000 from it, 8 bytes a frame),
    # written here independently of the library.
    python3 - "$root/data" <<'PY'
import os, struct, sys
d = sys.argv[1]
os.makedirs(d, exist_ok=True)
def frame(g, t, data):
    b = bytes([0x00, 0xFF, 0x5A, len(data) + 2, g, t]) + bytes(data)
    s = sum(b) & 0xFFFF
    return b + bytes([s >> 8, s & 0xFF])
cmd = frame(0x00, 0x80, [0x0B, 0xB8, 0xFA, 0x24, 0, 0, 0xA0, 0])
ang = frame(0x08, 0x10, [0x03, 0xE8, 0xFE, 0x0C, 0, 0])
with open(os.path.join(d, "serial.pcap"), "wb") as f:
    f.write(struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 147))
    for i, (to_gimbal, fr) in enumerate([(1, cmd), (0, ang)]):
        rec = bytes([to_gimbal]) + fr
        f.write(struct.pack("<IIII", 1700000000, i * 1000000, len(rec), len(rec)) + rec)
with open(os.path.join(d, "serial.expect"), "w") as f:
    for can_id, fr in (("11000000", cmd), ("10000000", ang)):
        for k in range(0, len(fr), 8):
            f.write("vcan0 %s#%s\n" % (can_id, fr[k:k + 8].hex().upper()))
PY
fi
cp "$here/init.sh" "$root/init"
chmod +x "$root/init"
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) > "$cache/initramfs.cpio.gz"

log="$cache/console.log"
rm -f "$log"
t_boot=$(date +%s%N)
set +e
timeout 110 "$qemu" -accel tcg -m 256 -smp 1 -no-reboot -display none -monitor none \
    -serial "file:$log" -kernel "$kdir/vmlinuz" -initrd "$cache/initramfs.cpio.gz" \
    -append "console=ttyS0 quiet panic=-1 rdinit=/init" < /dev/null
qrc=$?
set -e
t_end=$(date +%s%N)
cat "$log"
echo "can_vm: prepare $(( (t_boot - t_start) / 1000000 )) ms, VM $(( (t_end - t_boot) / 1000000 )) ms (kernel $pkg)"
if grep -q '^CAN-VM: PASS' "$log"; then
    exit 0
fi
if [ $qrc -eq 124 ]; then
    echo "FAIL: VM timed out"
elif ! grep -q '^CAN-VM: FAIL' "$log"; then
    echo "FAIL: VM ended without a result (qemu exit $qrc)"
fi
exit 1
