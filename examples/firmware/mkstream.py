#!/usr/bin/env python3
"""Write stream.h: the byte stream the QEMU firmware example "receives on its
UART", and the results the image must find in it.

The stream mixes clean host->gimbal frames with line noise and corruption
(bit flips, a Size byte that claims 253 data bytes, Size 0 and 1, a
truncated frame, false 00 FF 5A syncs in garbage, a bad checksum, an
incomplete frame at the end). The expected results come from an
independent reference model of the receiver rules in include/tase/frame.h,
written here in Python and sharing no code with src/tase_frame.c, and are
cross-checked against what the generator meant to put in the stream.

Run from this directory: python3 mkstream.py > stream.h (stream.h is
committed, so building the image needs no Python)."""
import random

SYNC = [0x00, 0xFF, 0x5A]


def frame(group, ptype, data):
    body = SYNC + [len(data) + 2, group, ptype] + list(data)
    s = sum(body) & 0xFFFF
    return body + [s >> 8, s & 0xFF]


def model(stream, arrive, pause_at, settle_after):
    """Reference receiver: the greedy scan of include/tase/frame.h. From the
    start of the stream, where a complete frame with a valid checksum
    begins it is taken and the scan continues after its last byte;
    anywhere else the scan moves on one byte. A frame is delivered once the
    bytes that decide it are in: its own last byte, or the last byte of an
    earlier candidate whose failure released it (a frame inside a pending
    candidate is held until that candidate fails). TIME BOUND: a candidate
    still pending when the line goes quiet (before byte `pause_at`, and at
    the end of the stream) fails once the line has been quiet for longer
    than its quiet limit: settle_after(bytes it still needs) ticks after
    the tick of its last byte that came, if that is before the line speaks
    again. `arrive(i)` is the tick that feeds byte i. Returns the frames
    (start, group, type, data length, tick deciding it), the checksum
    and Size errors, and the bytes not in a delivered frame."""
    out, csum_err, bad_size = [], 0, 0
    pos, decided, n = 0, 0, len(stream)
    settled = None  # (first byte after the quiet, the tick it settled at)
    while pos < n:
        if settled is not None and pos >= settled[0]:
            settled = None
        if stream[pos:pos + 3] == SYNC and pos + 3 < n:
            size = stream[pos + 3]
            e = pos + size + 5  # index of the candidate's last byte
            quiet_at = pause_at if pos < pause_at <= e else (n if e >= n else None)
            if settled is None and quiet_at is not None:
                at = arrive(quiet_at - 1) + settle_after(e + 1 - quiet_at)
                if quiet_at == n or at < arrive(quiet_at):
                    settled = (quiet_at, at)  # judged false before it completes
            if size < 2:
                bad_size += 1
            elif settled is not None and e >= settled[0]:
                decided = max(decided, settled[1])  # can no longer complete
            elif e < n:
                decided = max(decided, arrive(e))
                want = (stream[e - 1] << 8) | stream[e]
                if sum(stream[pos:e - 1]) & 0xFFFF == want:
                    out.append((pos, stream[pos + 4], stream[pos + 5], size - 2, decided))
                    pos = e + 1
                    continue
                csum_err += 1
        pos += 1
    return out, csum_err, bad_size, n - sum(f[3] + 8 for f in out)


# ---- what the gimbal application does (examples/firmware/gimbal.c), as a
# model: which frames it gets and how, what it answers, what telemetry it
# sends when. Written from the spec's tables (4.1 .. 4.4), not from src/.

BYTES_PER_TICK = 12  # the simulated UART interrupt delivers 12 bytes per 1 ms tick
RUN_MS = 1000        # the main loop polls the gimbal at t = 1 .. RUN_MS
PAUSE_MS = 100       # the line is quiet this long once, after noise and a command
# The receiver's time bound (include/tase/frame.h, TIME BOUND) as the
# image sets it: 115200 baud (11,520 bytes/s), the 20 ms default margin.
LINE_BYTES_PER_S = 11520
QUIET_MS = 20


def settle_after(left):
    """Ticks after the last byte at which a held candidate still needing
    `left` bytes is judged false: the first tick quiet for longer than
    max(the bytes' time at the line's rate, the margin)."""
    limit = max(-(-left * 1000 // LINE_BYTES_PER_S), QUIET_MS)
    return limit + 1

# Big-endian layouts of the packets in the stream (spec tables 5, 14, 20,
# 21, 24): one letter per field, x = reserved byte.
LAYOUT = {
    (0x00, 0x80): ("hhhBB", 8),             # GIMBAL_CMD
    (0x00, 0x40): ("", 0),                  # GYRO_ZERO_CMD
    (0x08, 0x42): ("IhhhBB", 12),           # HOST_ATTITUDE
    (0x10, 0x40): ("iiihhhB", 19),          # SPOI_CMD
    (0x48, 0x00): ("BBBBxBBBBxBBBBxB", 16),  # PACKET_RATE
    (0x48, 0x01): ("BB", 2),                # SENSOR_FILTER
    (0x48, 0x02): (None, 23),               # AXIS_SETTING (fields not traced)
    (0x48, 0x03): (None, 42),               # SYSTEM_VERSION (queried only)
    (0x48, 0x04): ("BB", 2),                # NAV_SOURCE
}
QUERYABLE = {(0x48, t) for t in range(8)} | {(0x10, 0x40)}
ROUTE_TYPED, ROUTE_ERROR, ROUTE_DEFAULT = 0, 1, 2
# GIMBAL_CMD flags of the spec's table 5 (4.1.1): a command with other
# flags is refused by the application (the stream's commands are all
# within the axes' ranges, the other half of tase_command_check()).
GIMBAL_CMD_FLAGS = {0x00, 0x01, 0x02, 0x03, 0x10, 0x90, 0x20, 0xA0, 0x30, 0xB0, 0xC0, 0xD0}


def fields(fmt, data):
    out, i = [], 0
    for c in fmt:
        w = {"B": 1, "h": 2, "i": 4, "I": 4, "x": 1}[c]
        v = int.from_bytes(bytes(data[i:i + w]), "big", signed=c in "hi")
        i += w
        if c != "x":
            out.append(v)
    assert i == len(data)
    return out


def route(group, ptype, n):
    if (group, ptype) not in LAYOUT:
        return ROUTE_DEFAULT
    if n == LAYOUT[(group, ptype)][1] or (n == 0 and (group, ptype) in QUERYABLE):
        return ROUTE_TYPED
    return ROUTE_ERROR


def sim_pan(t):
    return (3 * t) % 18000


def sim_tilt(t):
    return -(t % 9000)


def mode_byte(flags):
    """GIMBAL_RATE Mode byte (spec 4.2.2; bit 0 = MSB) for the last
    GIMBAL_CMD flags (4.1.1): bit 0 stabilisation, bits 3-7 the mode
    (0 rate, 1 position, 2 SPOI; PROTOCOL-NOTES D2)."""
    kind = (flags >> 4) & 7
    if kind == 0:  # legacy: 0x02 stabilisation, 0x01 position
        stab, mode = flags & 0x02, 1 if flags & 0x01 else 0
    else:  # 1 rate, 2 position, 3 impulse (a timed rate), 4-5 SPOI error
        stab, mode = flags & 0x80, {2: 1, 4: 2, 5: 2}.get(kind, 0)
    return (0x80 if stab else 0) | mode


SPOI_MODE = 0x80 | 2  # stabilised SPOI (PROTOCOL-NOTES P4)
LAT_MAX_MAS, LON_MAX_MAS = 90 * 3600000, 180 * 3600000


def spoi_ok(v):
    """A SPOI_CMD point the application tracks (tase_command_check():
    latitude within 90 degrees, longitude within 180)."""
    return abs(v[0]) <= LAT_MAX_MAS and abs(v[1]) <= LON_MAX_MAS


def spoi_data(lat_deg, lon_deg, height_m, flags):
    d = []
    for v, w in ((round(lat_deg * 3600000), 4), (round(lon_deg * 3600000), 4),
                 (round(height_m * 100), 4), (150, 2), (-20, 2), (0, 2)):
        d += list(v.to_bytes(w, "big", signed=True))
    return d + [flags]


def telemetry(events):
    """Per-millisecond model of the gimbal role's schedule (gimbal.h,
    SCHEDULE): a stream anchored at a with rate r sends slot n >= 1 at
    a + floor(n * 1000 / r). The main loop polls at t, then handles the
    frames the bytes of tick t decide, so a change made at tick t
    counts from the poll at t + 1. Rate changes re-anchor at t; unchanged
    streams keep their phase."""
    rates = [10, 10, 4]
    anchor, nxt = [0, 0, 0], [1, 1, 1]
    cmd = (0, 0, 0)  # pan, tilt, flags of the last GIMBAL_CMD
    spoi = False     # tracking a SPOI (SPOI mode)
    out = []
    ids = [(0x08, 0x10), (0x08, 0x40), (0x10, 0x41)]
    for t in range(1, RUN_MS + 1):
        for s in range(3):
            if rates[s] and t >= anchor[s] + nxt[s] * 1000 // rates[s]:
                nxt[s] += 1
                if s == 0:
                    v = [sim_pan(t), sim_tilt(t), 0]
                elif s == 1:
                    v = [t, cmd[0], cmd[1], 0, 0, 0, 0, SPOI_MODE if spoi else mode_byte(cmd[2])]
                else:
                    v = [t, 1000 * t, -2000 * t, 12345, sim_pan(t), sim_tilt(t), rates[2], 4000]
                out.append((ids[s], t, v))
        for kind, data in events.get(t, []):
            if kind == "cmd":
                k = (data[3] >> 4) & 7
                if k in (4, 5) and not spoi:
                    continue  # a SPOI error with no SPOI: nothing changes
                spoi = spoi and k in (3, 4, 5)  # rate, position, legacy end it
                cmd = (data[0], data[1], data[3])
            elif kind == "spoi":
                spoi, cmd = True, (0, 0, cmd[2])  # the SPOI error cleared
            else:
                new = [data[0], data[1], data[2]]
                for s in range(3):
                    if new[s] != rates[s]:
                        rates[s], anchor[s], nxt[s] = new[s], t, 1
    return out


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
    rates_new = [20, 10, 4, 0, 0] + [10, 10, 4, 0, 0] * 2 + [1]  # angle on port 1 at 20 Hz
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
    clean(0x48, 0x00, rates_new, rates_new)              # PACKET_RATE set: echoed
    noise(20)
    clean(0x48, 0x01, [80, 3], [80, 3])                  # SENSOR_FILTER set: echoed
    # AXIS_SETTING all zeros (max rates 0 lock the axes, temporary 0
    # stores it): refused, the settings in force echoed (the role's
    # defaults: tilt no-go 90/60 deg, max rates 60, accelerations 50,
    # gains 40 on pan and tilt)
    axis_default = [0, 0, 0, 0, 0x23, 0x28, 0x17, 0x70, 0, 0, 0, 0, 60, 0, 60, 0, 50, 50, 0,
                    40, 40, 0, 0]
    clean(0x48, 0x02, [0] * 23, axis_default)
    clean(0x00, 0x80, [0x11, 0x94, 0xFC, 0x18, 0, 0])    # GIMBAL_CMD, 6 bytes: error hook
    corrupt(0x48, 0x04, [], lambda f: f.__setitem__(3, 1))  # Size 1
    corrupt(0x48, 0x04, [], lambda f: f.__setitem__(3, 0))  # Size 0
    clean(0x48, 0x04, [], [0, 0])                        # NAV_SOURCE query
    clean(0x28, 0x00, [1, 2, 3])                         # group 0x28: unknown, default handler
    stream.extend(frame(0x08, 0x42, list(range(12)))[:9])   # truncated HOST_ATTITUDE
    clean(0x00, 0x80, [0xEE, 0x6C, 0x03, 0xE8, 0, 0, 0xA0, 0])  # GIMBAL_CMD -45.00/10.00
    clean(0x00, 0x80, [0x75, 0x30, 0x80, 0x00, 0, 0, 0x55, 0])  # flags 0x55: refused, -45/10 kept
    clean(0x48, 0x01, [7, 8, 9])                         # SENSOR_FILTER, 3 bytes: error hook
    for _ in range(6):                                   # garbage with false syncs
        noise(rnd.randrange(3, 40))
        stream.extend(SYNC + [rnd.randrange(2, 256)])
    noise(300)  # outlasts the false syncs' claimed sizes
    # Issue 27: noise that looks like a sync with Size 255 (257 more bytes
    # claimed), a GIMBAL_CMD, then the line goes quiet for PAUSE_MS: the
    # command comes out by the time bound, not when 257 more bytes came.
    noise((-len(stream) - 4 - 16) % BYTES_PER_TICK)
    stream.extend([0x00, 0xFF, 0x5A, 0xFF])
    quiet_cmd = len(stream)
    clean(0x00, 0x80, [0x03, 0xE8, 0x07, 0xD0, 0, 0, 0xA0, 0])  # GIMBAL_CMD 10.00/20.00
    pause_at = len(stream)
    assert pause_at % BYTES_PER_TICK == 0
    corrupt(0x08, 0x41, list(range(18)), lambda f: f.__setitem__(len(f) - 1, f[-1] ^ 1))
    clean(0x48, 0x01, [], [80, 3])                       # SENSOR_FILTER query: kept
    clean(0x48, 0x00, [], rates_new)                     # PACKET_RATE query: the new rates
    # SPOI_CMD: a query before any (zeros, the mode of the last GIMBAL_CMD:
    # stabilised position), a SPOI error command with no SPOI (ignored), a
    # point beyond 90 deg of latitude (refused, no echo), a point with the
    # echo flag (SPOI mode), a SPOI error command in SPOI mode (applied,
    # still SPOI), a query (the point, SPOI mode)
    clean(0x10, 0x40, [], [0] * 18 + [mode_byte(0xA0)])
    clean(0x00, 0x80, [0x00, 0x64, 0xFF, 0x38, 0, 0, 0xC0, 0])  # SPOI error 1.00/-2.00
    clean(0x10, 0x40, spoi_data(90.5, 7.25, 500, 0x80))
    spoi = spoi_data(45.0123, -7.25, 612.5, 0x80)
    clean(0x10, 0x40, spoi, spoi[:18] + [SPOI_MODE])
    clean(0x00, 0x80, [0x00, 0x64, 0xFF, 0x38, 0, 0, 0xC0, 0])
    clean(0x10, 0x40, [], spoi[:18] + [SPOI_MODE])
    for _ in range(3):
        clean(0x08, 0x42, [rnd.randrange(256) for _ in range(12)])  # HOST_ATTITUDE
        noise(rnd.randrange(0, 8))
    stream.extend(frame(0x48, 0x00, [])[:5])             # incomplete at end of input

    def arrive(i):
        return i // BYTES_PER_TICK + 1 + (PAUSE_MS if i >= pause_at else 0)

    found, csum_err, bad_size, discarded = model(stream, arrive, pause_at, settle_after)
    assert [f[:4] for f in found] == intended, (found, intended)
    assert arrive(len(stream) - 1) <= RUN_MS
    quiet_tick = [f[4] for f in found if f[0] == quiet_cmd][0]
    assert quiet_tick == arrive(pause_at - 1) + settle_after(261 - 20), quiet_tick

    # What each frame must reach the application as, and when.
    rows, values, events = [], [], {}
    for s, g, t, n, decided in found:
        data = stream[s + 6:s + 6 + n]
        r = route(g, t, n)
        v = []
        fmt = LAYOUT.get((g, t), (None, 0))[0]
        if r == ROUTE_TYPED and fmt is not None:  # a query decodes to zeros
            v = fields(fmt, data) if n > 0 else [0] * len(fmt.replace("x", ""))
        rows.append((s, g, t, n, r, len(values), len(v), decided))
        values.extend(v)
        tick = decided  # the tick whose bytes decide it
        if r == ROUTE_TYPED and (g, t) == (0x00, 0x80) and v[3] in GIMBAL_CMD_FLAGS:
            events.setdefault(tick, []).append(("cmd", v))
        if r == ROUTE_TYPED and (g, t) == (0x10, 0x40) and n > 0 and spoi_ok(v):
            events.setdefault(tick, []).append(("spoi", v))
        if r == ROUTE_TYPED and (g, t) == (0x48, 0x00) and n > 0:
            events.setdefault(tick, []).append(("rates", data))
    telem = telemetry(events)

    w = print
    w("/* Generated by examples/firmware/mkstream.py: do not edit. The recorded")
    w(" * UART stream fed to the example image and the results it must give. */")
    w("#ifndef STREAM_H")
    w("#define STREAM_H")
    w("#include <stdint.h>")
    w("")
    w("#define STREAM_BYTES_PER_TICK %du" % BYTES_PER_TICK)
    w("#define STREAM_RUN_MS %du" % RUN_MS)
    w("/* the line is quiet for STREAM_PAUSE_MS ticks before this byte */")
    w("#define STREAM_PAUSE_AT %du" % pause_at)
    w("#define STREAM_PAUSE_MS %du" % PAUSE_MS)
    w("#define STREAM_LINE_BYTES_PER_S %du" % LINE_BYTES_PER_S)
    w("")
    w("static const uint8_t stream_bytes[%d] = {" % len(stream))
    for i in range(0, len(stream), 16):
        w("    " + " ".join("0x%02X," % b for b in stream[i:i + 16]))
    w("};")
    w("")
    w("/* How a frame reaches the application. */")
    w("#define ROUTE_TYPED 0u   /* typed handler, decoded */")
    w("#define ROUTE_ERROR 1u   /* error hook, TASE_ELENGTH */")
    w("#define ROUTE_DEFAULT 2u /* default handler: unknown packet */")
    w("")
    w("typedef struct {")
    w("    uint32_t offset;")
    w("    uint8_t group, type, len, route;")
    w("    uint8_t first, nfields; /* decoded fields: expect_values[first..] */")
    w("    uint16_t tick;          /* the main loop tick whose bytes decide it */")
    w("} expect_frame_t;")
    w("")
    w("/* Every clean frame, in delivery order. */")
    w("static const expect_frame_t expect_frames[%d] = {" % len(rows))
    for s, g, t, n, r, first, nf, tick in rows:
        w("    {%u, 0x%02X, 0x%02X, %u, %u, %u, %u, %u}," % (s, g, t, n, r, first, nf, tick))
    w("};")
    w("")
    w("/* Decoded field values of the typed frames, in the spec's field order. */")
    w("static const int64_t expect_values[%d] = {" % len(values))
    for i in range(0, len(values), 8):
        w("    " + " ".join("%d," % v for v in values[i:i + 8]))
    w("};")
    w("")
    w("#define EXPECT_CHECKSUM_ERRORS %du" % csum_err)
    w("#define EXPECT_BAD_SIZE %du" % bad_size)
    w("#define EXPECT_BYTES_DISCARDED %du" % discarded)
    w("#define EXPECT_BAD_LENGTH %du" % sum(1 for r in rows if r[4] == ROUTE_ERROR))
    w("#define EXPECT_UNKNOWN %du" % sum(1 for r in rows if r[4] == ROUTE_DEFAULT))
    w("/* settings the application refuses (AXIS_SETTING max rates 0) */")
    w("#define EXPECT_SETUPS_REFUSED %du" % sum(
        1 for r in rows if (r[1], r[2]) == (0x48, 0x02) and r[3] == 23
        and 0 in (stream[r[0] + 6 + 12], stream[r[0] + 6 + 14])))
    w("/* GIMBAL_CMDs the application refuses (flags not of table 5) */")
    w("#define EXPECT_COMMANDS_REFUSED %du" % sum(
        1 for r in rows if r[4] == ROUTE_TYPED and (r[1], r[2]) == (0x00, 0x80)
        and values[r[5] + 3] not in GIMBAL_CMD_FLAGS))
    spoi_rows = [r for r in rows if r[4] == ROUTE_TYPED and (r[1], r[2]) == (0x10, 0x40)]
    w("/* SPOI_CMD points tracked, refused (beyond the Earth's ranges), and")
    w(" * queries; SPOI error commands with no SPOI in force (ignored) */")
    w("#define EXPECT_SPOIS %du" % sum(
        1 for r in spoi_rows if r[3] > 0 and spoi_ok(values[r[5]:r[5] + 2])))
    w("#define EXPECT_SPOIS_REFUSED %du" % sum(
        1 for r in spoi_rows if r[3] > 0 and not spoi_ok(values[r[5]:r[5] + 2])))
    w("#define EXPECT_SPOI_QUERIES %du" % sum(1 for r in spoi_rows if r[3] == 0))
    ignored, in_spoi = 0, False
    for r in rows:
        if r[4] != ROUTE_TYPED:
            continue
        if (r[1], r[2]) == (0x10, 0x40) and r[3] > 0 and spoi_ok(values[r[5]:r[5] + 2]):
            in_spoi = True
        elif (r[1], r[2]) == (0x00, 0x80) and values[r[5] + 3] in GIMBAL_CMD_FLAGS:
            k = (values[r[5] + 3] >> 4) & 7
            ignored += k in (4, 5) and not in_spoi
            in_spoi = in_spoi and k in (3, 4, 5)
    w("#define EXPECT_COMMANDS_IGNORED %du" % ignored)
    w("")
    w("/* The replies the gimbal must send, in order: setup packets echoed with")
    w(" * the current settings, SPOI_CMD answers. */")
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
    w("/* The telemetry the gimbal must send, in order: packet, the poll time")
    w(" * (ms) and decoded values. GIMBAL_ANGLE: pan, tilt, roll. GIMBAL_RATE:")
    w(" * time, pan_rate, tilt_rate, roll_rate, p, q, r, mode. GEOREFERENCE_DATA:")
    w(" * time, lat, lon, height, pan, tilt, sample_rate, hfov. */")
    w("typedef struct {")
    w("    uint8_t group, type;")
    w("    uint16_t t;")
    w("    int32_t v[8];")
    w("} expect_telemetry_t;")
    w("")
    w("static const expect_telemetry_t expect_telemetry[%d] = {" % len(telem))
    for (g, t), ms, v in telem:
        w("    {0x%02X, 0x%02X, %d, {%s}}," % (g, t, ms, ", ".join(str(x) for x in v)))
    w("};")
    w("")
    w("#endif /* STREAM_H */")


if __name__ == "__main__":
    main()
