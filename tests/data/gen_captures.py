#!/usr/bin/env python3
"""Writes the decode test captures and, from the values it encoded, the JSON
lines `tase decode` must print for them. The packet layouts below are typed
in from the spec tables, independently of the library's schema table, so a
mistake in either shows up as a difference.

Run from anywhere: python3 tests/data/gen_captures.py
Outputs (next to this script):
  decode_noisy.bin / decode_noisy.jsonl        raw serial bytes with noise
  decode_candump.log / decode_candump.jsonl    the same kind of traffic as a
                                               candump log, both directions (each
                                               packet with the time of the line
                                               carrying its last byte)
  klv_noisy.bin / klv_noisy.jsonl              KLV packets (spec table 31, built
                                               here) with noise, a corrupted and
                                               a cut packet; the expected lines
                                               hold offset and raw fields
"""
import json
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))

U8, S16, U16, S32, U32 = ("u8", 1, False), ("s16", 2, True), ("u16", 2, False), \
    ("s32", 4, True), ("u32", 4, False)

# name -> (group, type, [(json name or None for Reserved, kind)])
PACKETS = {
    "GIMBAL_CMD": (0x00, 0x80, [("pan", S16), ("tilt", S16), ("roll", S16),
                                ("flags", U8), ("impulse_time", U8)]),
    "RETRACT_DEPLOY_CMD": (0x00, 0x43, [("deploy", U8), (None, U8)]),
    "CAMERA_PASS": (0x00, 0x42, [("camera", U8), ("baud", U8), (None, U8), (None, U8)]),
    "GIMBAL_ANGLE": (0x08, 0x10, [("pan", S16), ("tilt", S16), ("roll", S16)]),
    "GIMBAL_RATE": (0x08, 0x40, [("time", U32), ("pan_rate", S16), ("tilt_rate", S16),
                                 ("roll_rate", S16), ("p", S16), ("q", S16), ("r", S16),
                                 (None, U8), ("mode", U8)]),
    "HOST_GPS_DATA": (0x10, 0x10, [("time", U32), ("lat", S32), ("lon", S32),
                                   ("height", S32), ("vnorth", S16), ("veast", S16),
                                   ("vdown", S16), ("year", U16), ("month", U8),
                                   ("day", U8), ("hour", U8), ("minute", U8),
                                   ("second", U8), ("frac_second", U8), ("valid", U8),
                                   ("sample_rate", U8)]),
    "SPOI_CMD": (0x10, 0x40, [("lat", S32), ("lon", S32), ("height", S32),
                              ("vnorth", S16), ("veast", S16), ("vdown", S16),
                              ("flags", U8)]),
    "PACKET_RATE": (0x48, 0x00, [("angle_1", U8), ("rate_1", U8), ("geo_ref_1", U8),
                                 ("camera_1", U8), (None, U8),
                                 ("angle_2", U8), ("rate_2", U8), ("geo_ref_2", U8),
                                 ("camera_2", U8), (None, U8),
                                 ("angle_3", U8), ("rate_3", U8), ("geo_ref_3", U8),
                                 ("camera_3", U8), (None, U8), ("temporary", U8)]),
}


def frame(group, ptype, data):
    body = bytes([0x00, 0xFF, 0x5A, len(data) + 2, group, ptype]) + bytes(data)
    s = sum(body) & 0xFFFF
    return body + bytes([s >> 8, s & 0xFF])


def packet(name, values, extra=b""):
    """Encode a known packet; return (frame bytes, expected fields dict)."""
    group, ptype, layout = PACKETS[name]
    data = bytearray()
    fields = {}
    for fname, (_, width, signed) in layout:
        v = 0 if fname is None else values[fname]
        data += int(v).to_bytes(width, "big", signed=signed)
        if fname is not None:
            fields[fname] = v
    data += extra
    return frame(group, ptype, data), name, group, ptype, len(data), fields


class Stream:
    def __init__(self):
        self.buf = bytearray()
        self.expect = []

    def noise(self, raw):
        self.buf += bytes(raw)

    def good(self, enc, extra_data=None):
        raw, name, group, ptype, size, fields = enc
        obj = {"offset": len(self.buf), "group": group, "type": ptype, "name": name,
               "size": size, "fields": fields}
        if extra_data is not None:
            obj["data"] = list(extra_data)
        self.expect.append(obj)
        self.buf += raw

    def query(self, name):
        group, ptype, _ = PACKETS[name]
        self.expect.append({"offset": len(self.buf), "group": group, "type": ptype,
                            "name": name, "size": 0, "fields": {}})
        self.buf += frame(group, ptype, b"")

    def unknown(self, group, ptype, data):
        self.expect.append({"offset": len(self.buf), "group": group, "type": ptype,
                            "name": "UNKNOWN", "size": len(data),
                            "fields": {"data": list(data)}})
        self.buf += frame(group, ptype, data)

    def wrong_length(self, name, data):
        group, ptype, _ = PACKETS[name]
        self.expect.append({"offset": len(self.buf), "group": group, "type": ptype,
                            "name": name, "size": len(data), "error": "wrong length"})
        self.buf += frame(group, ptype, data)

    def corrupt(self, raw, index, value):
        raw = bytearray(raw)
        raw[index] = value
        self.buf += raw


def noisy_capture(rng):
    s = Stream()
    s.noise([0x13, 0x37, 0x00, 0xFF])  # leading noise, half a sync
    s.good(packet("GIMBAL_ANGLE", {"pan": 1234, "tilt": -4500, "roll": 0}))
    s.good(packet("GIMBAL_RATE", {"time": 3000000000, "pan_rate": -32768, "tilt_rate": 32767,
                                  "roll_rate": 0, "p": -1, "q": 250, "r": -250, "mode": 0x81}))
    s.noise(rng.randbytes(17))
    # a checksum error: a data byte flipped
    bad, *_ = packet("GIMBAL_ANGLE", {"pan": 1, "tilt": 2, "roll": 3})
    s.corrupt(bad, 7, bad[7] ^ 0x10)
    s.good(packet("HOST_GPS_DATA", {"time": 123456, "lat": 162000000, "lon": -442800000,
                                    "height": 15000, "vnorth": 1000, "veast": -2000,
                                    "vdown": 30, "year": 2024, "month": 5, "day": 17,
                                    "hour": 13, "minute": 45, "second": 59,
                                    "frac_second": 99, "valid": 1, "sample_rate": 10}))
    # a corrupted Size byte claiming 253 data bytes must not hide what follows
    bad, *_ = packet("GIMBAL_ANGLE", {"pan": -1, "tilt": -2, "roll": -3})
    s.corrupt(bad, 3, 0xFF)
    s.good(packet("GIMBAL_CMD", {"pan": -1000, "tilt": 500, "roll": 0, "flags": 0x90,
                                 "impulse_time": 0}))
    s.query("PACKET_RATE")
    s.good(packet("PACKET_RATE", {"angle_1": 10, "rate_1": 10, "geo_ref_1": 4, "camera_1": 0,
                                  "angle_2": 5, "rate_2": 5, "geo_ref_2": 2, "camera_2": 0,
                                  "angle_3": 0, "rate_3": 0, "geo_ref_3": 0, "camera_3": 0,
                                  "temporary": 1}))
    s.noise([0x00, 0xFF, 0x5A, 0x01])  # a sync with an impossible Size (< 2)
    s.good(packet("RETRACT_DEPLOY_CMD", {"deploy": 1}))
    passthru = bytes([0x81, 0x01, 0x04, 0x07, 0x02, 0xFF])
    s.good(packet("CAMERA_PASS", {"camera": 1, "baud": 8}, passthru), passthru)
    s.unknown(0x28, 0x01, bytes([1, 2, 250]))
    s.wrong_length("GIMBAL_ANGLE", bytes([0x01, 0x02, 0x03, 0x04]))
    s.noise(rng.randbytes(9))
    s.good(packet("SPOI_CMD", {"lat": -162000001, "lon": 648000000, "height": -500,
                               "vnorth": 0, "veast": 0, "vdown": 0, "flags": 0x80}))
    s.good(packet("GIMBAL_ANGLE", {"pan": -18000, "tilt": 9000, "roll": 0}))
    # a frame cut off by the end of the capture is dropped at flush
    tail, *_ = packet("GIMBAL_ANGLE", {"pan": 5, "tilt": 5, "roll": 5})
    s.noise(tail[:9])
    return s


def candump(rng):
    """Both directions interleaved in 1..8-byte CAN frames, plus 3AX frames
    that must be ignored. Offsets count each direction's bytes separately."""
    gin, gout = Stream(), Stream()
    gin.good(packet("GIMBAL_CMD", {"pan": 2000, "tilt": -300, "roll": 0, "flags": 0x10,
                                   "impulse_time": 0}))
    gout.good(packet("GIMBAL_ANGLE", {"pan": 100, "tilt": -200, "roll": 0}))
    gin.query("PACKET_RATE")
    gout.noise([0x55, 0x00])
    gout.good(packet("PACKET_RATE", {"angle_1": 10, "rate_1": 10, "geo_ref_1": 4,
                                     "camera_1": 0, "angle_2": 10, "rate_2": 10,
                                     "geo_ref_2": 4, "camera_2": 0, "angle_3": 10,
                                     "rate_3": 10, "geo_ref_3": 4, "camera_3": 0,
                                     "temporary": 0}))
    bad, *_ = packet("GIMBAL_ANGLE", {"pan": 7, "tilt": 7, "roll": 7})
    gout.corrupt(bad, 8, bad[8] ^ 1)
    gout.good(packet("GIMBAL_RATE", {"time": 42, "pan_rate": 2000, "tilt_rate": 0,
                                     "roll_rate": 0, "p": 0, "q": 0, "r": 0, "mode": 0}))
    gin.good(packet("RETRACT_DEPLOY_CMD", {"deploy": 0}))

    def chunks(st):
        out, i = [], 0
        while i < len(st.buf):
            n = rng.randint(1, 8)
            out.append(bytes(st.buf[i:i + n]))
            i += n
        return out

    cin, cout = chunks(gin), chunks(gout)
    for o in gin.expect:
        o["dir"] = "in"
    for o in gout.expect:
        o["dir"] = "out"
    # the line on which each packet's last byte arrives decides output order
    lines, expect = [], []
    t = 1700000000.0
    pos = {"in": 0, "out": 0}
    pending = {"in": list(gin.expect), "out": list(gout.expect)}
    sizes = {"in": [len(frame(0, 0, b"")) + o.get("size", 0) for o in gin.expect],
             "out": [len(frame(0, 0, b"")) + o.get("size", 0) for o in gout.expect]}
    queues = {"in": cin, "out": cout}
    while queues["in"] or queues["out"]:
        which = rng.choice([d for d in ("in", "out") if queues[d]])
        data = queues[which].pop(0)
        can_id = "11000000" if which == "in" else "10000000"
        t += 0.000731
        stamp = "%.6f" % t
        lines.append("(%s) vcan0 %s#%s" % (stamp, can_id, data.hex().upper()))
        pos[which] += len(data)
        while pending[which]:
            o = pending[which][0]
            if o["offset"] + sizes[which][0] > pos[which]:
                break
            o["time"] = stamp  # the line that carried the packet's last byte
            o["interface"] = "vcan0"
            expect.append(pending[which].pop(0))
            sizes[which].pop(0)
        if rng.random() < 0.3:
            t += 0.0001
            lines.append("(%.6f) vcan0 12020000#%02X%02X" % (t, rng.randint(0, 254),
                                                          rng.randint(0, 255)))
    return "\n".join(lines) + "\n", expect


# KLV (spec section 6, table 31): key, BER length, tag/length/value items.
KLV_KEY = bytes([0x06, 0x0E, 0x2B, 0x34, 0x02, 0x03, 0x01, 0x01] + [0] * 8)
KLV_ITEMS = [("utc", 8, False), ("lat", 4, True), ("lon", 4, True), ("alt", 2, False),
             ("pan", 2, False), ("tilt", 2, True), ("heading", 2, False),
             ("pitch", 2, True), ("roll", 2, True), ("vnorth", 2, True),
             ("veast", 2, True), ("hfov", 2, False), ("vfov", 2, False),
             ("gps_status", 2, False)]


def klv_packet(values, declared=70):
    body = b""
    for tag, (name, width, signed) in enumerate(KLV_ITEMS, start=1):
        body += bytes([tag, width]) + values[name].to_bytes(width, "big", signed=signed)
    check = sum(body) & 0xFFFF  # every local-set byte before the checksum item
    body += bytes([15, 2]) + check.to_bytes(2, "big")
    assert len(body) == 70
    return KLV_KEY + bytes([declared]) + body


def klv_values(rng):
    v = {}
    for name, width, signed in KLV_ITEMS:
        bits = 8 * width
        if signed:
            v[name] = rng.randint(-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
        else:
            v[name] = rng.randint(0, (1 << bits) - 1)
    return v


def klv_capture(rng):
    buf = bytearray()
    expect = []

    def good(declared=70):
        v = klv_values(rng)
        expect.append({"offset": len(buf), "fields": v})
        buf.extend(klv_packet(v, declared))

    for i in range(12):
        kind = i % 6
        if kind == 1:  # noise, with stray key bytes and a partial key
            buf.extend(bytes(rng.randint(0, 255) for _ in range(rng.randint(1, 40))))
            buf.extend(KLV_KEY[:rng.randint(1, 15)])
        elif kind == 2:  # a packet with one value byte flipped: rejected
            bad = bytearray(klv_packet(klv_values(rng)))
            bad[17 + 2 + rng.randint(0, 7)] ^= 0x10
            buf.extend(bad)
        elif kind == 3:  # a packet cut short, the next one follows at once
            buf.extend(klv_packet(klv_values(rng))[:rng.randint(17, 80)])
        elif kind == 4:  # the spec's own declared length
            good(69)
            continue
        good()
    buf.extend(b"\x06\x0e\x2b")  # an unfinished key at the end
    return bytes(buf), expect


def dump(path, objs):
    """One JSON object per line, keys in the contract's order: offset, then
    time, dir and interface when present. Times are the capture's own text
    (seconds with six decimals), written as JSON numbers."""
    meta = ("offset", "time", "dir", "interface")
    with open(path, "w") as f:
        for o in objs:
            o = {**{k: o[k] for k in meta if k in o},
                 **{k: v for k, v in o.items() if k not in meta}}
            line = json.dumps(o, separators=(",", ":"))
            if "time" in o:
                line = line.replace('"time":"%s"' % o["time"], '"time":%s' % o["time"])
            f.write(line + "\n")


def main():
    rng = random.Random(6)
    s = noisy_capture(rng)
    with open(os.path.join(HERE, "decode_noisy.bin"), "wb") as f:
        f.write(s.buf)
    dump(os.path.join(HERE, "decode_noisy.jsonl"), s.expect)
    log, expect = candump(rng)
    with open(os.path.join(HERE, "decode_candump.log"), "w") as f:
        f.write(log)
    dump(os.path.join(HERE, "decode_candump.jsonl"), expect)
    klv, expect = klv_capture(random.Random(7))
    with open(os.path.join(HERE, "klv_noisy.bin"), "wb") as f:
        f.write(klv)
    dump(os.path.join(HERE, "klv_noisy.jsonl"), expect)


if __name__ == "__main__":
    main()
