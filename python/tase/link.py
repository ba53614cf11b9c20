"""Links to a gimbal: tase.connect(url) -> Link, the host side.

URLs, in pymavlink's style:
    serial:/dev/ttyUSB0[:BAUD]   a serial device or pty (pyserial), 57600 baud by default
    socketcan:can0               a SocketCAN interface (python-can)
    virtual:NAME                 python-can's in-process virtual bus NAME
    capture:FILE                 a capture of `tase record` (read only)

A link runs the library's host role (tase/host.h) over the transport: the
C code frames what is sent, scans what is received and matches answers
and echoes to requests, with retries; Python only moves the bytes.
"""

import collections
import errno
import fcntl
import math
import os
import re
import sys
import select
import socket
import struct
import termios
import threading
import time
import warnings
import weakref

from ._core import (
    Error,
    FieldError,
    LinkError,
    Packet,
    TimeoutError_,
    _check,
    _from_data,
    _scaled,
    _Sink,
    _with_meta,
    error,
    ffi,
    lib,
    packet_type,
)

__all__ = ["connect", "Link", "parse_url"]

DEFAULT_BAUD = 57600
# the device may hold ':' (/dev/serial/by-path/pci-0000:00:14.0-usb-0:2:1.0-port0):
# a baud is the digits after the last one
_SERIAL_URL = re.compile(r"^serial:(?P<dev>.+?)(?::(?P<baud>[0-9]+))?$")
_BAUDS = (9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)


def parse_url(url):
    """(scheme, target, baud) of a link URL; FieldError when it is not one."""
    if not isinstance(url, str):
        raise FieldError("a link URL is a string, not %s" % type(url).__name__)
    m = _SERIAL_URL.match(url)
    if m:
        baud = int(m.group("baud")) if m.group("baud") else DEFAULT_BAUD
        if baud not in _BAUDS:
            raise FieldError(
                "%s: baud %d is not one of %s" % (url, baud, ", ".join(map(str, _BAUDS)))
            )
        return "serial", m.group("dev"), baud
    for scheme in ("socketcan", "virtual", "capture"):
        if url.startswith(scheme + ":") and len(url) > len(scheme) + 1:
            return scheme, url[len(scheme) + 1 :], None
    raise FieldError(
        "not a link URL: %r (serial:/dev/ttyUSB0[:BAUD], socketcan:IFACE, virtual:NAME, "
        "capture:FILE)" % url
    )


def connect(url, *, timeout=0.5, retries=2, record=None):
    """Open the link `url` (see the module's doc) as a host. `timeout` (s,
    per attempt) and `retries` (more attempts) are the defaults of
    query() and the verbs that wait for an answer. `record`: a capture
    file the session is appended to (serial links; as `tase --record`:
    what is written as sent to the gimbal, what is read as sent by it).
    Use as a context manager: the link is closed on exit."""
    scheme, target, baud = parse_url(url)
    _request_opts(timeout, retries)  # refused here, not at the first query
    if record is not None and scheme != "serial":
        raise FieldError(
            "record: only a serial link's session can be recorded here (on CAN run "
            "`tase record --can IFACE` beside it)"
        )
    if scheme == "capture":
        from .capture import CaptureLink

        return CaptureLink(target)
    if scheme == "serial":
        transport = _SerialTransport(target, baud)
    else:
        transport = _CanTransport(scheme, target)
    if record is not None:
        from .capture import CaptureWriter

        try:
            transport = _Recorder(transport, CaptureWriter(record))
        except BaseException:
            transport.close()
            raise
    return Link(transport, url, timeout, retries)


class _Recorder:
    """A transport that records what passes through it. A capture that
    cannot be written (a full disk) stops the recording, not the link: the
    bytes went out or came in all the same, and an error there would tell
    the caller a command was not sent when it was (as `tase --record`:
    a warning, the command goes on). Link.record_error says why."""

    def __init__(self, inner, writer):
        self.inner = inner
        self.w = writer
        self.failed = None
        self.warning = None
        self.name = inner.name
        self.bytes_per_s = inner.bytes_per_s

    def _put(self, dir, data):
        if self.w is None:
            return
        try:
            self.w.put(dir, data)
        except Error as e:
            self.failed = e
            try:
                self._stop()
            except Error:
                pass
            # warned when the call returns (Link._call_locked), not here in
            # the port callback: under -W error the warning raised here was
            # taken for the port's failure (a sent command reported as not)
            self.warning = "%s; recording stopped, the link goes on" % e

    def write(self, data):
        n = self.inner.write(data)
        if n > 0:
            self._put(1, data[:n])
        return n

    def read(self, cap, timeout_s):
        data = self.inner.read(cap, timeout_s)
        if data:
            self._put(0, data)
        return data

    def _stop(self):
        """Close the capture (once)."""
        w, self.w = self.w, None
        if w is not None:
            w.close()

    def close(self):
        try:
            self.inner.close()
        finally:
            self._stop()


# ---- transports: bytes in and out -------------------------------------------


def _check_simlink(dev):
    """LinkError when `dev` is (or leads through) the link of a tase-sim
    that no longer runs: its pty may be another program's now (the tools'
    own check, tools/tk_simlink.c, as `tase` refuses it)."""
    why = ffi.new("char[]", 4096)
    if lib.tk_simlink_check(os.fsencode(dev), why, len(why)) != 0:
        raise LinkError(ffi.string(why).decode(errors="replace"), lib.TASE_ENODEV)


# TIOCGEXCL (Linux: _IOR('T', 0x40, int)); Python's termios lacks it
_TIOCGEXCL = getattr(termios, "TIOCGEXCL", 0x80045440 if sys.platform.startswith("linux") else None)


def _excl_held(fd):
    """Whether the terminal fd is held exclusively (TIOCEXCL) by anyone."""
    if _TIOCGEXCL is None:
        return False
    try:
        got = fcntl.ioctl(fd, _TIOCGEXCL, b"\0\0\0\0")
    except OSError:
        return False  # not a terminal that says
    return struct.unpack("i", got)[0] != 0


def _open_error(dev, e):
    """The LinkError of pyserial's failure to open `dev`, with the code the
    C port (port/posix_uart) gives the same errno: a device held by another
    program EBUSY, one that is missing or not a terminal ENODEV, one we may
    not open EACCES, anything else EIO. pyserial keeps the errno of an
    open or lock (SerialException(errno, text)) but not of its termios
    calls (/dev/null, a file): that one is the exception it was raised
    from."""
    n = getattr(e, "errno", None)
    if n is None and isinstance(getattr(e, "__context__", None), OSError):
        n = e.__context__.errno
    if n is None and e.__context__ is not None and getattr(e.__context__, "args", None):
        first = e.__context__.args[0]  # termios.error(errno, text)
        n = first if isinstance(first, int) else None
    if n in (errno.EBUSY, errno.EAGAIN, errno.EWOULDBLOCK):
        return LinkError("cannot open %s: in use by another program (%s)" % (dev, e), lib.TASE_EBUSY)
    if n in (errno.ENOENT, errno.ENXIO, errno.ENODEV, errno.ENOTDIR, errno.EISDIR, errno.ENOTTY):
        return LinkError("cannot open %s: not a serial device (%s)" % (dev, e), lib.TASE_ENODEV)
    if n in (errno.EACCES, errno.EPERM, errno.EROFS):
        return LinkError("cannot open %s: %s" % (dev, e), lib.TASE_EACCES)
    return LinkError("cannot open %s: %s" % (dev, e), lib.TASE_EIO)


class _SerialTransport:
    def __init__(self, dev, baud):
        try:
            import serial
        except ImportError as e:  # pragma: no cover - packaging
            raise Error("serial links need pyserial (Debian: python3-serial)") from e
        _check_simlink(dev)
        if not os.path.exists(dev):
            raise LinkError("%s: No such file or directory" % dev, lib.TASE_ENODEV)
        try:
            self.ser = serial.Serial(dev, baud, timeout=0, exclusive=True)
        except (serial.SerialException, OSError, ValueError) as e:
            raise _open_error(dev, e) from e
        try:
            _check_simlink(dev)  # again: the simulator may have died meanwhile
            if _excl_held(self.ser.fileno()):
                # pyserial's exclusive=True is a flock(); a program that
                # holds the device with TIOCEXCL alone (root may open it
                # anyway) is refused as the C port refuses it
                raise LinkError(
                    "cannot open %s: in use by another program (it holds the device with "
                    "TIOCEXCL)" % dev,
                    lib.TASE_EBUSY,
                )
        except BaseException:
            self.ser.close()
            raise
        self.fd = self.ser.fileno()
        self.name = dev
        self.bytes_per_s = baud // 10

    # The port contract (tase/port.h): a write blocks at most its bound W
    # (1 s, the POSIX serial port's default), then returns what went out,
    # or TASE_EAGAIN when nothing did. It waited for room for ever: a
    # gimbal that stopped reading hung send() and query().
    WRITE_BOUND_S = 1.0

    def write(self, data):
        n = 0
        deadline = time.monotonic() + self.WRITE_BOUND_S
        while n < len(data):
            try:
                k = os.write(self.fd, data[n:])
            except BlockingIOError:
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                select.select([], [self.fd], [], left)
                continue
            except OSError as e:
                raise LinkError(
                    "cannot write to %s: the device went away or hung up (%s)" % (self.name, e),
                    lib.TASE_EIO,
                ) from e
            n += k
        return n if n > 0 or not data else lib.TASE_EAGAIN

    def read(self, cap, timeout_s):
        try:
            p = select.poll()
            p.register(self.fd, select.POLLIN)
            ev = p.poll(max(0, math.ceil(timeout_s * 1000)))
            if not ev:
                return b""
            data = os.read(self.fd, cap)
        except BlockingIOError:
            return b""
        except OSError as e:
            raise LinkError(
                "cannot read %s: the device went away or hung up (%s)" % (self.name, e),
                lib.TASE_EIO,
            ) from e
        if not data:
            # readable and no byte: a hang-up only when poll() said so; else
            # another reader of the device took them first
            if ev[0][1] & (select.POLLHUP | select.POLLERR | select.POLLNVAL):
                raise LinkError(
                    "cannot read %s: the device went away or hung up" % self.name, lib.TASE_EIO
                )
            return b""
        return data

    def close(self):
        self.ser.close()


def _interface_exists(name):
    try:
        socket.if_nametoindex(name)
        return True
    except OSError:
        return False


def _can_error(what, name, e):
    """The LinkError of a failed CAN read or send, with the C port's code
    and the tools' words for an interface that went down or was removed
    (python-can may wrap the OSError in a CanError: its cause is looked at)."""
    os_e = e if isinstance(e, OSError) else e.__cause__ or e.__context__
    e_no = getattr(os_e, "errno", None) or getattr(e, "error_code", None)
    if e_no == errno.ENETDOWN:
        return LinkError("%s %s: the interface went down" % (what, name), lib.TASE_EDOWN)
    if e_no in (errno.ENODEV, errno.ENXIO):
        return LinkError("%s %s: the interface was removed" % (what, name), lib.TASE_ENODEV)
    return LinkError("%s %s: %s" % (what, name, e), lib.TASE_EIO)


class _CanTransport:
    """The datalink over CAN as the host (sends 0x11000000, listens to
    0x10000000): the library splits and accepts, python-can moves frames."""

    def __init__(self, scheme, channel):
        try:
            import can
        except ImportError as e:  # pragma: no cover - packaging
            raise Error("CAN links need python-can (Debian: python3-can)") from e
        self.can = can
        self.name = channel
        try:
            self.bus = can.Bus(interface=scheme, channel=channel)
        except (OSError, can.CanError, ValueError) as e:
            e_no = getattr(e, "errno", None)
            code = lib.TASE_ENODEV
            why = {
                errno.EAFNOSUPPORT: "this kernel has no SocketCAN support (load the can and "
                "can-raw modules, or see docs/CAN.md for the VM)",
                errno.ENODEV: "no such device",
                errno.ENETDOWN: "interface is down (ip link set %s up)" % channel,
            }.get(e_no, str(e))
            if e_no == errno.ENODEV and _interface_exists(channel):
                # bind() says ENODEV for lo or eth0 too, as the C port knows
                why, code = "not a CAN interface", lib.TASE_EARG
            raise LinkError("cannot open %s:%s: %s" % (scheme, channel, why), code) from e
        self.bytes_per_s = lib.TASE_SOCKETCAN_BYTES_PER_S
        self.pending = b""
        self.frames = ffi.new("tase_can_frame_t[]", 40)
        self.one = ffi.new("tase_can_frame_t *")

    def write(self, data):
        n = lib.tase_can_split(lib.TASE_CAN_ROLE_HOST, data, len(data), self.frames, 40)
        if n < 0:
            raise error(n, "CAN split")
        for i in range(n):
            f = self.frames[i]
            msg = self.can.Message(
                arbitration_id=f.id, is_extended_id=True, data=bytes(f.data[0 : f.dlc])
            )
            try:
                self.bus.send(msg, timeout=1.0)
            except (OSError, self.can.CanError) as e:
                raise _can_error("cannot send on", self.name, e) from e
        return len(data)

    def read(self, cap, timeout_s):
        if self.pending:
            out, self.pending = self.pending[:cap], self.pending[cap:]
            return out
        deadline = time.monotonic() + timeout_s
        while True:
            left = max(0.0, deadline - time.monotonic())
            try:
                msg = self.bus.recv(left)
            except (OSError, self.can.CanError) as e:
                raise _can_error("cannot read", self.name, e) from e
            if msg is None:
                return b""
            if msg.is_error_frame or msg.is_remote_frame or getattr(msg, "is_fd", False):
                continue
            f = self.one
            f.id = msg.arbitration_id
            f.extended = msg.is_extended_id
            f.dlc = min(len(msg.data), 8)
            ffi.memmove(f.data, bytes(msg.data[:8]), f.dlc)
            n = lib.tase_can_accept(lib.TASE_CAN_ROLE_HOST, f)
            if n > 0:
                data = bytes(msg.data[:n])
                out, self.pending = data[:cap], data[cap:]
                return out
            if time.monotonic() >= deadline:
                return b""

    def close(self):
        self.bus.shutdown()


# ---- the port callbacks of the C host role -----------------------------------


def _closed_meanwhile(link):
    """close() from another thread during a call: the call ends at its
    next read or write (the device stays open until it has)."""
    if link._closed:
        link._exc = Error("%s: the link was closed" % link.url)
        return True
    return False


# Every line of a callback is inside its try: cffi prints and drops an
# exception that leaves one (a Ctrl-C there was lost, with the bytes read).


@ffi.def_extern()
def py_port_write(ctx, data, n):
    link = None
    try:
        link = ffi.from_handle(ctx)()
        if link is None or _closed_meanwhile(link):
            return lib.TASE_EIO
        return link._t.write(ffi.buffer(data, n)[:])
    except BaseException as e:  # noqa: B902 - handed back to the caller
        if link is not None:
            link._exc = e
        return lib.TASE_EIO


# A read waits in slices of this many seconds, so that close() from
# another thread ends a call waiting for an answer that does not come (it
# waited out the whole timeout).
_READ_SLICE_S = 0.2


@ffi.def_extern()
def py_port_read(ctx, buf, cap, timeout_ms):
    link = None
    try:
        link = ffi.from_handle(ctx)()
        if link is None or _closed_meanwhile(link):
            return lib.TASE_EIO
        deadline = time.monotonic() + timeout_ms / 1000.0
        while True:
            left = deadline - time.monotonic()
            data = link._t.read(cap, max(0.0, min(left, _READ_SLICE_S)))
            if data or left <= _READ_SLICE_S:
                break
            if _closed_meanwhile(link):
                return lib.TASE_EIO
        if data:
            ffi.memmove(buf, data, len(data))
            # the frames these bytes complete arrived now (tase monitor --time)
            link._sink.s.now = _now_us()
        return len(data)
    except BaseException as e:  # noqa: B902
        if link is not None:
            link._exc = e
        return lib.TASE_EIO


@ffi.def_extern()
def py_port_now(ctx):
    try:
        return int(time.monotonic() * 1000) & 0xFFFFFFFF
    except BaseException as e:  # noqa: B902
        try:
            link = ffi.from_handle(ctx)()
            if link is not None:
                link._exc = e
        except BaseException:  # noqa: B902
            pass
        return 0


# The modes of the spec's table 5, for the message that lists them; whether
# a flags value is one is the C library's answer (_gimbal_mode_ok()).
_GIMBAL_CMD_FLAGS = {
    lib.TASE_GIMBAL_FLAGS_RATE: "rate",
    lib.TASE_GIMBAL_FLAGS_RATE_STAB: "rate, stabilised",
    lib.TASE_GIMBAL_FLAGS_POSITION: "position",
    lib.TASE_GIMBAL_FLAGS_POSITION_STAB: "position, stabilised",
    lib.TASE_GIMBAL_FLAGS_IMPULSE: "impulse",
    lib.TASE_GIMBAL_FLAGS_IMPULSE_STAB: "impulse, stabilised",
    lib.TASE_GIMBAL_FLAGS_SPOI_ERROR: "SPOI error",
    lib.TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE: "SPOI error rate",
}
for _f in range(lib.TASE_GIMBAL_FLAGS_LEGACY_RATE, lib.TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB + 1):
    _GIMBAL_CMD_FLAGS[_f] = "legacy"


def _gimbal_mode_ok(packet):
    """Whether a GIMBAL_CMD's flags are a mode of the spec's table 5: the C
    library's tase_command_check_data() (what the host role checks), asked
    of the packet with pan and tilt 0 (in range for every mode), so that
    only its flags can fail (a position out of range is the host role's
    own refusal, with its own message)."""
    probe = packet.replace(raw={"pan": 0, "tilt": 0}).payload
    return lib.tase_command_check_data(packet.id, probe, len(probe)) == lib.TASE_OK


# How to send anyway what _checked() refuses for reserved flag bits.
_SEND_RESERVED = "send(..., reserved=True) sends it anyway, as tase send --raw"
_QUERY_RESERVED = "send(..., reserved=True) sends it; the answer is then read with recv()"


def _request_opts(timeout, retries):
    """A request's timeout (s) and retries: FieldError unless a number in
    (0, 2^31 ms) and an int 0..255."""
    if (
        isinstance(timeout, bool)
        or not isinstance(timeout, (int, float))
        or not 0 < timeout < 2**31 / 1000
    ):
        # the value given is said: "timeout must be ..." alone did not
        # tell which call's value, or whether timeout or retries, was wrong
        raise FieldError("timeout must be > 0 s and under 2^31 ms, not %r" % (timeout,))
    if isinstance(retries, bool) or not isinstance(retries, int) or not 0 <= retries <= 255:
        raise FieldError("retries must be an int 0..255, not %r" % (retries,))
    return timeout, retries


def _warn_at_caller(msg):
    """A RuntimeWarning at the first frame outside this package."""
    here = os.path.dirname(os.path.abspath(__file__))
    f, level = sys._getframe(1), 1
    while f is not None and os.path.dirname(os.path.abspath(f.f_code.co_filename)) == here:
        f, level = f.f_back, level + 1
    warnings.warn(msg, RuntimeWarning, level + 1)


def _flag(what, v):
    """A True/False option (a string such as "no" is true in Python)."""
    if not isinstance(v, bool):
        raise FieldError("%s must be True or False, not %r: nothing sent" % (what, v))
    return v


def _stab(what, v):
    """stab= of point()/rate(): True or False only (a string such as
    "off" is true in Python, and stabilised is not what it asked for)."""
    if not isinstance(v, bool):
        raise FieldError("%s: stab must be True or False, not %r: nothing sent" % (what, v))
    return v


def _seconds(what, v):
    """A timeout in seconds: a finite number >= 0 (under 2^31 ms, what the
    C side's clock arithmetic can see expire), else FieldError."""
    if (
        isinstance(v, bool)
        or not isinstance(v, (int, float))
        or not math.isfinite(v)
        or not 0 <= v < 2**31 / 1000
    ):
        raise FieldError("%s: %r is not a number of seconds >= 0 (and under 2^31 ms)" % (what, v))
    return v


def _packets_limits(timeout, count):
    """packets()'s timeout (None or seconds, _seconds()) and count (None or
    an int >= 0), else FieldError; of every kind of link."""
    if timeout is not None:
        _seconds("packets: timeout", timeout)
    if count is not None and (isinstance(count, bool) or not isinstance(count, int) or count < 0):
        raise FieldError("packets: count %r is not a number of packets (an int >= 0)" % (count,))


def _close_dropped(link):
    """__del__ of a link (serial, CAN, capture): one dropped without
    close() is closed when its last reference goes."""
    if not getattr(link, "_closed", True):
        try:
            link.close()
        except Exception:  # noqa: BLE001 - nothing to report to at collection
            pass


def _setting_differs(t, sent, echo):
    """Whether a setup packet's echo shows a setting other than the one
    sent: fields sent as "do not change" and `temporary` (what to do with
    the packet, no setting) are not compared; an echo of another length
    (AXIS_SETTING's other layout) is the gimbal's own answer."""
    if echo.size != sent.size:
        return False
    for f in t.fields:
        v = sent.raw.get(f.name)
        if f.name == "temporary" or v is None or v == f.keep:
            continue
        if echo.raw.get(f.name) != v:
            return True
    return False

class Link:
    """A link to a gimbal, as the host. Made by tase.connect()."""

    def __init__(self, transport, url, timeout=0.5, retries=2):
        self._t = transport
        self.url = url
        self.timeout = timeout
        self.retries = retries
        self._exc = None
        # the C side reaches the link through a weak reference: a handle of
        # the link itself would be a cycle, and a link dropped unclosed kept
        # its device (and its lock) until the cyclic collector ran
        self._handle = ffi.new_handle(weakref.ref(self))
        self._host = ffi.new("tase_host_t *")
        self._sink = _Sink(1 << 18, cap=1 << 15, timed=True)
        self._ctx = ffi.new("py_ctx_t *")
        self._ctx.s = self._sink.s
        self._base = 0
        self._queue = collections.deque()
        self._closed = False
        # Threads: a Link's calls run one at a time (_call_lock), and a
        # close() from another thread during a call leaves the device open
        # until that call has ended (it ends at its next read or write), so
        # its descriptor cannot be reused meanwhile by another link.
        self._call_lock = threading.RLock()
        self._state_lock = threading.Lock()
        self._calls = 0
        self._t_open = True
        _check(
            lib.py_host_init(self._host, self._handle, transport.bytes_per_s, self._ctx), url
        )
        self._reply = ffi.new("uint8_t[]", lib.TASE_DATA_MAX)

    # -- plumbing

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        """Close the link (also from another thread: a call in progress
        there then ends with an Error, and the device is closed when it
        has)."""
        with self._state_lock:
            if self._closed:
                return
            self._closed = True
            shut = self._shut_now()
        if shut:
            self._t.close()

    def _shut_now(self):
        """With _state_lock held: whether the device is to be closed now
        (the link is closed and no call is left in it); marks it closed."""
        shut = self._closed and self._calls == 0 and self._t_open
        if shut:
            self._t_open = False
        return shut

    def __del__(self):
        _close_dropped(self)

    def _live(self):
        if self._closed:
            raise Error("%s: the link is closed" % self.url)

    def _call(self, fn, *args):
        """Run a host call that may receive (one at a time, whatever the
        thread); collect the frames it passed on (telemetry, other answers)
        into the queue; raise what the transport raised."""
        with self._call_lock:
            with self._state_lock:
                self._live()
                self._calls += 1
            try:
                return self._call_locked(fn, *args)
            finally:
                with self._state_lock:
                    self._calls -= 1
                    shut = self._shut_now()
                if shut:
                    self._t.close()

    def _call_locked(self, fn, *args):
        self._exc = None
        lib.py_host_begin(self._host, self._sink.s, self._base)
        before = self._host.rx.stats.bytes_in
        try:
            r = fn(*args)
        finally:
            self._base += (self._host.rx.stats.bytes_in - before) & 0xFFFFFFFF
            got = self._sink.take(None, "out")
            if got:
                self._queue.extend(got)
        w = getattr(self._t, "warning", None)
        if w is not None:
            self._t.warning = None
            _warn_at_caller(w)
        if self._exc is not None:
            e, self._exc = self._exc, None
            if isinstance(e, Error) or not isinstance(e, Exception):
                raise e  # ours, or KeyboardInterrupt / SystemExit as they are
            raise LinkError("%s: %s" % (self.url, e), lib.TASE_EIO) from e
        return r

    # -- sending

    def _checked(self, packet, reserved=False, how=_SEND_RESERVED):
        if not isinstance(packet, Packet):
            raise TypeError("send() takes a tase.Packet, not %s" % type(packet).__name__)
        t = packet.packet_type
        if t is None:
            raise FieldError(
                "group 0x%02X type 0x%02X is not a packet of the spec: not sent"
                % (packet.group, packet.type)
            )
        if not t.to_gimbal:
            raise FieldError("%s is sent by the gimbal, not to it: not sent" % t.name)
        if packet.error is not None:
            raise FieldError("%s: %s: not sent" % (t.name, packet.error))
        if t.name == "SYSTEM_VERSION" and packet.size > 0:
            raise FieldError(
                "SYSTEM_VERSION is query-only: use query(\"SYSTEM_VERSION\"); not sent"
            )
        bad = t.reserved_flags
        if bad and not reserved and packet.size > 0:
            flags = packet.raw.get("flags")
            if flags is not None and flags & bad:
                bits = [b for b in range(8) if bad & (0x80 >> b)]
                raise FieldError(
                    "%s flags=0x%02X sets reserved bits %d-%d (0x%02X); not sent (%s)"
                    % (t.name, flags, bits[0], bits[-1], bad, how)
                )
        if t.name == "GIMBAL_CMD" and packet.size > 0:
            flags = packet.raw["flags"]
            if not _gimbal_mode_ok(packet):
                raise FieldError(
                    "GIMBAL_CMD flags 0x%02X is not a mode of the spec's table 5 (%s): not sent"
                    % (flags, ", ".join("0x%02X" % f for f in sorted(_GIMBAL_CMD_FLAGS)))
                )
        return t

    def _request_opts(self, timeout, retries):
        """A request's timeout (s) and retries, the link's defaults for None."""
        return _request_opts(
            self.timeout if timeout is None else timeout, self.retries if retries is None else retries
        )

    def send(self, packet, reserved=False):
        """Send one packet to the gimbal now (no answer awaited). Packets
        the gimbal sends, unknown ones, wrong lengths, a full-length
        SYSTEM_VERSION (query-only), GIMBAL_CMD flags outside the spec's
        table 5, a position or SPOI outside the spec's ranges (the host
        role's tase_command_check()) and flags with bits the spec reserves (CAMERA_CMD,
        HOST_SENSOR, HOST_ATTITUDE, SPOI_CMD; reserved=True sends those
        anyway) are refused (FieldError), nothing sent, as `tase send`."""
        self._live()
        self._checked(packet, _flag("send: reserved", reserved))
        data = packet.payload
        r = self._call(lib.tase_host_send, self._host, packet.group, packet.type, data, len(data))
        if r < 0:
            raise error(r, "%s: send %s" % (self.url, packet.name))
        return packet

    def query(self, what, timeout=None, retries=None):
        """Ask the gimbal and return its answer (a Packet, dir "out").

        `what` is a packet name (its zero-length query: setup packets,
        SPOI_CMD, SYSTEM_VERSION; any other name is a FieldError, nothing
        sent) or a Packet: such a query, or a setting to confirm (a setup
        packet, SPOI_CMD with the echo flag; RETRACT_DEPLOY_CMD is answered
        when the move ends: retract()/deploy() with wait). The answer is
        the gimbal's frame of the same group and type (the library's host
        role matches it and re-sends after each `timeout` s, up to
        `retries` more times). TimeoutError when none comes."""
        self._live()
        if isinstance(what, str):
            t = packet_type(what)
            if not t.has_query:
                raise FieldError(
                    "%s has no zero-length query form (queryable: the setup packets, "
                    "SPOI_CMD, SYSTEM_VERSION): nothing sent" % t.name
                )
            what = Packet.query(t.name)
        if isinstance(what, Packet) and what.is_query and what.packet_type.has_query:
            req = what
        elif isinstance(what, Packet):
            t = self._checked(what, how=_QUERY_RESERVED)
            echoed = t.group == 0x48 or (
                t.name == "SPOI_CMD" and what.size > 0 and what.raw["flags"] & lib.TASE_SPOI_ECHO
            )
            if not echoed:
                # a retry would send it again: only packets the gimbal echoes
                raise FieldError(
                    "%s is not echoed by the gimbal (setup packets are, SPOI_CMD with its "
                    "echo flag): use send(), nothing sent" % t.name
                )
            req = what
        else:
            raise TypeError("query() takes a packet name or a tase.Packet, not %s" % type(what).__name__)
        t = req.packet_type
        timeout, retries = self._request_opts(timeout, retries)
        ms = min(max(1, int(round(timeout * 1000))), 2**31 - 1)

        def ask(data, second=False):
            # the answer of one transact (a Packet), or None after a timeout
            # (the second look: after any error the library returns; a
            # closed link or a transport error still raises)
            r = self._call(lib.tase_host_transact, self._host, req.group, req.type,
                           data if data else ffi.NULL, len(data), self._reply,
                           lib.TASE_DATA_MAX, ms, retries)
            if r == lib.TASE_ETIMEOUT or (second and r < 0):
                return None
            if r < 0:
                raise error(r, "%s: %s" % (self.url, t.name))
            return _with_meta(_from_data(req.id, ffi.buffer(self._reply, r)[:]), _now_us(), "out")

        echo = ask(req.payload)
        if echo is None:
            raise TimeoutError_(
                "%s: timeout: no answer to %s after %d attempts of %d ms"
                % (self.url, t.name, 1 + retries, ms),
                lib.TASE_ETIMEOUT,
            )
        if t.group == 0x48 and req.size > 0 and _setting_differs(t, req, echo):
            # an answer that came after the send can be an earlier
            # request's (a late or repeated one, another gimbal): the
            # setting in force decides, asked once more (as `tase send`);
            # when that goes unanswered, the echo that came stands
            echo = ask(b"", second=True) or echo
        return echo

    # -- receiving

    def packets(self, timeout=None, count=None):
        """Iterate over the packets received (telemetry, echoes, answers
        not taken by query()), each when it arrives, until `timeout`
        seconds have passed in all (None: no limit) or `count` packets
        were given."""
        self._live()
        _packets_limits(timeout, count)
        deadline = None if timeout is None else time.monotonic() + timeout
        given = 0
        looked = False
        while count is None or given < count:
            self._live()  # closed meanwhile (by the caller, another thread)
            if self._queue:
                given += 1
                yield self._queue.popleft()
                continue
            wait = 0.2 if deadline is None else deadline - time.monotonic()
            if wait <= 0 and looked:
                return
            # at least one look at the port, also with timeout 0 (a poll)
            ms = 0 if wait <= 0 else max(1, min(int(wait * 1000), 200))
            looked = True
            if ms == 0:
                # a poll does not wait for another thread's call (recv(0)
                # waited seconds behind a query)
                if not self._call_lock.acquire(blocking=False):
                    continue
                try:
                    # everything the port has ready (at most 16 KiB), not
                    # one 64-byte read: a 10 Hz poll loop fell behind
                    r = self._call(lib.tase_host_drain, self._host)
                finally:
                    self._call_lock.release()
            else:
                r = self._call(lib.tase_host_service, self._host, ms)
            if r < 0:
                raise error(r, "%s: receive" % self.url)

    def recv(self, timeout=None):
        """The next packet received, or TimeoutError after `timeout` s."""
        for p in self.packets(timeout=timeout, count=1):
            return p
        raise TimeoutError_("%s: no packet within %s s" % (self.url, timeout), lib.TASE_ETIMEOUT)

    @property
    def record_error(self):
        """Why the recording of connect(record=...) stopped (a CaptureError,
        e.g. a full disk; a RuntimeWarning said so then), or None while it
        runs or when there is none. The link goes on without it."""
        return getattr(self._t, "failed", None)

    @property
    def stats(self):
        """Counters of the host role and its receiver (32-bit, as the
        library keeps them)."""
        h = self._host.stats
        rx = self._host.rx.stats
        return {
            "frames_tx": h.frames_tx,
            "tx_errors": h.tx_errors,
            "frames_rx": h.frames_rx,
            "requests": h.requests,
            "retries": h.retries,
            "replies": h.replies,
            "timeouts": h.timeouts,
            "late": h.late,
            # frames of a request's type begun before it was sent: not its answer
            "stale": h.stale,
            # zero-length frames received: our own queries coming back
            # (a line that echoes what is sent; a gimbal sends none)
            "queries_rx": h.queries_rx,
            "bytes_in": rx.bytes_in,
            "checksum_errors": rx.checksum_errors,
            "bad_size": rx.bad_size,
            "bytes_discarded": rx.bytes_discarded,
            # frames beyond the link's buffer during one blocking call (32768)
            "frames_dropped": self._sink.s.dropped,
        }

    # -- the CLI's safe verbs (tase point/rate/spoi/retract/deploy/camera)

    def point(self, pan, tilt, stab=True):
        """GIMBAL_CMD position (`tase point`): pan -180..180 and tilt
        -270..90 degrees (the spec's ranges, tase/units.h)."""
        for name, v, lo, hi in (
            ("pan", pan, lib.TASE_PAN_MIN_CDEG, lib.TASE_PAN_MAX_CDEG),
            ("tilt", tilt, lib.TASE_TILT_MIN_CDEG, lib.TASE_TILT_MAX_CDEG),
        ):
            if (
                isinstance(v, bool)
                or not isinstance(v, (int, float))
                or not lo / 100 <= v <= hi / 100
            ):
                raise FieldError(
                    "point: %s %r is not a number in %g..%g degrees" % (name, v, lo / 100, hi / 100)
                )
        flags = lib.TASE_GIMBAL_FLAGS_POSITION_STAB if _stab("point", stab) else lib.TASE_GIMBAL_FLAGS_POSITION
        return self.send(_gimbal_cmd(pan, tilt, flags))

    def rate(self, pan_rate, tilt_rate, stab=True):
        """GIMBAL_CMD rate (`tase rate`): deg/s, -327.68..327.67; rate(0, 0) stops."""
        for name, v in (("pan_rate", pan_rate), ("tilt_rate", tilt_rate)):
            if (
                isinstance(v, bool)
                or not isinstance(v, (int, float))
                or not -327.68 <= v <= 327.67
            ):
                raise FieldError(
                    "rate: %s %r is not a number in -327.68..327.67 deg/s" % (name, v)
                )
        flags = lib.TASE_GIMBAL_FLAGS_RATE_STAB if _stab("rate", stab) else lib.TASE_GIMBAL_FLAGS_RATE
        return self.send(_gimbal_cmd(pan_rate, tilt_rate, flags))

    def spoi(self, lat, lon, height, wait=True, timeout=None, retries=None):
        """SPOI_CMD (`tase spoi`): degrees WGS-84, metres; no velocity. With
        wait the echo is requested and returned, and its position compared
        (Error if it differs); else the packet sent is returned."""
        _flag("spoi: wait", wait)
        for name, v in (("latitude", lat), ("longitude", lon), ("height", height)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise FieldError("spoi: %s %r is not a number: nothing sent" % (name, v))
        if not -90 <= lat <= 90 or not -180 <= lon <= 180:
            raise FieldError("spoi: latitude %r / longitude %r out of range" % (lat, lon))
        p = Packet(
            "SPOI_CMD",
            lat=lat,
            lon=lon,
            height=height,
            vnorth=0,
            veast=0,
            vdown=0,
            raw={"flags": lib.TASE_SPOI_ECHO if wait else 0},
        )
        if not wait:
            return self.send(p)
        echo = self.query(p, timeout, retries)
        sent, got = p.raw, echo.raw
        for k in ("lat", "lon", "height"):
            if got.get(k) != sent[k]:
                raise Error(
                    "%s: SPOI_CMD not applied as sent: %s sent %d, gimbal has %s"
                    % (self.url, k, sent[k], got.get(k))
                )
        # a gimbal that took the point tracks it (4.3.2); the echo's flags
        # are its Mode byte (PROTOCOL-NOTES P4: the mode in bits 3-7, the
        # low five bits); flags 0x80 as sent: our own packet from a line
        # that echoes, most likely
        mode = got["flags"] & 0x1F
        if mode != lib.TASE_MODE_SPOI:
            raise Error(
                "%s: SPOI_CMD echoed with flags 0x%02X: the gimbal reports mode %d, not SPOI (%d), "
                "so it is not tracking the point%s"
                % (self.url, got["flags"], mode, lib.TASE_MODE_SPOI,
                   " (flags as sent: our own packet back from a line that echoes?)"
                   if got["flags"] == lib.TASE_SPOI_ECHO else "")
            )
        return echo

    def _retract_deploy(self, deploy, wait):
        if wait is not None:
            # before sending; 0 s would send and then time out at once
            what = "%s: wait" % ("deploy" if deploy else "retract")
            if _seconds(what, wait) == 0:
                raise FieldError("%s: 0 is no time to wait (None: do not wait); nothing sent" % what)
        p = Packet("RETRACT_DEPLOY_CMD", deploy=lib.TASE_DEPLOY if deploy else lib.TASE_RETRACT)
        self.send(p)
        if wait is None:
            return p
        others = []  # left for packets(), in order, after the wait
        try:
            for q in self.packets(timeout=wait):
                if q.name == "RETRACT_DEPLOY_CMD" and q.size > 0:
                    if bool(q.raw["deploy"]) != deploy:
                        raise Error(
                            "%s: the gimbal reports %s"
                            % (self.url, "deployed" if q.raw["deploy"] else "retracted")
                        )
                    return q
                others.append(q)
        finally:
            self._queue.extendleft(reversed(others))
        raise TimeoutError_(
            "%s: no RETRACT_DEPLOY_CMD echo within %s s (the move is not complete, or the "
            "gimbal has no 3AX retract: it is an option, 4.1.6)" % (self.url, wait),
            lib.TASE_ETIMEOUT,
        )

    def retract(self, wait=None):
        """RETRACT_DEPLOY_CMD deploy=0; wait: seconds to wait for the echo
        the gimbal sends when the move is complete (returned)."""
        return self._retract_deploy(False, wait)

    def deploy(self, wait=None):
        """RETRACT_DEPLOY_CMD deploy=1; wait as retract()."""
        return self._retract_deploy(True, wait)

    def camera(self, camera=None, hfov=None, zoom=None, timeout=None, retries=None):
        """CAMERA_CMD (`tase camera`): camera "A"/"B"/"C" (checked first in
        the gimbal's SYSTEM_VERSION: a camera it does not have is refused,
        nothing sent), hfov in degrees (0.01..327.67) or zoom ratio
        (1..327.68); every other field "do not change"."""
        self._request_opts(timeout, retries)  # checked even when no query is made
        if hfov is not None and zoom is not None:
            raise FieldError("camera: hfov or zoom, not both")
        cam = None
        if camera is not None:
            if not isinstance(camera, str) or camera.upper() not in ("A", "B", "C"):
                raise FieldError("camera: %r is not A, B or C" % (camera,))
            cam = "ABC".index(camera.upper())
        elif hfov is None and zoom is None:
            raise FieldError("camera: name a camera, an hfov or a zoom")
        if hfov is not None and (
            isinstance(hfov, bool) or not isinstance(hfov, (int, float)) or not 0.01 <= hfov <= 327.67
        ):
            raise FieldError("camera: hfov %r is not in 0.01..327.67 degrees" % (hfov,))
        if zoom is not None and (
            isinstance(zoom, bool) or not isinstance(zoom, (int, float)) or not 1 <= zoom <= 327.68
        ):
            raise FieldError("camera: zoom %r is not in 1..327.68" % (zoom,))
        if cam is not None:
            version = self.query("SYSTEM_VERSION", timeout, retries)
            kind = version.raw["camera_" + "abc"[cam]]
            if kind == lib.TASE_CAMTYPE_NONE:
                raise Error(
                    "%s: the gimbal has no camera %s (SYSTEM_VERSION: type 0xFF, none); "
                    "CAMERA_CMD was not sent" % (self.url, "ABC"[cam])
                )
        raw = {}
        if cam is not None:
            raw["camera"] = cam
        if hfov is not None:
            raw["hfov"] = _scaled(hfov, 100)
        if zoom is not None:
            raw["hfov"] = -_scaled(zoom, 100)
        if hfov is None and zoom is None:
            return self.send(Packet("CAMERA_CMD", raw=raw, length=1))
        return self.send(Packet("CAMERA_CMD", raw=raw))


def _gimbal_cmd(pan, tilt, flags):
    return Packet(
        "GIMBAL_CMD",
        raw={
            "pan": _scaled(pan, 100),
            "tilt": _scaled(tilt, 100),
            "roll": 0,
            "flags": flags,
            "impulse_time": 0,
        },
    )


def _now_us():
    return int(time.time() * 1e6)


