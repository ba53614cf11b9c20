#!/usr/bin/env python3
"""Test helpers for the capture checks (tests/tools/capture.sh,
tests/tools/wireshark.sh). Frames are built and captures read by the tase
Python package (on PYTHONPATH: build/python, as ctest sets it). What the
tools must print is worked out here from how each capture was built, never
by a receiver (the generator's expected lines at the records completing
them, the greedy scan's frames from the streams as assembled). The
captures are written byte by byte from the format descriptions
(docs/TOOLS.md "Captures", tcpdump.org's LINKTYPE_CAN_SOCKETCAN), not by the
package's writer: some are damaged on purpose, and the tools' reader is
checked against a writer other than its own.

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
  quiet OUT GAP                    a false sync, then GAP seconds later the
        bytes completing it as a frame (the receiver's time bound).
  times OUT                        records stamped past 2038 and with a
        fraction of 10^9 ns or more.
  replay-checks CUT BAD BACK       captures `tase replay` must refuse (cut,
        bad direction byte) or replay across a clock stepped back.
  held-cut OUT                     a capture cut inside its second record,
        a whole GIMBAL_ANGLE behind a false start in its first.
  step-back OUT DAYS               a GIMBAL_ANGLE split over two records, the
        second stamped DAYS days earlier.
  spb OUT [yes]                    a pcapng: a GEOREFERENCE_DATA split over
        two timed records and a Simple Packet Block between them (yes: a
        record of the other direction 500 ms later before the SPB).
  reader-edges DIR                 the captures of a fuzzing review of the
        readers (usfrac.pcap, capbig.pcap, negtime.pcapng, spb.pcapng,
        rtr.pcap, 3ax.pcap; capture.sh says what each must give).
  unknown OUT                      a serial capture of packets of an unknown
        type, of no data and of 2 bytes.
  pty-pair A B                     two pseudo-terminals (symlinks A and B)
        joined like a null-modem cable, raw, until killed.
  compare-pdml PDML JSONL          the dissector's packets (tshark -T pdml)
        against `tase decode`'s JSON lines: names, keys, field values in
        order, data bytes, errors, directions, offsets and times.
  greedy SCENARIO FORMAT OUT EXPECT  a capture (FORMAT pcap: serial
        records; candump: a candump log) of two directions built to test
        the receiver's greedy scan, and EXPECT, the frames it must give
        (one JSON line each: dir, offset, name, the packet carrying the
        last byte, the packet that decides it or null for the end of the
        capture, time). SCENARIO camera-pass: a CAMERA_PASS whose camera
        bytes are a whole valid GIMBAL_CMD frame, completed records after
        it; held: frames inside longer candidates with corrupted Size
        bytes, split over several records, decided when the candidate
        fails or at the end of the capture, and a CAMERA_PASS carrying a
        frame among them.
  expect-decode EXPECT JSONL       `tase decode`'s objects, per direction in
        stream order, are EXPECT's frames (offset, name, time).
  expect-pdml EXPECT PDML PASSES   the dissector's frames, packet by packet
        with their annotations, are what EXPECT says for a tshark run with
        PASSES 2 (-2: each frame in the packet of its last byte) or 1 (a
        frame in the packet that decided it, none decided at the end).
  pdml-3ax PDML                    the 3AX frames the dissector showed, one
        "NAME position speed" line each ("error" for a wrong length).
  records PCAP                     one line per record: time, then (serial)
        the direction byte and the bytes in hex, or (CAN) id#data.
  paced-angles TTY N PAUSE JITTER GAP  N GIMBAL_ANGLE frames (pan 0..N-1)
        written to TTY, each paused PAUSE..PAUSE+JITTER ms after its sixth
        byte (random, seed 7) and GAP ms after its last (a sender that
        pauses inside a packet, at or past the quiet limit).
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
import time
import tty
import xml.etree.ElementTree as ET
from decimal import ROUND_DOWN, Decimal

import tase

USEC = Decimal("0.000001")

LINKTYPE_SERIAL = 147
LINKTYPE_CAN = 227
DIRS = {"out": 0, "in": 1}
T0 = 1700000000


# The capture writer of the checks (see the module's docstring): a
# nanosecond pcap header and records of any (sec, nsec), bytes as given.
def pcap_header(linktype, snaplen=65535):
    return struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, snaplen, linktype)


def pcap_record(sec, nsec, data):
    return struct.pack("<IIII", sec, nsec, len(data), len(data)) + data


def read_pcap(path):
    """[(Decimal time, linktype, bytes)] of the records of a capture, by the
    package's reader (times in whole microseconds, as `tase decode`)."""
    return [(Decimal(t).scaleb(-6), lt, data)
            for _, lt, t, data, _ in tase.capture.records(path)]


def cut(data, rng):
    out, i = [], 0
    while i < len(data):
        n = rng.randint(1, 64)
        out.append(data[i:i + n])
        i += n
    return out


def cut_at_frames(data, jsonl):
    """Records that end where the expected frames (jsonl: offset, size)
    end, the noise before each frame with it, as a sender writes a frame:
    whole, at the line's rate."""
    out, i = [], 0
    for line in open(jsonl):
        o = json.loads(line)
        end = o["offset"] + o["size"] + 8
        out.append(data[i:end])
        i = end
    if i < len(data):
        out.append(data[i:])
    return out


def serial_pcap(out, seed, gaps, *specs):
    """A serial capture of the streams SPEC (FILE.bin:DIR), records of 1..64
    bytes from either direction at random, GAPS ms ("LO-HI") apart. Gaps a
    live receiver would see as the line going quiet (HI >= 20 ms, its time
    bound's margin) come only where a frame ended (FILE.jsonl beside the
    .bin has the frames): no sender pauses inside a frame."""
    rng = random.Random(int(seed))
    lo, hi = (int(Decimal(x) * 1000000) for x in gaps.split("-"))
    queues = []
    for spec in specs:
        path, d = spec.rsplit(":", 1)
        data = open(path, "rb").read()
        if hi >= 20 * 1000000:
            queues.append((DIRS[d], cut_at_frames(data, path[:-4] + ".jsonl")))
        else:
            queues.append((DIRS[d], cut(data, rng)))
    ns = 0
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        while any(q for _, q in queues):
            d, q = rng.choice([x for x in queues if x[1]])
            ns += rng.randint(lo, hi)
            f.write(pcap_record(T0 + ns // 10**9, ns % 10**9, bytes([d]) + q.pop(0)))


def expect_serial(pcap, *specs):
    recs = [(t, rec) for t, _, rec in read_pcap(pcap)]
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
    angle = gimbal_angle(1000, -500)[1]
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        f.write(pcap_record(T0, 1, b"\x00" + angle))
        f.write(pcap_record(T0, 2, b"\x07" + angle))  # record 2: direction 7
        f.write(pcap_record(T0, 3, b"\x00"))  # record 3: no bytes
        f.write(pcap_record(T0, 4, b"\x01" + angle))
        f.write(pcap_record(T0, 5, b""))  # record 5: not even a direction byte


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


# Where a frame's last byte was and when it was decided: the dissector's
# annotations, not JSON keys.
HELD_FIELDS = ("decided_in", "decided_at_end", "last_byte_in")


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
            o["data"] = list(bytes.fromhex(f.get("value", "")))  # none: no value
        elif short not in ("checksum",) + HELD_FIELDS:
            pkt, field = short.split(".", 1)
            assert pkt == name.lower(), (key, name)
            fields[field] = int(show)
    obj = {k: o[k] for k in ("offset", "dir", "group", "type", "name", "size") if k in o}
    if "error" in o:
        obj["error"] = o["error"]
    elif name == "UNKNOWN":  # its data field, even of none (decode's "data":[])
        obj["fields"] = {"data": o["data"]} if "data" in o else {}
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


def packet(name, data=b"", **raw):
    """(name, frame) of a packet from wire integers, by the package."""
    return name, tase.Packet(name, raw=raw, data=data).encode()


def gimbal_angle(pan, tilt):
    return packet("GIMBAL_ANGLE", pan=pan, tilt=tilt, roll=0)


def gimbal_cmd(pan, tilt, flags):
    return packet("GIMBAL_CMD", pan=pan, tilt=tilt, roll=0, flags=flags, impulse_time=0)


def camera_pass(camera_bytes):
    return packet("CAMERA_PASS", camera_bytes, camera=1, baud=8)


def false_start(size):
    """Sync bytes and a Size byte claiming `size`: a frame whose Size byte
    was corrupted upwards, or noise that looks like a header."""
    return bytes([0x00, 0xFF, 0x5A, size, 0x08, 0x40])


class Stream:
    """One direction's bytes with the frames the greedy scan must find:
    [name, offset, end, decided_at] (decided_at: the stream offset whose
    arrival decides the frame; None: only the end of the capture)."""

    def __init__(self):
        self.data = b""
        self.frames = []
        self.candidate_end = None  # end of the pending false candidate
        self.candidates = []  # (start, end) of every false candidate

    def good(self, named):
        name, raw = named
        start = len(self.data)
        self.data += raw
        end = len(self.data)
        held = self.candidate_end
        # held behind the candidate when its last byte comes before the
        # candidate's (the candidate has not failed yet)
        decided = end if held is None or end > held else held
        self.frames.append([name, start, end, decided])

    def noise(self, raw):
        assert b"\x00\xff\x5a" not in raw
        self.data += raw

    def false(self, size):
        """A false candidate whose Size byte is `size`: the frames added
        until its end are held behind it."""
        start = len(self.data)
        self.data += false_start(size)
        self.candidate_end = start + size - 2 + 8
        self.candidates.append((start, self.candidate_end))
        return start

    def fill_candidate(self):
        need = self.candidate_end - len(self.data)
        assert need > 0
        self.noise(b"\x11" * need)
        self.candidate_end = None

    def leave_candidate(self):
        self.candidate_end = None

    def finish(self):
        if self.candidate_end is not None and self.candidate_end > len(self.data):
            for fr in self.frames:
                if fr[3] == self.candidate_end:
                    fr[3] = None  # the candidate never completes
        for fr in self.frames:
            assert fr[3] is None or fr[3] <= len(self.data)
        for start, end in self.candidates:  # each one is cut or fails its checksum
            assert all(p.offset > 0 for p in tase.decode(self.data[start:end]))


# The issue 12 repro's inner frame: GIMBAL_CMD pan 90.00, tilt -10.00.
INNER = gimbal_cmd(9000, -1000, 0)[1]


def scenario(name):
    out, inn = Stream(), Stream()
    if name == "camera-pass":
        out.good(gimbal_angle(1234, -4500))
        out.noise(b"\x07\x5a")
        out.good(gimbal_angle(-1, 1))
        out.good(gimbal_angle(17999, 0))
        inn.good(packet("RETRACT_DEPLOY_CMD", deploy=1))
        inn.good(camera_pass(INNER))
        inn.good(gimbal_cmd(1000, -500, 0xA0))
        inn.good(camera_pass(b"\x55" + INNER + b"\x66" * 12))
    elif name == "held":
        # from the gimbal: a candidate with Size byte 200 hides three
        # frames; one frame starts inside it and ends after it; a second
        # false candidate still pending at the end hides one more.
        out.good(gimbal_angle(100, 200))
        start = out.false(200)
        out.good(gimbal_angle(-300, 400))
        out.noise(b"\x01\x02\x03")
        out.good(packet("GIMBAL_RATE", time=77, pan_rate=1, tilt_rate=2, roll_rate=3, p=4, q=5,
                        r=6, mode=0x81))
        out.good(gimbal_angle(500, -600))
        out.noise(b"\x11" * (out.candidate_end - len(out.data) - 5))
        straddle = len(out.data)
        out.leave_candidate()
        out.good(gimbal_angle(700, -800))  # ends after the candidate
        assert straddle < start + 206 < len(out.data)
        out.good(gimbal_angle(900, -1000))
        out.false(0xF0)
        out.good(gimbal_angle(-900, 1000))
        out.noise(b"\x22" * 20)
        # to the gimbal: a candidate hides a CAMERA_PASS carrying a valid
        # GIMBAL_CMD frame (only the CAMERA_PASS counts) and a GIMBAL_CMD.
        inn.false(144)
        inn.good(camera_pass(INNER + b"\x66" * 12))
        inn.good(gimbal_cmd(-2000, 300, 0x10))
        inn.fill_candidate()
        inn.good(gimbal_cmd(0, 0, 0xA0))
    else:
        raise SystemExit("unknown scenario " + name)
    out.finish()
    inn.finish()
    return out, inn


def quiet(out, gap):
    """Issue 27: a serial capture (from the gimbal) whose first record is
    the false sync 00 FF 5A FF followed by a GIMBAL_CMD, the second, `gap`
    seconds later, the bytes that complete the false sync as a valid
    261-byte frame (type 0x00/0xFF) and a GIMBAL_ANGLE. A live receiver
    whose quiet limit is below the gap judged the false sync on its own,
    so the GIMBAL_CMD, then the GIMBAL_ANGLE; with a shorter gap the
    261-byte frame (hiding the GIMBAL_CMD), then the GIMBAL_ANGLE."""
    inner = gimbal_cmd(9000, -1000, 0xA0)[1]
    cand = tase.Packet.from_data(0x00, 0xFF, inner[2:] + bytes(253 - len(inner) + 2)).encode()
    assert cand[:4] == bytes([0x00, 0xFF, 0x5A, 0xFF]) and cand[4:4 + len(inner)] == inner
    first = cand[:4 + len(inner)]
    rest = cand[4 + len(inner):] + gimbal_angle(100, 200)[1]
    ns = int(Decimal(gap) * 10**9)
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        f.write(pcap_record(T0, 1000000, bytes([DIRS["out"]]) + first))
        f.write(pcap_record(T0 + (1000000 + ns) // 10**9, (1000000 + ns) % 10**9,
                            bytes([DIRS["out"]]) + rest))


def times(out):
    """Issue 25 item 6: a serial capture of three GIMBAL_ANGLEs stamped
    2147483647.75 (the last second a signed 32-bit field holds), 2147483648.25
    (past 2038-01-19 03:14:07: the unsigned field) and 1700000000 s plus
    1,500,000,000 ns (a fraction not normalised: 1700000001.5), 2^31 ns and
    2^32 - 1 ns (an unsigned fraction libpcap hands over negative:
    1700000002.147483, 1700000004.294967)."""
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        for i, (sec, ns) in enumerate([(2147483647, 750000000), (2147483648, 250000000),
                                       (1700000000, 1500000000), (1700000000, 0x80000000),
                                       (1700000000, 0xFFFFFFFF)]):
            f.write(pcap_record(sec, ns, bytes([DIRS["out"]]) + gimbal_angle(i, 0)[1]))


def replay_checks(out_cut, out_bad, out_back):
    """Issue 25 item 7: captures replay must check before sending anything.
    out_cut: five GIMBAL_ANGLEs 0.1 s apart, the file cut inside the last
    record's header; out_bad: the same with record 4 of direction 7;
    out_back: four GIMBAL_ANGLEs stamped 0, 0.5, 0.2 (a clock stepped back)
    and 0.7 s: replayed 0.5 s apart (the step is no gap; the gaps after it
    keep their lengths), 1.0 s in all."""
    recs = [pcap_record(T0, i * 100000000, b"\x00" + gimbal_angle(i, 0)[1]) for i in range(5)]
    data = pcap_header(LINKTYPE_SERIAL) + b"".join(recs)
    with open(out_cut, "wb") as f:
        f.write(data[:-len(recs[-1]) + 9])
    recs[3] = pcap_record(T0, 300000000, b"\x07" + gimbal_angle(3, 0)[1])
    with open(out_bad, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL) + b"".join(recs))
    with open(out_back, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        for i, ns in enumerate([0, 500000000, 200000000, 700000000]):
            f.write(pcap_record(T0, ns, b"\x00" + gimbal_angle(i, 0)[1]))


def held_cut(out):
    """A review: a serial capture whose first record holds a false start
    (Size 200) and then a whole GIMBAL_ANGLE (pan 1, tilt 2), the second
    record two more, the file cut 5 bytes before its end (inside record 2).
    The GIMBAL_ANGLE of record 1 is whole before the cut: `tase decode`
    must print it (the held false start is decided at the end) before it
    says where the file is cut."""
    a = gimbal_angle(1, 2)[1]
    data = (pcap_header(LINKTYPE_SERIAL)
            + pcap_record(T0, 0, b"\x00" + false_start(200) + a)
            + pcap_record(T0, 1000000, b"\x00" + gimbal_angle(3, 4)[1] + gimbal_angle(5, 6)[1]))
    with open(out, "wb") as f:
        f.write(data[:-5])


def step_back(out, days):
    """A review: a GIMBAL_ANGLE split 5 + 9 bytes over two records, the
    second stamped `days` days before the first (a clock stepped back).
    A step back is no pause: `tase decode` must give the frame for any
    step (30 days, between 2^31 and 2^32 ms, wrapped the receiver's 32-bit
    clock into a long pause that cut it)."""
    a = gimbal_angle(7, 8)[1]
    back = T0 - int(Decimal(days) * 86400)
    with open(out, "wb") as f:
        f.write(pcap_header(LINKTYPE_SERIAL))
        f.write(pcap_record(T0, 0, b"\x00" + a[:5]))
        f.write(pcap_record(back, 0, b"\x00" + a[5:]))


def pcapng_block(btype, body):
    """A little-endian pcapng block: type, total length, body padded to 4
    bytes, total length again (the pcapng draft's general block)."""
    body += bytes(-len(body) % 4)
    return struct.pack("<II", btype, len(body) + 12) + body + struct.pack("<I", len(body) + 12)


def spb(out, other="no"):
    """A review: a GEOREFERENCE_DATA (63 bytes of data 0..62) from the
    gimbal split over three records of a pcapng, the middle one a Simple
    Packet Block (no time): an Enhanced Packet Block at T, the SPB, an EPB
    at T + 1 ms. Both tools must give the frame (the dissector took the
    SPB's time as 1970, and the gap cut the frame). other "yes": a record
    to the gimbal at T + 500 ms comes before the SPB, whose time is then
    that one's (the record before it, any direction): a 500 ms pause in
    the frame, which both tools must judge alike (the dissector took its
    own stream's time, T, and kept the frame)."""
    f = tase.Packet.from_data(0x10, 0x41, bytes(range(63))).encode()
    t0 = T0 * 10**6

    def epb(t, data):
        return pcapng_block(6, struct.pack("<IIIII", 0, t >> 32, t & 0xFFFFFFFF, len(data),
                                           len(data)) + data)

    with open(out, "wb") as fh:
        fh.write(pcapng_block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1)))
        fh.write(pcapng_block(1, struct.pack("<HHI", LINKTYPE_SERIAL, 0, 65535)))
        fh.write(epb(t0, b"\x00" + f[:5]))
        if other == "yes":
            fh.write(epb(t0 + 500000, b"\x01" + gimbal_angle(1, 1)[1]))
        fh.write(pcapng_block(3, struct.pack("<I", 26) + b"\x00" + f[5:30]))
        fh.write(epb(t0 + 1000, b"\x00" + f[30:]))


def reader_edges(d):
    """A fuzzing review's captures of the readers' edges, each a
    GIMBAL_ANGLE from the gimbal: a microsecond pcap whose fractions are
    5,000,000 us, 2^31 us and 2^32 - 1 us (usfrac; libpcap hands the last two
    over negative, times 1000); a record claiming more bytes captured than its
    packet had (capbig); a pcapng whose if_tsoffset puts it before 1970
    (negtime); a frame split over an Enhanced and a Simple Packet Block
    (spb); CAN captures of only a remote frame (rtr) and of only a 3AX
    frame (3ax)."""
    f = bytes.fromhex("00FF5A08081004D2EE6C000003A9")
    usec = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, LINKTYPE_SERIAL)
    with open(d + "/usfrac.pcap", "wb") as fh:
        fh.write(usec + b"".join(pcap_record(T0, frac, b"\0" + f)
                                 for frac in (5000000, 0x80000000, 0xFFFFFFFF)))
    with open(d + "/capbig.pcap", "wb") as fh:
        fh.write(pcap_header(LINKTYPE_SERIAL) + struct.pack("<IIII", T0, 0, 15, 3) + b"\0" + f)
    shb = pcapng_block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))

    def idb(offset):  # if_tsresol 6 (microseconds), if_tsoffset
        opts = struct.pack("<HHB3x", 9, 1, 6) + struct.pack("<HHq", 14, 8, offset) + bytes(4)
        return pcapng_block(1, struct.pack("<HHI", LINKTYPE_SERIAL, 0, 65535) + opts)

    def epb(us, data):
        return pcapng_block(6, struct.pack("<IIIII", 0, us >> 32, us & 0xFFFFFFFF, len(data),
                                           len(data)) + data)

    t = (T0 * 10**6) + 250000
    with open(d + "/negtime.pcapng", "wb") as fh:
        fh.write(shb + idb(-T0 - 1) + epb(t, b"\0" + f))
    with open(d + "/spb.pcapng", "wb") as fh:
        fh.write(shb + idb(0) + epb(t, b"\0" + f[:6]) +
                 pcapng_block(3, struct.pack("<I", 9) + b"\0" + f[6:]))

    def can(cid, dlc, data):
        return pcap_record(T0, 0, struct.pack(">IBBBB", cid, dlc, 0, 0, 0) + data.ljust(8, b"\0"))

    with open(d + "/rtr.pcap", "wb") as fh:
        fh.write(pcap_header(LINKTYPE_CAN) + can(0xD0000000, 0, b""))
    with open(d + "/3ax.pcap", "wb") as fh:
        fh.write(pcap_header(LINKTYPE_CAN) + can(0x92010000 | 0x80000000, 2, b"\1\2"))


def unknown(out):
    """A serial capture (from the gimbal) of packets of a type the schema
    does not know, 0x77/0x01, with no data, 2 bytes and none again."""
    with open(out, "wb") as fh:
        fh.write(pcap_header(LINKTYPE_SERIAL))
        for i, data in enumerate((b"", b"\1\2", b"")):
            fh.write(pcap_record(T0 + i, 0, b"\0" + tase.Packet.from_data(0x77, 0x01, data).encode()))


def cut_records(streams, sizes):
    """Round-robin records of the given sizes (cycled) from each stream:
    [(dir, stream offset of the end, bytes)]."""
    pos = {d: 0 for d in streams}
    out, k = [], 0
    while any(pos[d] < len(streams[d].data) for d in streams):
        for d in ("out", "in"):
            data = streams[d].data
            if pos[d] < len(data):
                n = sizes[k % len(sizes)]
                k += 1
                chunk = data[pos[d]:pos[d] + n]
                pos[d] += len(chunk)
                out.append((d, pos[d], chunk))
    return out


def greedy(scen, fmt, path, expect):
    out, inn = scenario(scen)
    streams = {"out": out, "in": inn}
    sizes = [5, 11, 3, 13, 8, 1, 9, 2] if fmt == "pcap" else [8, 3, 8, 1, 5, 8, 7, 2]
    recs = cut_records(streams, sizes)
    times = [Decimal(T0) + Decimal(n + 1) / 1000 + Decimal(7 * n) / 1000000
             for n in range(len(recs))]

    def packet_of(d, offset):
        """the packet (1-based) carrying the byte before `offset`"""
        for n, (rd, end, _) in enumerate(recs):
            if rd == d and end >= offset:
                return n + 1
        raise AssertionError("offset %d of %s beyond the capture" % (offset, d))

    lines, held_split = [], 0
    for d in ("out", "in"):
        for name, start, end, decided in streams[d].frames:
            last = packet_of(d, end)
            dec = None if decided is None else packet_of(d, decided)
            if dec != last and packet_of(d, start + 1) != last:
                held_split += 1
            lines.append({"dir": d, "offset": start, "name": name, "last": last,
                          "decided": dec, "time": str(times[last - 1].quantize(USEC))})
    # A frame carried by a CAMERA_PASS ends records before the CAMERA_PASS
    # does (a receiver judging candidates on their own shows it, first).
    early = 0
    for name, start, end, _ in inn.frames:
        i = inn.data.find(INNER, start, end)
        if name == "CAMERA_PASS" and i >= 0:
            early += packet_of("in", i + len(INNER)) < packet_of("in", end)
    assert early >= 1
    if scen == "held":
        assert held_split >= 3 and any(x["decided"] is None for x in lines)
    with open(path, "wb") as f:
        if fmt == "pcap":
            f.write(pcap_header(LINKTYPE_SERIAL))
            for (d, _, chunk), t in zip(recs, times):
                ns = int((t - T0) * 10**9)
                f.write(pcap_record(T0 + ns // 10**9, ns % 10**9, bytes([DIRS[d]]) + chunk))
        else:
            for (d, _, chunk), t in zip(recs, times):
                ident = "10000000" if d == "out" else "11000000"
                f.write(("(%s) vcan0 %s#%s\n" % (t.quantize(USEC), ident, chunk.hex().upper()))
                        .encode())
    with open(expect, "w") as f:
        for x in lines:
            f.write(json.dumps(x) + "\n")


def expect_decode(expect, jsonl):
    exp = [json.loads(line) for line in open(expect)]
    got = [json.loads(line, parse_float=Decimal) for line in open(jsonl)]
    bad = 0
    for d in ("out", "in"):
        e = [(x["offset"], x["name"], Decimal(x["time"]).quantize(USEC, ROUND_DOWN))
             for x in exp if x["dir"] == d]
        g = [(x["offset"], x["name"], x.get("time")) for x in got if x.get("dir") == d]
        if e != g:
            print("dir %s: tase decode printed\n  %s\nexpected\n  %s" % (d, g, e))
            bad += 1
    print("tase decode: %d frames as expected" % len(exp) if not bad else "tase decode differs")
    return 1 if bad else 0


def pdml_frames(pdml):
    """(packet, dir, offset, name, annotation) of every TASE frame shown."""
    out = []
    for n, (_, protos) in enumerate(pdml_packets(pdml)):
        for p in protos:
            vals = {f.get("name"): f.get("show") for f in p.findall("field")}
            if vals.get("tase.name", "").startswith("3AX_"):
                continue
            note = None
            for key in HELD_FIELDS:
                if "tase." + key in vals:
                    note = key if key == "decided_at_end" else "%s %s" % (key, vals["tase." + key])
            out.append((n + 1, vals.get("tase.dir"), int(vals["tase.offset"]),
                        vals["tase.name"], note))
    return out


def expect_pdml(expect, pdml, passes):
    exp = []
    for x in map(json.loads, open(expect)):
        last, dec = x["last"], x["decided"]
        if passes == "2":
            note = ("decided_at_end" if dec is None else
                    None if dec == last else "decided_in %d" % dec)
            exp.append((last, x["dir"], x["offset"], x["name"], note))
        elif dec is not None:
            exp.append((dec, x["dir"], x["offset"], x["name"],
                        None if dec == last else "last_byte_in %d" % last))
    exp.sort(key=lambda e: e[0])  # by packet; within one, stream order
    got = pdml_frames(pdml)
    if got != exp:
        print("the dissector (%s pass%s) showed:" % (passes, "es" if passes == "2" else ""))
        for g in got:
            print("  " + repr(g))
        print("expected:")
        for e in exp:
            print("  " + repr(e))
        return 1
    print("%d frames in the expected packets" % len(exp))
    return 0


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
    for t, linktype, r in read_pcap(pcap):
        if linktype == LINKTYPE_SERIAL:
            print(t, r[0], r[1:].hex().upper())
        else:
            can_id, n = struct.unpack(">IB", r[:5])
            print(t, "%08X#%s" % (can_id, r[8:8 + n].hex().upper()))


def paced_angles(tty, n, pause, jitter, gap):
    fd = os.open(tty, os.O_RDWR | os.O_NOCTTY)
    rng = random.Random(7)
    for i in range(int(n)):
        _, f = gimbal_angle(i, 0)
        os.write(fd, f[:6])
        time.sleep((float(pause) + rng.random() * float(jitter)) / 1000)
        os.write(fd, f[6:])
        time.sleep(float(gap) / 1000)
    os.close(fd)


def timing(sent, got, d, speed, tol):
    want = DIRS[d]
    sbytes = [(t, b) for t, _, r in read_pcap(sent) if r[0] == want for b in r[1:]]
    gbytes = [(t, b) for t, _, r in read_pcap(got) if r[0] == 0 for b in r[1:]]
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
    """Run the command argv[1]: the function of that name (- for _)."""
    commands = {f.__name__.replace("_", "-"): f for f in (
        serial_pcap, expect_serial, can_pcap, replay_checks, times, quiet, bad_pcap, pty_pair,
        compare_pdml, greedy, expect_decode, expect_pdml, pdml_3ax, records, paced_angles,
        timing, held_cut, step_back, spb, reader_edges,
        unknown)}
    if len(argv) < 2 or argv[1] not in commands:
        raise SystemExit("usage: capture_util.py COMMAND ARGS... (commands: %s)"
                         % ", ".join(commands))
    return commands[argv[1]](*argv[2:]) or 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
