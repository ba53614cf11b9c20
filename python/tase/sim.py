"""tase.sim.start(): the simulated gimbal `tase-sim` for tests and scripts.

    with tase.sim.start() as sim, tase.connect(sim.url) as link:
        link.point(45, -20)

It runs `tase-sim` on a new pseudo-terminal (its --link symlink in a
temporary directory), with can="IFACE" on a SocketCAN interface, or with
virtual="NAME" on python-can's in-process virtual bus NAME (tase-sim on a
pty with --can-pty, so that its link is the CAN port, PACKET_RATE's port 3;
its bytes carried to and from the bus in CAN frames of the spec's
encapsulation by a thread of this process: CAN without kernel support),
and stops it on exit from the with block, also on an exception (a Sim
never stopped is stopped when it is garbage collected, at the latest when
the interpreter exits). The program is found as $TASE_SIM, else
`tase-sim` on the PATH.
"""

import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
import weakref

from ._core import Error, FieldError, error, ffi, lib
from .link import _BAUDS

__all__ = ["start", "Sim", "find_program"]

_READY = re.compile(r"simulated gimbal on (\S+?),? ")


def find_program():
    path = os.environ.get("TASE_SIM") or shutil.which("tase-sim")
    if not path:
        raise Error(
            "tase-sim not found: install tase-tools, put it on the PATH or set TASE_SIM "
            "to its path"
        )
    return path


class _Running:
    """What a Sim holds outside Python (the process, the CAN bridge's
    threads, the temporary directory), apart from the Sim so that a
    finalizer can release it: Sim.stop(), else the Sim's collection, else
    the interpreter's exit."""

    def __init__(self, dir):
        self.dir = dir
        self.proc = None
        self.bridge = None

    def halt(self):
        """Stop the bridge and the process (SIGTERM, then SIGKILL after 5 s)."""
        if self.bridge is not None:
            bridge, self.bridge = self.bridge, None
            bridge.stop()
        proc = self.proc
        if proc is not None and proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()

    def release(self):
        """halt() and remove the temporary directory."""
        try:
            self.halt()
        finally:
            shutil.rmtree(self.dir, ignore_errors=True)


def _check_args(baud, can, virtual):
    """FieldError, nothing started, for a sim whose url tase.connect()
    would refuse: a baud it does not take (1200 started tase-sim, then
    connect(sim.url) refused the url), an empty or non-str interface or
    bus name (virtual="" gave the url "virtual:")."""
    if isinstance(baud, bool) or not isinstance(baud, int) or baud not in _BAUDS:
        raise FieldError(
            "tase.sim.start(): baud %r is not one of %s (what tase.connect() takes)"
            % (baud, ", ".join(map(str, _BAUDS)))
        )
    for what, v in (("can", can), ("virtual", virtual)):
        if v is not None and (not isinstance(v, str) or not v):
            raise FieldError("tase.sim.start(): %s %r is not an interface or bus name" % (what, v))


class Sim:
    """A running tase-sim. url: what tase.connect() takes; log(): what it
    printed so far; pid; stop(). One never stopped is stopped when it is
    garbage collected, at the latest when the interpreter exits (its
    temporary directory removed with it). A program that cannot be run or
    that does not start is a tase.Error, nothing left behind."""

    def __init__(
        self, baud=57600, can=None, seconds=None, program=None, ready_timeout=10.0, virtual=None
    ):
        if can is not None and virtual is not None:
            raise Error("tase.sim.start(): can or virtual, not both")
        _check_args(baud, can, virtual)
        self._log_text = None
        self.program = program or find_program()
        self.dir = tempfile.mkdtemp(prefix="tase-sim-")
        self._run = _Running(self.dir)
        # not a method of self: the finalizer must not keep the Sim alive
        self._finalizer = weakref.finalize(self, self._run.release)
        try:
            self._start(baud, can, seconds, ready_timeout, virtual)
        except BaseException:
            self._finalizer()
            raise

    def _start(self, baud, can, seconds, ready_timeout, virtual):
        self.logfile = os.path.join(self.dir, "sim.log")
        args = [self.program]
        if can is not None:
            args += ["--can", can]
            self.url = "socketcan:" + can
        else:
            link = os.path.join(self.dir, "gimbal")
            # the virtual bus carries the pty's bytes in CAN frames: the
            # gimbal's CAN port (PACKET_RATE port 3, CAN's capacity)
            args += ["--link", link] + (["--can-pty"] if virtual is not None else ["--baud", str(baud)])
            self.url = "serial:%s:%d" % (link, baud)
            self.link = link
        if seconds is not None:
            args += ["--seconds", str(seconds)]
        try:
            with open(self.logfile, "wb") as log:
                self.proc = self._run.proc = subprocess.Popen(
                    args, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT
                )
        except OSError as e:
            raise Error("cannot run tase-sim %s: %s" % (self.program, e.strerror or e)) from e
        self.pid = self.proc.pid
        deadline = time.monotonic() + ready_timeout
        while True:
            text = self.log()
            if _READY.search(text) and (can is not None or os.path.exists(self.link)):
                break
            if self.proc.poll() is not None:
                raise Error("tase-sim exited with status %d: %s" % (self.proc.returncode, text.strip()))
            if time.monotonic() > deadline:
                raise Error("tase-sim did not start within %s s: %s" % (ready_timeout, text.strip()))
            time.sleep(0.02)
        if virtual is not None:
            self._run.bridge = _Bridge(self.link, baud, virtual)
            self.url = "virtual:" + virtual

    def log(self):
        """What tase-sim printed (its log of commands), also after stop()."""
        if self._log_text is not None:
            return self._log_text
        try:
            with open(self.logfile, "rb") as f:
                return f.read().decode(errors="replace")
        except OSError:
            return ""

    def stop(self):
        """Stop the simulator (SIGTERM, then SIGKILL after 5 s) and remove
        its temporary directory. Returns its exit status."""
        self._run.halt()
        if self._log_text is None:
            self._log_text = self.log()
        self._finalizer()
        return self.proc.returncode

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()
        return False


def start(baud=57600, can=None, seconds=None, program=None, virtual=None):
    """Start tase-sim (see the module's doc); returns a Sim to use in a
    with statement."""
    return Sim(baud=baud, can=can, seconds=seconds, program=program, virtual=virtual)


class _Bridge:
    """tase-sim's pty <-> a python-can virtual bus, as the gimbal's CAN
    node: the sim's bytes go out in frames of ID 0x10000000 (the library's
    splitter), frames of ID 0x11000000 (the library's acceptance) go in."""

    def __init__(self, dev, baud, channel):
        import can

        from .link import _SerialTransport

        self.can = can
        self.pty = _SerialTransport(dev, baud)
        self.bus = can.Bus(interface="virtual", channel=channel)
        self.done = False
        self.frames = ffi.new("tase_can_frame_t[]", 64)
        self.threads = [threading.Thread(target=f, daemon=True) for f in (self._out, self._in)]
        for t in self.threads:
            t.start()

    def _out(self):
        while not self.done:
            try:
                data = self.pty.read(256, 0.05)
            except Error:
                return
            if not data:
                continue
            n = lib.tase_can_split(lib.TASE_CAN_ROLE_GIMBAL, data, len(data), self.frames, 64)
            if n < 0:
                raise error(n, "CAN split")
            for i in range(n):
                f = self.frames[i]
                self.bus.send(
                    self.can.Message(
                        arbitration_id=f.id, is_extended_id=True, data=bytes(f.data[0 : f.dlc])
                    )
                )

    def _in(self):
        one = ffi.new("tase_can_frame_t *")
        while not self.done:
            m = self.bus.recv(0.05)
            if m is None or m.is_error_frame or m.is_remote_frame or len(m.data) > 8:
                continue
            one.id = m.arbitration_id
            one.extended = m.is_extended_id
            one.dlc = len(m.data)
            ffi.memmove(one.data, bytes(m.data), len(m.data))
            n = lib.tase_can_accept(lib.TASE_CAN_ROLE_GIMBAL, one)
            if n > 0:
                try:
                    self.pty.write(bytes(m.data[:n]))
                except Error:
                    return

    def stop(self):
        self.done = True
        for t in self.threads:
            t.join(2.0)
        self.bus.shutdown()
        self.pty.close()
