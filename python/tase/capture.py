"""Captures of `tase record` (pcap or pcapng; docs/TOOLS.md, Captures):
tase.read_capture(path) yields (time, packet) exactly as `tase decode FILE`
prints them: each direction (serial records by their direction byte, CAN
frames by their ID) fed to its own C receiver, the record times as the
receivers' clock (a gap settles a held candidate as on the live line), a
packet's time that of the record carrying its last byte.
"""

import collections
import os
import struct
import time

from ._core import Decoder, Error, _with_meta, ffi, lib

__all__ = ["read_capture", "records", "CaptureLink", "CaptureWriter"]

LINKTYPE_SERIAL = 147  # LINKTYPE_USER0: direction byte + bytes
LINKTYPE_CAN = 227  # LINKTYPE_CAN_SOCKETCAN
_HIST = 264  # chunks remembered for frame times (tools/toolkit.h TK_HIST)
_CAN_EFF = 0x80000000
_CAN_RTR = 0x40000000
_CAN_ERR = 0x20000000
# First bytes of the files read_capture() takes (pcap us/ns, both byte
# orders; pcapng).
MAGICS = (
    b"\xd4\xc3\xb2\xa1",
    b"\x4d\x3c\xb2\xa1",
    b"\xa1\xb2\xc3\xd4",
    b"\xa1\xb2\x3c\x4d",
    b"\x0a\x0d\x0d\x0a",
)


class CaptureError(Error, ValueError):
    """A file that is not a capture tase can read."""


def _pcap(f, head):
    magic = head[:4]
    if magic in MAGICS[0:2]:
        e = "<"
    elif magic in MAGICS[2:4]:
        e = ">"
    else:
        raise CaptureError("not a pcap file")
    nano = magic in (b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\x3c\x4d")
    rest = f.read(20)
    if len(rest) < 20:
        raise CaptureError("pcap header cut short")
    linktype = struct.unpack(e + "HHiIII", rest)[5] & 0x0FFFFFFF
    index = 0
    while True:
        h = f.read(16)
        if not h:
            return
        if len(h) < 16:
            raise CaptureError("record %d: header cut short" % (index + 1))
        sec, frac, incl, orig = struct.unpack(e + "IIII", h)
        data = f.read(incl)
        index += 1
        if len(data) < incl:
            raise CaptureError("record %d: cut short" % index)
        usec = frac // 1000 if nano else frac
        yield index, linktype, sec * 1000000 + usec, data, incl < orig


def _pcapng(f, head):
    index = 0
    e = "<"
    ifaces = []
    while True:
        h = head if head else f.read(8)
        head = None
        if not h:
            return
        if len(h) < 8:
            raise CaptureError("pcapng block cut short")
        btype = struct.unpack(e + "I", h[:4])[0]
        if btype == 0x0A0D0D0A:
            bom = f.read(4)
            e = "<" if bom == b"\x4d\x3c\x2b\x1a" else ">"
            blen = struct.unpack(e + "I", h[4:8])[0]
            f.read(blen - 12)
            ifaces = []
            continue
        blen = struct.unpack(e + "I", h[4:8])[0]
        body = f.read(blen - 8)
        if len(body) < blen - 8 or blen < 12:
            raise CaptureError("pcapng block cut short")
        body = body[:-4]
        if btype == 1:  # interface description
            linktype = struct.unpack(e + "H", body[:2])[0]
            res = 1000000
            opts = body[8:]
            while len(opts) >= 4:
                code, olen = struct.unpack(e + "HH", opts[:4])
                if code == 0:
                    break
                if code == 9 and olen >= 1:
                    r = opts[4]
                    res = 2 ** (r & 0x7F) if r & 0x80 else 10 ** r
                opts = opts[4 + (olen + 3) // 4 * 4 :]
            ifaces.append((linktype, res))
        elif btype in (6, 3):  # enhanced / simple packet
            index += 1
            if btype == 6:
                iface, hi, lo, incl, orig = struct.unpack(e + "IIIII", body[:20])
                data = body[20 : 20 + incl]
            else:
                iface, hi, lo = 0, 0, 0
                orig = struct.unpack(e + "I", body[:4])[0]
                data = body[4:]
                incl = len(data)
            if iface >= len(ifaces):
                raise CaptureError("record %d: unknown interface" % index)
            linktype, res = ifaces[iface]
            ts = hi << 32 | lo
            usec = ts * 1000000 // res
            yield index, linktype, usec, data, incl < orig


def records(path):
    """(index, linktype, time_us, bytes, cut) of every record of a pcap or
    pcapng file."""
    f = open(path, "rb")
    with f:
        head = f.read(4)
        if head == b"\x0a\x0d\x0d\x0a":
            yield from _pcapng(f, head + f.read(4))
        else:
            yield from _pcap(f, head)


class CaptureWriter:
    """Write a serial capture as `tase record` does: nanosecond pcap, link
    type 147, one record per read or write (a direction byte, 0 from the
    gimbal, 1 to it, then the bytes). An existing file is appended to when
    it is such a capture (as `--record`), else refused; a new one is
    created. Every record is flushed."""

    _HEADER = struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, LINKTYPE_SERIAL)

    def __init__(self, path):
        self.path = path
        self.records = 0
        if os.path.exists(path) and os.path.getsize(path) > 0:
            with open(path, "rb") as f:
                head = f.read(24)
            if head != self._HEADER:
                raise CaptureError(
                    "%s: not a nanosecond serial capture of tase record: not appending" % path
                )
            self.f = open(path, "ab")
        else:
            self.f = open(path, "wb")
            self.f.write(self._HEADER)
            self.f.flush()

    def put(self, dir, data, t_ns=None):
        """One record: dir 0 (bytes from the gimbal) or 1 (to it)."""
        t = time.time_ns() if t_ns is None else t_ns
        for i in range(0, len(data), 4096):
            chunk = bytes((dir,)) + bytes(data[i : i + 4096])
            self.f.write(
                struct.pack("<IIII", t // 1000000000, t % 1000000000, len(chunk), len(chunk))
                + chunk
            )
            self.records += 1
        self.f.flush()

    def close(self):
        self.f.close()


class _Stream:
    def __init__(self, dir, rate):
        self.dec = Decoder(rate, dir)
        self.dir = dir
        self.hist = collections.deque(maxlen=_HIST)
        self.last = None

    def _timed(self, packets, fallback):
        out = []
        for p in packets:
            end = p.offset + p.size + 8
            t = fallback
            for e, tt in reversed(self.hist):
                if e < end:
                    break
                t = tt
            out.append(_with_meta(p, t, self.dir))
        return out

    def bytes(self, data, t):
        ms = (t // 1000) & 0xFFFFFFFF
        out = self._timed(self.dec.tick(ms), self.last)
        self.last = t
        self.hist.append((self.dec.bytes + len(data), t))
        out += self._timed(self.dec.feed(data), t)
        out += self._timed(self.dec.tick(ms), t)
        return out

    def finish(self):
        return self._timed(self.dec.flush(), self.last)


class Capture:
    """Iterate over (time, packet) of a capture; .bad lists the malformed
    records skipped ((index, reason)), .stats the receivers' counters."""

    def __init__(self, path, baud=57600):
        self.path = path
        self.rate = baud // 10
        self.bad = []
        self.streams = {}

    def _stream(self, dir, rate):
        s = self.streams.get(dir)
        if s is None:
            s = self.streams[dir] = _Stream(dir, rate)
        return s

    def __iter__(self):
        frame = ffi.new("tase_can_frame_t *")
        for index, linktype, t, data, cut in records(self.path):
            if linktype == LINKTYPE_SERIAL:
                if cut:
                    self.bad.append((index, "cut by the snapshot length"))
                    continue
                if len(data) < 2:
                    self.bad.append((index, "no bytes"))
                    continue
                if data[0] not in (0, 1):
                    self.bad.append((index, "bad direction byte 0x%02X" % data[0]))
                    continue
                s = self._stream("out" if data[0] == 0 else "in", self.rate)
                got = s.bytes(data[1:], t)
            elif linktype == LINKTYPE_CAN:
                if len(data) < 8:
                    self.bad.append((index, "CAN record shorter than its header"))
                    continue
                cid, dlc = struct.unpack(">IB", data[:5])
                if dlc > len(data) - 8:
                    self.bad.append((index, "CAN payload longer than the record"))
                    continue
                if cid & (_CAN_RTR | _CAN_ERR) or len(data) > 16 or not cid & _CAN_EFF or dlc > 8:
                    continue
                frame.id = cid & 0x1FFFFFFF
                frame.extended = True
                frame.dlc = dlc
                ffi.memmove(frame.data, data[8 : 8 + dlc], dlc)
                n = lib.tase_can_accept(lib.TASE_CAN_ROLE_HOST, frame)
                dir = "out"
                if n <= 0:
                    n = lib.tase_can_accept(lib.TASE_CAN_ROLE_GIMBAL, frame)
                    dir = "in"
                if n <= 0:
                    continue
                s = self._stream(dir, lib.TASE_SOCKETCAN_BYTES_PER_S)
                got = s.bytes(data[8 : 8 + n], t)
            else:
                raise CaptureError(
                    "%s: link type %d is neither TASE serial (147) nor SocketCAN (227)"
                    % (self.path, linktype)
                )
            for p in got:
                yield p.time, p
        for s in self.streams.values():
            for p in s.finish():
                yield p.time, p


def read_capture(path, baud=57600):
    """Yield (time, packet) for every packet of a `tase record` capture, as
    `tase decode FILE` prints them (same packets, order, offsets, times);
    `baud`: the serial line's rate, for the receivers' time bound (as
    decode's --baud). time is Unix seconds (packet.time_us exact)."""
    return iter(Capture(path, baud))


class CaptureLink:
    """capture:FILE: a read-only link over a capture (packets() only)."""

    def __init__(self, path):
        self.url = "capture:" + path
        self.path = path
        self._cap = Capture(path)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def close(self):
        pass

    def packets(self, timeout=None, count=None):
        n = 0
        for _, p in self._cap:
            if count is not None and n >= count:
                return
            n += 1
            yield p

    def _read_only(self, *args, **kw):
        raise Error("%s: a capture is read only: nothing can be sent" % self.url)

    send = query = point = rate = spoi = retract = deploy = camera = _read_only
