"""tase.sim.start(): the simulated gimbal `tase-sim` for tests and scripts.

    with tase.sim.start() as sim, tase.connect(sim.url) as link:
        link.point(45, -20)

It runs `tase-sim` on a new pseudo-terminal (its --link symlink in a
temporary directory) or, with can="IFACE", on a SocketCAN interface, and
stops it on exit from the with block, also on an exception. The program is
found as $TASE_SIM, else `tase-sim` on the PATH.
"""

import os
import re
import shutil
import signal
import subprocess
import tempfile
import time

from ._core import Error

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


class Sim:
    """A running tase-sim. url: what tase.connect() takes; log(): what it
    printed so far; pid; stop()."""

    def __init__(self, baud=57600, can=None, seconds=None, program=None, ready_timeout=10.0):
        self.program = program or find_program()
        self.dir = tempfile.mkdtemp(prefix="tase-sim-")
        self.logfile = os.path.join(self.dir, "sim.log")
        args = [self.program]
        if can is not None:
            args += ["--can", can]
            self.url = "socketcan:" + can
        else:
            link = os.path.join(self.dir, "gimbal")
            args += ["--link", link, "--baud", str(baud)]
            self.url = "serial:%s:%d" % (link, baud)
            self.link = link
        if seconds is not None:
            args += ["--seconds", str(seconds)]
        with open(self.logfile, "wb") as log:
            self.proc = subprocess.Popen(
                args, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT
            )
        self.pid = self.proc.pid
        deadline = time.monotonic() + ready_timeout
        while True:
            text = self.log()
            if _READY.search(text) and (can is not None or os.path.exists(self.link)):
                break
            if self.proc.poll() is not None:
                self._cleanup()
                raise Error("tase-sim exited with status %d: %s" % (self.proc.returncode, text.strip()))
            if time.monotonic() > deadline:
                self.stop()
                raise Error("tase-sim did not start within %s s: %s" % (ready_timeout, text.strip()))
            time.sleep(0.02)

    def log(self):
        try:
            with open(self.logfile, "rb") as f:
                return f.read().decode(errors="replace")
        except OSError:
            return ""

    def stop(self):
        """Stop the simulator (SIGTERM, then SIGKILL after 5 s). Returns
        its exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log_text = self.log()
        self._cleanup()
        return self.proc.returncode

    def _cleanup(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()
        return False


def start(baud=57600, can=None, seconds=None, program=None):
    """Start tase-sim (see the module's doc); returns a Sim to use in a
    with statement."""
    return Sim(baud=baud, can=can, seconds=seconds, program=program)
