#!/usr/bin/env python3
"""Write stream.h: the byte stream the QEMU firmware example "receives on its
UART", and the results the image must find in it.

The stream mixes clean host->gimbal frames with line noise and corruption
(bit flips, a Size byte that claims 253 data bytes, Size 0 and 1, a
truncated frame, false 00 FF 5A syncs in garbage, a bad checksum, an
incomplete frame at the end). The expected results come from an
independent reference model of the receiver rules in include/tase/frame.h,
written here in Python and sharing no code with src/frame.c, and are
cross-checked against what the generator meant to put in the stream.

Run from this directory: python3 mkstream.py > stream.h (stream.h is
committed, so building the image needs no Python)."""
import random

SYNC = [0x00, 0xFF, 0x5A]
MAX_CANDIDATES = 4  # TASE_RX_CANDIDATES default; the model ignores the limit


def frame(group, ptype, data):
    body = SYNC + [len(data) + 2, group, ptype] + list(data)
    s = sum(body) & 0xFFFF
    return body + [s >> 8, s & 0xFF]


def model(stream):
    """Reference receiver: candidates start at every 00 FF 5A not inside a
    delivered frame; Size < 2 rejects; a candidate is judged when its last
    byte arrives; a valid one drops the candidates that began inside it."""
    cands = []  # dicts: start, end (None until Size seen)
    floor = 0
    out, csum_err, bad_size, overlap = [], 0, 0, 0
    for q, _ in enumerate(stream):
        if q >= 2 and q - 2 >= floor and stream[q - 2:q + 1] == SYNC:
            cands.append({"start": q - 2, "end": None})
        overlap = max(overlap, len(cands))
        i = 0
        while i < len(cands):
            c = cands[i]
            event = c["end"] if c["end"] is not None else c["start"] + 3
            if event != q:
                i += 1
                continue
            if c["end"] is None:
                size = stream[q]
                if size < 2:
                    bad_size += 1
                    del cands[i]
                else:
                    c["end"] = c["start"] + size + 5
                    i += 1
                continue
            s, e = c["start"], c["end"]
            want = (stream[e - 1] << 8) | stream[e]
            if sum(stream[s:e - 1]) & 0xFFFF != want:
                csum_err += 1
                del cands[i]
                continue
            out.append((s, stream[s + 4], stream[s + 5], stream[s + 3] - 2))
            floor = e + 1
            cands = cands[:i] + [d for d in cands[i + 1:] if d["start"] > e]
    covered = set()
    for s, _, _, n in out:
        covered.update(range(s, s + n + 8))
    return out, csum_err, bad_size, len(stream) - len(covered), overlap


def main():
    rnd = random.Random(8)
    stream, intended, replies = [], [], []

    def noise(n, avoid_sync=True):
        for _ in range(n):
            stream.append(rnd.randrange(256))
        if avoid_sync:  # keep accidental syncs out of plain noise
            for i in range(len(stream) - n, len(stream)):
                if stream[i - 2:i + 1] == SYNC:
                    stream[i] = 0x5B

    def clean(group, ptype, data, reply=None):
        intended.append((len(stream), group, ptype, len(data)))
        stream.extend(frame(group, ptype, data))
        if reply is not None:
            replies.append((group, ptype, list(reply)))

    def corrupt(group, ptype, data, how):
        f = frame(group, ptype, data)
        how(f)
        stream.extend(f)

    rates_default = [10, 10, 4, 0, 0] * 3 + [0]
    version = [0, 1, 0, 1, 0x07, 0xE8, 5, 17] + [0] * 16 + [3, 0, 0x0F, 0xA0, 0x00, 0xC8] \
        + [0xFF, 0, 0, 0, 0, 0] * 2
    noise(37)
    clean(0x48, 0x00, [], rates_default)                 # PACKET_RATE query
    noise(5)
    stream.extend([0x00, 0xFF])                          # partial sync, then a frame
    clean(0x00, 0x80, [0x11, 0x94, 0xFC, 0x18, 0, 0, 0xA0, 0])  # GIMBAL_CMD 45.00/-10.00
    corrupt(0x00, 0x80, [0x01, 0x02, 0xFC, 0x18, 0, 0, 0xA0, 0],
            lambda f: f.__setitem__(8, f[8] ^ 0x10))     # bit flip in data
    clean(0x48, 0x01, [], [100, 5])                      # SENSOR_FILTER query: defaults
    corrupt(0x48, 0x03, [], lambda f: f.__setitem__(3, 0xFF))  # Size claims 253 bytes
    clean(0x48, 0x03, [], version)                       # SYSTEM_VERSION query, inside it
    clean(0x00, 0x40, [])                                # GYRO_ZERO_CMD
    noise(20)
    clean(0x48, 0x01, [80, 3], [80, 3])                  # SENSOR_FILTER set: echoed
    corrupt(0x48, 0x04, [], lambda f: f.__setitem__(3, 1))  # Size 1
    corrupt(0x48, 0x04, [], lambda f: f.__setitem__(3, 0))  # Size 0
    clean(0x48, 0x04, [], [0, 0])                        # NAV_SOURCE query
    stream.extend(frame(0x08, 0x42, list(range(12)))[:9])   # truncated HOST_ATTITUDE
    clean(0x00, 0x80, [0xEE, 0x6C, 0x03, 0xE8, 0, 0, 0xA0, 0])  # GIMBAL_CMD -45.00/10.00
    for _ in range(6):                                   # garbage with false syncs
        noise(rnd.randrange(3, 40))
        stream.extend(SYNC + [rnd.randrange(2, 256)])
    noise(300)  # outlasts the false syncs' claimed sizes
    corrupt(0x08, 0x41, list(range(18)), lambda f: f.__setitem__(len(f) - 1, f[-1] ^ 1))
    clean(0x48, 0x01, [], [80, 3])                       # SENSOR_FILTER query: kept
    for _ in range(3):
        clean(0x08, 0x42, [rnd.randrange(256) for _ in range(12)])  # HOST_ATTITUDE
        noise(rnd.randrange(0, 8))
    stream.extend(frame(0x48, 0x00, [])[:5])             # incomplete at end of input

    found, csum_err, bad_size, discarded, overlap = model(stream)
    assert found == intended, (found, intended)
    assert overlap <= MAX_CANDIDATES, overlap

    w = print
    w("/* Generated by examples/firmware/mkstream.py: do not edit. The recorded")
    w(" * UART stream fed to the example image and the results it must give. */")
    w("#ifndef STREAM_H")
    w("#define STREAM_H")
    w("#include <stdint.h>")
    w("")
    w("static const uint8_t stream_bytes[%d] = {" % len(stream))
    for i in range(0, len(stream), 16):
        w("    " + " ".join("0x%02X," % b for b in stream[i:i + 16]))
    w("};")
    w("")
    w("typedef struct {")
    w("    uint32_t offset;")
    w("    uint8_t group, type, len;")
    w("} expect_frame_t;")
    w("")
    w("/* Every clean frame, in delivery order. */")
    w("static const expect_frame_t expect_frames[%d] = {" % len(found))
    for s, g, t, n in found:
        w("    {%u, 0x%02X, 0x%02X, %u}," % (s, g, t, n))
    w("};")
    w("")
    w("#define EXPECT_CHECKSUM_ERRORS %du" % csum_err)
    w("#define EXPECT_BAD_SIZE %du" % bad_size)
    w("#define EXPECT_BYTES_DISCARDED %du" % discarded)
    w("")
    w("/* The replies the gimbal must send, in order: setup packets echoed with")
    w(" * the current settings. */")
    w("typedef struct {")
    w("    uint8_t group, type, len;")
    w("    const uint8_t *data;")
    w("} expect_reply_t;")
    w("")
    for i, (_, _, d) in enumerate(replies):
        w("static const uint8_t reply_data_%d[%d] = {%s};" %
          (i, max(len(d), 1), ", ".join("0x%02X" % b for b in d) or "0"))
    w("static const expect_reply_t expect_replies[%d] = {" % len(replies))
    for i, (g, t, d) in enumerate(replies):
        w("    {0x%02X, 0x%02X, %d, reply_data_%d}," % (g, t, len(d), i))
    w("};")
    w("")
    w("/* Last clean GIMBAL_CMD: pan, tilt in 1/100 degree. */")
    w("#define EXPECT_CMD_PAN (-4500)")
    w("#define EXPECT_CMD_TILT 1000")
    w("#define EXPECT_GYRO_ZEROS 1u")
    w("/* Valid frames the gimbal does not act on (HOST_ATTITUDE). */")
    w("#define EXPECT_IGNORED %du" % sum(1 for f in found if f[1] not in (0x00, 0x48)))
    w("")
    w("#endif /* STREAM_H */")


if __name__ == "__main__":
    main()
