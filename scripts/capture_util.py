#!/usr/bin/env python3
"""Test helpers for the capture checks (scripts/tools-capture.sh,
scripts/check-wireshark.sh). Written from the format descriptions
(docs/TOOLS.md "Captures", tcpdump.org's LINKTYPE_CAN_SOCKETCAN), not from
the tools' code, so they check it rather than repeat it.

  serial-pcap OUT SEED GAPS BIN:DIR...  a nanosecond pcap, link type 147,
        of the raw byte streams BIN (DIR out = from the gimbal, in = to it)
        cut in random 1..64-byte records, interleaved, GAPS ("LO-HI", in
        milliseconds) apart.
  expect-serial PCAP JSONL:DIR...  the JSON lines `tase decode PCAP` must
        print, from each stream's expected lines (the generator's
        decode_noisy.jsonl): "time" (microseconds, truncated) and "dir"
        added, ordered by the record that completes each frame.
  can-pcap OUT LOG                 a LINKTYPE_CAN_SOCKETCAN pcap of a candump
        log (nanosecond timestamps, big-endian identifiers with flags).
  bad-pcap OUT                     a serial pcap with a bad direction byte, a
        record with no bytes, and good records around them.
  pty-pair A B                     two pseudo-terminals (symlinks A and B)
        joined like a null-modem cable, raw, until killed.
  compare-pdml PDML JSONL          the dissector's packets (tshark -T pdml)
        against `tase decode`'s JSON lines: names, keys, field values in
        order, data bytes, errors, directions, offsets and times.
  pdml-3ax PDML                    the 3AX frames the dissector showed, one
        "NAME position speed" line each ("error" for a wrong length).
  records PCAP                     one line per record: time, then (serial)
        the direction byte and the bytes in hex, or (CAN) id#data.
  timing PCAP_SENT PCAP_GOT DIR SPEED TOL  the bytes of direction DIR in
        PCAP_SENT arrived in PCAP_GOT (direction out) byte for byte, each
        within TOL seconds of its recorded time divided by SPEED.
"""
import json
import os
import random
import select
import struct
import sys
import termios
import tty
import xml.etree.ElementTree as ET
from decimal import ROUND_DOWN, Decimal

USEC = Decimal("0.000001")

LINKTYPE_SERIAL = 147
LINKTYPE_CAN = 227
DIRS = {"out": 0, "in": 1}
T0 = 1700000000


def pcap_header(linktype, snaplen=65535):
    return struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, snaplen, linktype)


def pcap_record(sec, nsec, data):
    return struct.pack("<IIII", sec, nsec, len(data), len(data)) + data


def read_pcap(path):
    """[(Decimal time, bytes)] of a pcap (micro or nanosecond, either order)."""
    raw = open(path, "rb").read()
    magic = struct.unpack("<I", raw[:4])[0]
    if magic in (0xA1B2C3D4, 0xA1B23C4D):
        e = "<"
    else:
        e = ">"
        magic = struct.unpack(">I", raw[:4])[0]
    scale = Decimal("1e-9") if magic == 0xA1B23C4D else Decimal("1e-6")
    linktype = struct.unpack(e + "I", raw[20:24])[0]
    out, i = [], 24
    while i < len(raw):
        sec, frac, cap, _ = struct.unpack(e + "IIII", raw[i:i + 16])
        out.append((Decimal(sec) + frac * scale, raw[i + 16:i + 16 + cap]))
        i += 16 + cap
    return linktype, out


def cut(data, rng):
    out, i = [], 0
    while i < len(data):
        n = rng.randint(1, 64)
        out.append(data[i:i + n])
        i += n
    return out


def serial_pcap(out, seed, gaps, specs):
    rng = random.Random(int(seed))
    lo, hi = (int(Decimal(x) * 1000000) for x in gaps.split("-"))
    queues = []
    for spec in specs:
        path, d = spec.rsplit(":", 1)
        queues.append((DIRS[d], cut(open(path, "rb").read(), rng)))
    ns = 0
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        while any(q for _, q in queues):
            d, q = rng.choice([x for x in queues if x[1]])
            ns += rng.randint(lo, hi)
            f.write(pcap_record(T0 + ns // 10**9, ns % 10**9, bytes([d]) + q.pop(0)))


def expect_serial(pcap, specs):
    _, recs = read_pcap(pcap)
    pending = {}
    for spec in specs:
        path, d = spec.rsplit(":", 1)
        pending[DIRS[d]] = [(d, json.loads(line)) for line in open(path)]
    pos = {0: 0, 1: 0}
    for t, rec in recs:
        d = rec[0]
        pos[d] += len(rec) - 1
        while pending.get(d):
            name, o = pending[d][0]
            if o["offset"] + 8 + o["size"] > pos[d]:
                break
            pending[d].pop(0)
            o = {"offset": o["offset"], "time": str(t.quantize(USEC, ROUND_DOWN)), "dir": name,
                 **{k: v for k, v in o.items() if k != "offset"}}
            text = json.dumps({k: ("@t@" if k == "time" else v) for k, v in o.items()},
                              separators=(",", ":"))
            print(text.replace('"@t@"', o["time"]))
    assert not any(pending.values()), "frames never completed: %r" % pending


def can_pcap(out, log):
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_CAN, 72))
        for line in open(log):
            ts, _, frame = line.split()
            sec, usec = ts.strip("()").split(".")
            ident, data = frame.split("#")
            data = bytes.fromhex(data)
            can_id = int(ident, 16) | (0x80000000 if len(ident) == 8 else 0)
            body = struct.pack(">IBBBB", can_id, len(data), 0, 0, 0) + data.ljust(8, b"\0")
            f.write(pcap_record(int(sec), int(usec) * 1000, body))


def bad_pcap(out):
    angle = bytes([0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x03, 0xE8, 0xFE, 0x0C, 0x00, 0x00,
                   0x03, 0x6E])  # GIMBAL_ANGLE pan 1000 tilt -500, framed by hand
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        f.write(pcap_record(T0, 1, b"\x00" + angle))
        f.write(pcap_record(T0, 2, b"\x07" + angle))  # record 2: direction 7
        f.write(pcap_record(T0, 3, b"\x00"))  # record 3: no bytes
        f.write(pcap_record(T0, 4, b"\x01" + angle))


def pty_pair(a, b):
    masters = []
    keep = []
    for link in (a, b):
        m, s = os.openpty()
        tty.setraw(s)  # the line is raw whoever opens it
        attrs = termios.tcgetattr(s)
        attrs[3] &= ~termios.ECHO
        termios.tcsetattr(s, termios.TCSANOW, attrs)
        keep.append(s)  # held open: no hang-up between clients
        masters.append(m)
        if os.path.lexists(link):
            os.unlink(link)
        os.symlink(os.ttyname(s), link)
    peer = {masters[0]: masters[1], masters[1]: masters[0]}
    while True:
        ready, _, _ = select.select(masters, [], [])
        for m in ready:
            try:
                data = os.read(m, 4096)
            except OSError:
                continue
            os.write(peer[m], data)


def pdml_packets(path):
    """[(time, [proto elements named tase])] per packet."""
    out = []
    for pkt in ET.parse(path).getroot().iter("packet"):
        t = None
        protos = []
        for proto in pkt.findall("proto"):
            if proto.get("name") == "geninfo":
                for f in proto.iter("field"):
                    if f.get("name") == "timestamp":
                        t = Decimal(f.get("value"))
            elif proto.get("name") == "tase":
                protos.append(proto)
        out.append((t, protos))
    return out


def proto_object(proto):
    """A dissected TASE packet as a JSON contract object (no time)."""
    o, fields = {}, {}
    name = None
    for f in proto.findall("field"):
        key, show = f.get("name"), f.get("show")
        if not key.startswith("tase."):
            continue  # expert info
        short = key[len("tase."):]
        if short in ("offset", "size"):
            o[short] = int(show)
        elif short in ("group", "type"):
            o[short] = int(show, 16) if show.startswith("0x") else int(show)
        elif short in ("dir", "name", "error"):
            o[short] = show
            name = show if short == "name" else name
        elif short == "data":
            o["data"] = list(bytes.fromhex(f.get("value")))
        elif short != "checksum":
            pkt, field = short.split(".", 1)
            assert pkt == name.lower(), (key, name)
            fields[field] = int(show)
    obj = {k: o[k] for k in ("offset", "dir", "group", "type", "name", "size") if k in o}
    if "error" in o:
        obj["error"] = o["error"]
    elif name == "UNKNOWN":
        obj["fields"] = {"data": o.get("data", [])}
    else:
        obj["fields"] = fields
        if "data" in o:
            obj["data"] = o["data"]
    return obj


def compare_pdml(pdml, jsonl):
    got = []
    for t, protos in pdml_packets(pdml):
        for p in protos:
            o = proto_object(p)
            if o["name"].startswith("3AX_"):
                continue
            got.append((t, o))
    exp = [json.loads(line, parse_float=Decimal) for line in open(jsonl)]
    # Each direction in its stream order; across directions tase decode
    # prints in the order its receivers decided the frames (a frame held
    # behind a longer candidate comes later), the dissector in packet order.
    got.sort(key=lambda to: to[1].get("dir") or "")
    exp.sort(key=lambda e: e.get("dir") or "")
    # CAMERA_PASS: "data" (the camera bytes) follows "fields"; an unknown
    # packet's bytes are fields.data, for both.
    bad = 0
    if len(got) != len(exp):
        print("dissector showed %d TASE packets, tase decode printed %d" % (len(got), len(exp)))
        bad += 1
    for i, ((t, g), e) in enumerate(zip(got, exp)):
        e = dict(e)
        etime = e.pop("time", None)
        e.pop("interface", None)
        if "dir" not in e:
            g.pop("dir", None)
        if list(g.items()) != list(e.items()):
            print("packet %d differs:\n  dissector: %s\n  decode:    %s" % (i, json.dumps(g),
                                                                         json.dumps(e)))
            bad += 1
        elif etime is not None and etime != t.quantize(etime, ROUND_DOWN):
            print("packet %d: decode time %s, frame time %s" % (i, etime, t))
            bad += 1
    names = sorted({o["name"] for _, o in got})
    print("compared %d packets (%s): %s" % (len(exp), ", ".join(names),
                                            "same" if bad == 0 else "%d differences" % bad))
    return 0 if bad == 0 else 1


def pdml_3ax(pdml):
    for _, protos in pdml_packets(pdml):
        for p in protos:
            vals = {f.get("name"): f.get("show") for f in p.findall("field")}
            name = vals.get("tase.name", "")
            if not name.startswith("3AX_"):
                continue
            if "tase.error" in vals:
                print(name, "error")
            elif name == "3AX_MOVE":
                print(name, vals["tase.3ax_move.position"])
            else:
                print(name, vals["tase.3ax_status.position"], vals["tase.3ax_status.speed"])


def records(pcap):
    linktype, recs = read_pcap(pcap)
    for t, r in recs:
        if linktype == LINKTYPE_SERIAL:
            print(t, r[0], r[1:].hex().upper())
        else:
            can_id, n = struct.unpack(">IB", r[:5])
            print(t, "%08X#%s" % (can_id, r[8:8 + n].hex().upper()))


def timing(sent, got, d, speed, tol):
    want = DIRS[d]
    _, srecs = read_pcap(sent)
    _, grecs = read_pcap(got)
    sbytes = [(t, b) for t, r in srecs if r[0] == want for b in r[1:]]
    gbytes = [(t, b) for t, r in grecs if r[0] == 0 for b in r[1:]]
    if [b for _, b in sbytes] != [b for _, b in gbytes]:
        print("replayed bytes differ: sent %d, received %d" % (len(sbytes), len(gbytes)))
        return 1
    speed, tol = Decimal(speed), Decimal(tol)
    worst = max(abs((tg - gbytes[0][0]) - (ts - sbytes[0][0]) / speed)
                for (ts, _), (tg, _) in zip(sbytes, gbytes))
    span = (sbytes[-1][0] - sbytes[0][0]) / speed
    print("%d bytes identical; timing: worst byte %.1f ms off over %.2f s" %
          (len(sbytes), worst * 1000, span))
    return 0 if worst <= tol else 1


def main(argv):
    cmd, args = argv[1], argv[2:]
    if cmd == "serial-pcap":
        serial_pcap(args[0], args[1], args[2], args[3:])
    elif cmd == "expect-serial":
        expect_serial(args[0], args[1:])
    elif cmd == "can-pcap":
        can_pcap(args[0], args[1])
    elif cmd == "bad-pcap":
        bad_pcap(args[0])
    elif cmd == "pty-pair":
        pty_pair(args[0], args[1])
    elif cmd == "compare-pdml":
        return compare_pdml(args[0], args[1])
    elif cmd == "pdml-3ax":
        pdml_3ax(args[0])
    elif cmd == "records":
        records(args[0])
    elif cmd == "timing":
        return timing(*args)
    else:
        raise SystemExit("unknown command " + cmd)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
