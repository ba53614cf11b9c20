"""Captures of `tase record` (pcap or pcapng; docs/TOOLS.md, Captures):
tase.read_capture(path) yields (time, packet) exactly as `tase decode FILE`
prints them: each direction (serial records by their direction byte, CAN
frames by their ID) fed to its own C receiver, the record times as the
receivers' clock (a gap settles a held candidate as on the live line), a
packet's time that of the record carrying its last byte.
"""

import collections
import errno
import fcntl
import os
import signal
import stat
import struct
import time

from ._core import Decoder, Error, FieldError, LinkError, TimeoutError_, _with_meta, ffi, lib
from .link import _close_dropped, _packets_limits

__all__ = ["read_capture", "records", "CaptureLink", "CaptureWriter"]

LINKTYPE_SERIAL = 147  # LINKTYPE_USER0: direction byte + bytes
LINKTYPE_CAN = 227  # LINKTYPE_CAN_SOCKETCAN
_HIST = 264  # chunks remembered for frame times (tools/toolkit.h TK_HIST)
_CAN_EFF = 0x80000000
_CAN_RTR = 0x40000000
_CAN_ERR = 0x20000000
_CANFD_FDF = 0x04  # flags byte of a SocketCAN record: an FD frame
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
    """A file that is not a capture tase can read, or one that cannot be
    written (a full disk)."""


# libpcap's bounds (sf-pcap.c, sf-pcapng.c): a record longer than any
# snapshot length, a block longer than its reader takes, is a damaged file
# (and would be read into memory whole)
_MAX_SNAPLEN = 262144
_MAX_BLOCK = 16 * 1024 * 1024
_SHB = b"\x0a\x0d\x0d\x0a"
_BOM = 0x1A2B3C4D


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
    major, minor, _, _, snaplen, linktype = struct.unpack(e + "HHiIII", rest)
    # the versions libpcap (tase decode) opens: 2.0 to 2.4, and 543.0
    # (these were read whatever their version)
    if major < 2:
        raise CaptureError("archaic pcap savefile format")
    if not ((major == 2 and minor <= 4) or (major, minor) == (543, 0)):
        raise CaptureError("unsupported pcap savefile version %d.%d" % (major, minor))
    linktype &= 0x03FFFFFF  # as libpcap (LT_LINKTYPE): the low 26 bits name it
    if snaplen == 0 or snaplen > _MAX_SNAPLEN:
        snaplen = _MAX_SNAPLEN  # libpcap's adjustment
    index = 0
    while True:
        h = f.read(16)
        if not h:
            return
        if len(h) < 16:
            raise CaptureError("record %d: header cut short" % (index + 1))
        sec, frac, incl, orig = struct.unpack(e + "IIII", h)
        if incl > _MAX_SNAPLEN:
            raise CaptureError(
                "record %d: invalid packet capture length %d, bigger than maximum of %d"
                % (index + 1, incl, _MAX_SNAPLEN)
            )
        data = f.read(incl)
        index += 1
        if len(data) < incl:
            raise CaptureError("record %d: cut short" % index)
        if incl > snaplen:
            # as libpcap: read, but given up to the snapshot length only, so
            # the record is cut (tase decode skips it; this gave it whole)
            data = data[:snaplen]
        usec = frac // 1000 if nano else frac
        yield index, linktype, sec * 1000000 + usec, data, _damage(len(data), orig)


def _damage(incl, orig):
    """Why a record of `incl` bytes captured of a packet of `orig` is
    skipped, as tase decode says it, or None."""
    if incl < orig:
        return "cut to %d of its %d bytes by the capture's snapshot length" % (incl, orig)
    if incl > orig:  # no writer keeps more than the packet had
        return "%d bytes captured of a packet of %d: a damaged record header" % (incl, orig)
    return None


class _Block:
    """The body of a pcapng block, taken field by field: what it does not
    hold is a CaptureError (libpcap's "block of type N ... is too short")."""

    def __init__(self, btype, body, e, where):
        self.btype = btype
        self.body = body
        self.at = 0
        self.e = e
        self.where = where

    def left(self):
        return len(self.body) - self.at

    def take(self, n):
        if self.left() < n:
            raise CaptureError(
                "%sblock of type %d in pcapng dump file is too short" % (self.where, self.btype)
            )
        out = self.body[self.at : self.at + n]
        self.at += n
        return out

    def unpack(self, fmt):
        return struct.unpack(self.e + fmt, self.take(struct.calcsize(self.e + fmt)))


def _idb_options(blk):
    """(ticks per second, offset in seconds) of an Interface Description
    Block's options (if_tsresol, if_tsoffset), checked as libpcap does."""
    res, offset = 1000000, 0
    seen = set()
    while blk.left():
        code, olen = blk.unpack("HH")
        value = blk.take((olen + 3) // 4 * 4)[:olen]
        if code == 0:  # opt_endofopt
            if olen != 0:
                raise CaptureError(
                    "%sInterface Description Block has opt_endofopt option with length %d != 0"
                    % (blk.where, olen)
                )
            break
        if code in (9, 14):
            name, size = ("if_tsresol", 1) if code == 9 else ("if_tsoffset", 8)
            if olen != size:
                raise CaptureError(
                    "%sInterface Description Block has %s option with length %d != %d"
                    % (blk.where, name, olen, size)
                )
            if code in seen:
                raise CaptureError(
                    "%sInterface Description Block has more than one %s option" % (blk.where, name)
                )
            seen.add(code)
            if code == 14:
                offset = struct.unpack(blk.e + "q", value)[0]
                continue
            r = value[0]
            if (r & 0x7F > 63) if r & 0x80 else (r > 19):
                raise CaptureError(
                    "%sInterface Description Block if_tsresol option resolution %s is too high"
                    % (blk.where, "2^-%d" % (r & 0x7F) if r & 0x80 else "10^-%d" % r)
                )
            res = 2 ** (r & 0x7F) if r & 0x80 else 10**r
    return res, offset


def _pcapng(f, head):
    """The records of a pcapng file whose first 8 bytes are head. Every
    block is checked as libpcap checks it (the reader of `tase decode`):
    its length (>= 12, a multiple of 4, the trailer's), the fixed fields of
    its type and what its lengths claim within it; a damaged block is a
    CaptureError saying which, never a partial record."""
    index = 0
    last_usec = 0  # the time of the record before (a Simple Packet Block's)
    e = None  # the byte order of the sections, from the first one's magic
    ifaces = []
    idb_seen = False
    while True:
        where = "after record %d: " % index
        h = head if head is not None else f.read(8)
        head = None
        if not h:
            if not idb_seen:
                # libpcap opens no such file (tase decode: exit 1)
                raise CaptureError("the capture file has no Interface Description Blocks")
            return
        if len(h) < 8:
            raise CaptureError("%struncated pcapng dump file: a block header cut short" % where)
        if h[:4] == _SHB:
            # libpcap takes the file's first section header apart from the
            # other blocks: version 1.0 or 1.2 only, its trailer not looked
            # at (it refused one with a bad trailer that tase decode reads,
            # and read 1.1 or 1.3 that it refuses); a later one like the rest
            first = e is None
            bom = f.read(4)
            if len(bom) < 4:
                raise CaptureError("%struncated pcapng dump file: section header cut short" % where)
            if e is None:
                if struct.unpack("<I", bom)[0] == _BOM:
                    e = "<"
                elif struct.unpack(">I", bom)[0] == _BOM:
                    e = ">"
                else:
                    raise CaptureError(
                        "not a pcapng file: unknown byte-order magic 0x%s" % bom.hex()
                    )
            elif struct.unpack(e + "I", bom)[0] != _BOM:
                if struct.unpack(e + "I", bom[::-1])[0] == _BOM:
                    why = "sections with different byte orders"
                else:
                    why = "a section with a bad byte order magic field"
                raise CaptureError("%sthe file has %s" % (where, why))
            blen = struct.unpack(e + "I", h[4:8])[0]
            if not 28 <= blen <= _MAX_BLOCK or blen % 4:
                raise CaptureError(
                    "%sSection Header Block in pcapng dump file has an invalid length %d"
                    % (where, blen)
                )
            rest = f.read(blen - 12)
            btype = 0x0A0D0D0A
        else:
            btype, blen = struct.unpack(e + "II", h)
            if blen < 12:
                raise CaptureError(
                    "%sblock in pcapng dump file has a length of %d < 12" % (where, blen)
                )
            if blen % 4:
                raise CaptureError(
                    "%sblock in pcapng dump file has a length of %d that is not a multiple of 4"
                    % (where, blen)
                )
            if blen > _MAX_BLOCK:
                raise CaptureError(
                    "%spcapng block size %d > maximum %d" % (where, blen, _MAX_BLOCK)
                )
            rest = f.read(blen - 8)
            bom = b""
        need = blen - 8 - len(bom)
        if len(rest) < need:
            raise CaptureError(
                "%struncated pcapng dump file: block of type %d cut short (%d of its %d bytes)"
                % (where, btype, 8 + len(bom) + len(rest), blen)
            )
        trailer = struct.unpack(e + "I", rest[-4:])[0]
        if trailer != blen and not (btype == 0x0A0D0D0A and first):
            raise CaptureError(
                "%sblock total length in header %d and trailer %d don't match"
                % (where, blen, trailer)
            )
        blk = _Block(btype, bom + rest[:-4], e, where)
        if btype == 0x0A0D0D0A:  # section header: its own interfaces
            blk.take(4)
            major, minor = blk.unpack("HH")
            if major != 1 or (first and minor not in (0, 2)):
                raise CaptureError(
                    "%sunsupported pcapng savefile version %d.%d" % (where, major, minor)
                )
            ifaces = []
        elif btype == 1:  # interface description
            linktype, _, snaplen = blk.unpack("HHI")
            if snaplen == 0 or snaplen > _MAX_SNAPLEN:
                snaplen = _MAX_SNAPLEN  # libpcap's adjustment
            res, offset = _idb_options(blk)
            ifaces.append((linktype, snaplen, res, offset))
            idb_seen = True
        elif btype in (6, 3):  # enhanced / simple packet
            if btype == 6:
                iface, hi, lo, incl, orig = blk.unpack("IIIII")
            else:
                iface, hi, lo = 0, 0, 0
                (orig,) = blk.unpack("I")
            if iface >= len(ifaces):
                raise CaptureError(
                    "%sa packet on interface %d, but no Interface Description Block for it"
                    % (where, iface)
                )
            linktype, snaplen, res, offset = ifaces[iface]
            if btype == 3:  # its data: the packet up to the snapshot length
                incl = min(orig, snaplen)
            elif incl > snaplen:
                raise CaptureError(
                    "%sinvalid packet capture length %d, bigger than snaplen of %d"
                    % (where, incl, snaplen)
                )
            data = blk.take(incl)
            index += 1
            ts = hi << 32 | lo
            usec = (ts // res + offset) * 1000000 + ts % res * 1000000 // res
            if ts == 0 and index > 1:
                # a Simple Packet Block has no time: the record before's, as
                # tase decode (1970 cut a frame split across the two as a pause)
                usec = last_usec
            last_usec = usec
            yield index, linktype, usec, data, _damage(incl, orig)


def _records(f, path):
    """The records of the open capture f; a CaptureError names `path`."""
    try:
        head = f.read(4)
        if head == _SHB:
            yield from _pcapng(f, head + f.read(4))
        else:
            yield from _pcap(f, head)
    except CaptureError as e:
        raise CaptureError("%s: %s" % (path, e)) from None


def records(path):
    """(index, linktype, time_us, bytes, damage) of every record of a pcap
    or pcapng file (damage: why tase decode skips the record, cut by the
    snapshot length or a damaged header, or None). A file that is not one, or a damaged record or block, is a
    CaptureError naming the file (the records before it are given)."""
    try:
        f = open(path, "rb")
    except IsADirectoryError:
        raise CaptureError("%s: is a directory, not a capture" % path) from None
    with f:
        yield from _records(f, path)


def _write_error(path, e):
    """The CaptureError of an OSError writing the capture `path`."""
    return CaptureError("cannot write capture %s: %s" % (path, e.strerror or e))


class CaptureWriter:
    """Write a serial capture as `tase record` does: nanosecond pcap, link
    type 147, one record per read or write (a direction byte, 0 from the
    gimbal, 1 to it, then the bytes). An existing file is appended to when
    it is a classic pcap of link type 147 (as `--record`: either byte
    order, microseconds or nanoseconds, its records in its format), else
    refused; a record a full
    disk cut short at its end is cut off first (as `--record` does: the
    next session would be unreadable behind it); a new one is created.
    Every record is flushed. A write that fails (a full disk) is a
    CaptureError, the file left ending with its last whole record."""

    _HEADER = struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, LINKTYPE_SERIAL)
    _CHUNK = 4096  # bytes of a read or write per record, after the direction byte

    # the signals that end a Python program, or interrupt it, by default
    _ENDING = tuple(
        getattr(signal, n)
        for n in ("SIGHUP", "SIGINT", "SIGTERM", "SIGQUIT", "SIGUSR1", "SIGUSR2", "SIGALRM",
                  "SIGPROF", "SIGVTALRM", "SIGXCPU", "SIGPOLL")
        if hasattr(signal, n)
    )

    def __init__(self, path):
        path = _path_arg("a capture", path)
        existed = os.path.lexists(path)
        # a file made here is not left empty, without its header (no
        # capture), by a signal that comes between: such signals wait
        # until the header is written (others hold the lock one write at a
        # time), as in tase --record
        held = None if existed else signal.pthread_sigmask(signal.SIG_BLOCK, self._ENDING)
        try:
            self._open(path, existed)
        finally:
            if held is not None:
                signal.pthread_sigmask(signal.SIG_SETMASK, held)

    def _open(self, path, existed):
        self.path = path
        self.records = 0
        self.f = None
        self._new_format()
        fd = None
        try:
            # appended to (O_APPEND), each record in one write: another
            # writer's records (tase --record, a second link) go between
            # ours, never over them (a seek to our own end overwrote them).
            # O_NONBLOCK: a FIFO would hold the open until a reader came.
            fd = os.open(
                path, os.O_RDWR | os.O_APPEND | os.O_CREAT | os.O_NONBLOCK | os.O_CLOEXEC, 0o666
            )
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise CaptureError(
                    "cannot write capture %s: not a regular file (a recording is appended "
                    "to a file)" % path
                )
            os.set_blocking(fd, True)
            self.f = open(fd, "ab", buffering=0)
            fd = None
            fd_ = self.f.fileno()
            # Scanned first without the lock (a long capture takes a while,
            # and every other recorder waits for the lock), then, under the
            # lock every writer of ours takes for a write (tase --record
            # too), only what was added since and the tail: another's
            # record in progress is not taken for one a crash cut short,
            # and two writers of a new file do not both write its header.
            pos, index = 24, 0
            size = os.fstat(fd_).st_size
            if size > 0:
                self._check_header()
                pos, index = self._scan(24, 0, size, under_lock=False)
            fcntl.flock(fd_, fcntl.LOCK_EX)
            try:
                size = os.fstat(fd_).st_size
                if size == 0:
                    self.good = 0
                    self._new_format()
                    self._append(self._HEADER)
                else:
                    if (pos, index) == (24, 0):
                        self._check_header()  # another program's header meanwhile
                    end, _ = self._scan(pos, index, size, under_lock=True)
                    self.f.truncate(end)
            finally:
                fcntl.flock(fd_, fcntl.LOCK_UN)
        except (OSError, CaptureError) as e:
            if fd is not None:
                os.close(fd)
            if self.f is not None:
                try:
                    if not existed and os.fstat(self.f.fileno()).st_size == 0:
                        os.unlink(path)  # a file this call made goes again
                except OSError:
                    pass
                self.f.close()
            if isinstance(e, CaptureError):
                raise
            raise _write_error(path, e) from e

    def _new_format(self):
        """The records of a file this writer gives its header: _HEADER's."""
        self._e, self._nano, self._limit = "<", True, 65535

    def _check_header(self):
        """Take the format of the existing file's header, as tase --record
        does (tools/tk_capture.c): a classic pcap of either byte order, in
        microseconds or nanoseconds, link type 147, a snapshot length that
        holds our largest record; else a CaptureError, nothing appended.
        (Only _HEADER's own bytes were taken: a capture --record appends to,
        a microsecond or big-endian one, was refused.)"""
        head = os.pread(self.f.fileno(), 24, 0)
        magic = head[:4]
        if len(head) < 24 or magic not in MAGICS[:4]:
            raise CaptureError(
                "%s: not a classic pcap file (a recording appends only to one; give a new "
                "file name): not appending" % self.path
            )
        e = "<" if magic in MAGICS[:2] else ">"
        snaplen, linktype = struct.unpack(e + "II", head[16:24])
        linktype &= 0x03FFFFFF
        if linktype != LINKTYPE_SERIAL:
            raise CaptureError(
                "%s: its link type is %d, not TASE serial (%d): not appending"
                % (self.path, linktype, LINKTYPE_SERIAL)
            )
        limit = _MAX_SNAPLEN if snaplen == 0 or snaplen > _MAX_SNAPLEN else snaplen
        if limit < 1 + self._CHUNK:
            raise CaptureError(
                "%s: its snapshot length (%d bytes) is below the %d bytes a record of ours "
                "may take: not appending" % (self.path, snaplen, 1 + self._CHUNK)
            )
        self._e, self._nano, self._limit = e, magic in (MAGICS[1], MAGICS[3]), limit

    def _scan(self, pos, index, size, under_lock):
        """(end, count) of the whole records from `pos` (a record boundary,
        `index` records before it) to `size`. A record header no writer
        writes (more data than the snapshot length or the packet's length)
        is damage, not the end of a file a crash cut short: a CaptureError
        under the lock, nothing cut (without it: looked at again under it,
        from the start, a write of another program may be under way)."""
        fd = self.f.fileno()
        while pos + 16 <= size:
            _, _, n, length = struct.unpack(self._e + "IIII", os.pread(fd, 16, pos))
            if n > self._limit or n > length:
                if not under_lock:
                    return 24, 0
                raise CaptureError(
                    "%s: its record %d is damaged (not the end of a file a crash cut short): "
                    "not appending, the file is left as it is" % (self.path, index + 1)
                )
            if pos + 16 + n > size:
                break
            pos += 16 + n
            index += 1
        return pos, index

    def _append(self, buf):
        """Write buf at the end (the caller holds the lock); a write cut
        short is cut off again."""
        fd = self.f.fileno()
        self.good = os.fstat(fd).st_size  # others may have appended
        try:
            view = memoryview(buf)
            while view:
                view = view[self.f.write(view) :]
        except OSError as e:
            try:  # what did go out of this record is cut off again
                self.f.truncate(self.good)
            except (OSError, ValueError):
                pass
            raise _write_error(self.path, e) from e

    def _write(self, buf):
        fd = self.f.fileno()
        fcntl.flock(fd, fcntl.LOCK_EX)  # as tase --record: see __init__
        try:
            self._append(buf)
        finally:
            fcntl.flock(fd, fcntl.LOCK_UN)

    def put(self, dir, data, t_ns=None):
        """One record: dir 0 (bytes from the gimbal) or 1 (to it)."""
        t = time.time_ns() if t_ns is None else t_ns
        frac = t % 1000000000 if self._nano else t % 1000000000 // 1000
        for i in range(0, len(data), self._CHUNK):
            chunk = bytes((dir,)) + bytes(data[i : i + self._CHUNK])
            self._write(
                struct.pack(self._e + "IIII", t // 1000000000, frac, len(chunk), len(chunk))
                + chunk
            )
            self.records += 1

    def close(self):
        try:
            self.f.close()
        except OSError as e:
            raise _write_error(self.path, e) from e


class _Stream:
    def __init__(self, dir, rate):
        self.dec = Decoder(rate, dir)
        self.dir = dir
        self.hist = collections.deque(maxlen=_HIST)
        self.last = None
        # the record clock's steps back so far, added to the times fed to
        # the receiver (as tase decode): a step back is no time, however
        # far (one of 2^31..2^32 ms wrapped into a long pause)
        self.back_ms = 0

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
        step = 0 if self.last is None else t // 1000 - self.last // 1000
        out = []
        if step < 0:
            self.back_ms -= step
        elif step >= 1 << 31:
            # 2^31 ms or more reads as no time on the receiver's clock
            # (modulo 2^32): it is told of 2^30 ms of quiet first
            quiet = (self.last // 1000 + self.back_ms + (1 << 30)) & 0xFFFFFFFF
            out += self._timed(self.dec.tick(quiet), self.last)
        ms = (t // 1000 + self.back_ms) & 0xFFFFFFFF
        out += self._timed(self.dec.tick(ms), self.last)
        self.last = t
        self.hist.append((self.dec.bytes + len(data), t))
        out += self._timed(self.dec.feed(data), t)
        out += self._timed(self.dec.tick(ms), t)
        return out

    def finish(self):
        return self._timed(self.dec.flush(), self.last)



def _path_arg(what, path):
    """A file path (str, bytes, os.PathLike); an int would be taken for an
    open file descriptor (record=3 wrote the capture onto the link's own
    line), so anything else is a TypeError."""
    if isinstance(path, bool) or not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError("%s is a file path, not %s" % (what, type(path).__name__))
    return os.fsdecode(path)


class Capture:
    """Iterate over (time, packet) of a capture; .bad lists the malformed
    records skipped ((index, reason)), .records the records read, .stats
    the receivers' counters. Each iteration reads the file from its start
    with new receivers (the counters are those of the last one)."""

    def __init__(self, path, baud=57600):
        if isinstance(baud, bool) or not isinstance(baud, int) or not 10 <= baud <= 4000000:
            # an OverflowError / TypeError from deep inside, or 0 taken
            raise FieldError("baud %r is not a serial line rate (10..4000000)" % (baud,))
        self.path = _path_arg("a capture", path)
        self.rate = baud // 10
        self.bad = []
        self.streams = {}
        self.records = 0

    def _stream(self, dir, rate):
        s = self.streams.get(dir)
        if s is None:
            s = self.streams[dir] = _Stream(dir, rate)
        return s

    @property
    def stats(self):
        """The receivers' counters, both directions together (the names of
        a link's stats): bytes_in, checksum_errors, bad_size,
        bytes_discarded; records read and bad_records skipped."""
        st = {
            "records": self.records,
            "bad_records": len(self.bad),
            "bytes_in": 0,
            "checksum_errors": 0,
            "bad_size": 0,
            "bytes_discarded": 0,
        }
        for s in self.streams.values():
            d = s.dec.stats
            st["bytes_in"] += d["bytes"]
            st["checksum_errors"] += d["checksum_errors"]
            st["bad_size"] += d["bad_size"]
            st["bytes_discarded"] += d["discarded"]
        return st

    def __iter__(self):
        return self._packets(records(self.path))

    def _packets(self, recs):
        """(time, packet) of the records `recs`, from new receivers."""
        self.bad = []
        self.streams = {}
        self.records = 0
        frame = ffi.new("tase_can_frame_t *")
        try:
            yield from self._records(recs, frame)
        except CaptureError:
            # a file cut inside a record (a copy of one being written):
            # what came before it first, the frames its receivers hold
            # included, then the error (as tase decode)
            for s in self.streams.values():
                for p in s.finish():
                    yield p.time, p
            raise
        for s in self.streams.values():
            for p in s.finish():
                yield p.time, p

    def _records(self, recs, frame):
        for index, linktype, t, data, damage in recs:
            self.records += 1
            if damage:
                self.bad.append((index, damage))
                continue
            if linktype == LINKTYPE_SERIAL:
                if len(data) < 2:
                    # tase decode's words
                    self.bad.append((index, "no bytes after the direction byte" if data
                                     else "empty (no direction byte, no bytes)"))
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
                cid, dlc, flags = struct.unpack(">IBB", data[:6])
                # FD: a 72-byte record or the FD flag (tase decode's test)
                fd = len(data) == 72 or flags & _CANFD_FDF
                if dlc > (64 if fd else 8) or dlc > len(data) - 8:
                    self.bad.append(
                        (index, "payload length %d does not fit the record (%d bytes)"
                         % (dlc, len(data)))
                    )
                    continue
                if fd or cid & (_CAN_RTR | _CAN_ERR) or not cid & _CAN_EFF:
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


def read_capture(path, baud=57600):
    """Yield (time, packet) for every packet of a `tase record` capture, as
    `tase decode FILE` prints them (same packets, order, offsets, times);
    `baud`: the serial line's rate, for the receivers' time bound (as
    decode's --baud). time is Unix seconds (packet.time_us exact). A file
    that is not a pcap or pcapng capture, or a damaged block in it (its
    structure), is a CaptureError naming the file and the block, raised
    when the iteration reaches it (`tase decode` fails on those too). A
    record whose contents are bad (a direction byte other than 0 or 1, no
    bytes, cut by the snapshot length, a damaged record header, a CAN
    payload longer than its record) is skipped, as `tase decode` skips
    it (warning, exit 4): iterate over `Capture(path, baud)` instead to
    find them in its `.bad` afterwards."""
    return iter(Capture(path, baud))


class CaptureLink:
    """capture:FILE: a read-only link over a capture. As any link it is a
    stream: packets() and recv() go on where the last call stopped, each
    packet given once, in the order and with the offsets and times of
    read_capture(); at the end of the file packets() ends and recv()
    raises TimeoutError (nothing more will come). The file is opened by
    tase.connect(): one that cannot be opened is a LinkError, one that is
    not a capture a CaptureError, both at once."""

    def __init__(self, path, baud=57600):
        self.url = "capture:" + path
        self.path = path
        try:
            self._f = open(path, "rb")
        except OSError as e:
            raise LinkError(
                "cannot open capture %s: %s" % (path, e.strerror or e),
                lib.TASE_ENODEV if e.errno == errno.ENOENT else lib.TASE_EIO,
            ) from e
        try:
            head = self._f.read(4)
            self._f.seek(0)
        except OSError as e:
            self._f.close()
            raise LinkError(
                "cannot read capture %s: %s" % (path, e.strerror or e), lib.TASE_EIO
            ) from e
        if head not in MAGICS:
            self._f.close()
            raise CaptureError("%s: not a capture tase can read (pcap or pcapng)" % path)
        self._cap = Capture(path, baud)
        self._it = self._cap._packets(_records(self._f, path))
        self._given = 0
        self._end = None  # None: more to come; True: the end; or the CaptureError that ended it
        self._closed = False

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        if not self._closed:
            self._closed = True
            self._it.close()
            self._f.close()

    def __del__(self):
        # as a serial link (its file was left to the collector, with a
        # ResourceWarning "unclosed file")
        _close_dropped(self)

    def _live(self):
        if self._closed:
            raise Error("%s: the link is closed" % self.url)

    def _next(self):
        """The next packet, or None at the end of the capture (a damaged
        record ends it: its CaptureError, then on every later call)."""
        if self._end is not None:
            if isinstance(self._end, BaseException):
                raise self._end
            return None
        try:
            _, p = next(self._it)
        except StopIteration:
            self._end = True
            return None
        except CaptureError as e:
            self._end = e
            raise
        self._given += 1
        return p

    def packets(self, timeout=None, count=None):
        """Iterate over the packets not given yet, until the end of the
        capture or `count` packets were given (`timeout` is not waited
        for: a capture holds what it holds; both are checked as a serial
        link checks them, so that a script does the same on either)."""
        self._live()
        _packets_limits(timeout, count)
        given = 0
        while count is None or given < count:
            self._live()  # closed meanwhile
            p = self._next()
            if p is None:
                return
            given += 1
            yield p

    def recv(self, timeout=None):
        """The next packet, or TimeoutError at the end of the capture."""
        self._live()
        _packets_limits(timeout, None)
        p = self._next()
        if p is None:
            raise TimeoutError_(
                "%s: end of the capture: no more packets" % self.url, lib.TASE_ETIMEOUT
            )
        return p

    @property
    def stats(self):
        """What the capture counted so far: frames_rx (packets given),
        records read, bad_records (skipped: cut, no direction byte, ...)
        and the receivers' bytes_in, checksum_errors, bad_size and
        bytes_discarded (both directions together)."""
        st = {"frames_rx": self._given}
        st.update(self._cap.stats)
        return st

    def _read_only(self, *args, **kw):
        raise Error("%s: a capture is read only: nothing can be sent" % self.url)

    send = query = point = rate = spoi = retract = deploy = camera = _read_only
