"""tase.sim: a simulator that cannot start is a tase.Error and leaves
nothing behind; one never stopped is stopped when its Sim goes (collected,
or the interpreter exits)."""

import os
import shutil
import subprocess
import sys
import tempfile
import time

import pytest

import tase


def _running(pid):
    """Whether process pid runs (a zombie nobody reaped does not)."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _wait_gone(pid, seconds=10.0):
    deadline = time.monotonic() + seconds
    while _running(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    return not _running(pid)


def test_start_with_a_missing_program(tmp_path, monkeypatch):
    # a bare FileNotFoundError, and the temporary directory left behind
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    with pytest.raises(tase.Error, match="/nonexistent/tase-sim"):
        tase.sim.start(program="/nonexistent/tase-sim")
    assert os.listdir(tmp_path) == []
    prog = tmp_path / "not-a-program"
    prog.write_text("not executable\n")
    with pytest.raises(tase.Error, match="not-a-program"):
        tase.sim.start(program=str(prog))
    assert os.listdir(tmp_path) == ["not-a-program"]


SCRIPT = r"""
import sys, tase
sim = tase.sim.start(seconds=60)
print(sim.pid, sim.dir, flush=True)
if sys.argv[1] == "collected":
    pid = sim.pid
    del sim
    import os
    print(os.path.exists("/proc/%d" % pid), flush=True)  # waited for: no zombie either
"""


@pytest.mark.parametrize("how", ["exit", "collected"])
def test_a_sim_never_stopped_is_stopped(tase_sim, how):
    # tase-sim ran on after the interpreter exited (no finalizer), its
    # temporary directory with it
    r = subprocess.run([sys.executable, "-c", SCRIPT, how], capture_output=True, text=True,
                       timeout=60, env=dict(os.environ, TASE_SIM=tase_sim))
    assert r.returncode == 0, r.stderr
    out = r.stdout.split()
    pid, where = int(out[0]), out[1]
    try:
        if how == "collected":
            assert out[2] == "False", "tase-sim still runs after its Sim was collected"
        assert _wait_gone(pid, 2.0), "tase-sim %d still runs after its interpreter exited" % pid
        assert not os.path.exists(where)
    finally:
        if _running(pid):
            os.kill(pid, 9)
        shutil.rmtree(where, ignore_errors=True)


def test_the_simulator_says_what_it_dropped(tase_sim):
    # a review: a frame with a bad checksum, a setup packet of a wrong
    # length were dropped without a word (other packets were logged)
    import tty

    bad = bytearray(tase.encode(tase.Packet.query("PACKET_RATE")))
    bad[-1] ^= 0xFF
    short = tase.encode(tase.Packet.from_data(0x48, 0x00, bytes(15)))  # PACKET_RATE is 16
    with tase.sim.start() as sim:
        fd = os.open(sim.url.split(":")[1], os.O_RDWR | os.O_NOCTTY)
        try:
            tty.setraw(fd)
            os.write(fd, bytes(bad) + short)
            time.sleep(0.5)
        finally:
            os.close(fd)
    line = [l for l in sim.log().splitlines() if "stopped:" in l][-1]
    assert "dropped: 1 checksum errors, 1 setup packets of a wrong length" in line, line


def test_the_stale_link_of_a_killed_sim_is_refused(tase_sim):
    # a review: tase-sim killed with SIGKILL leaves its link to /dev/pts/N;
    # the next program that asks for a pty may get N (here another
    # simulator) and connect() opened it, the commands going to that
    # program. Refused whether the pty was reused or not, nothing sent.
    with tase.sim.start() as sim:
        dev = sim.link
        pts = os.readlink(dev)
        sim.proc.kill()
        sim.proc.wait()
        with tase.sim.start() as other:  # likely on the same pty
            with pytest.raises(tase.LinkError, match="is the link of a tase-sim that is no "
                               "longer running .*may belong to another program now") as e:
                with tase.connect(sim.url) as link:
                    link.point(10, 5)
            assert pts in str(e.value)
            time.sleep(0.3)
            assert "GIMBAL_CMD" not in other.log()
        with tase.sim.start() as live:  # a live simulator's link still opens
            with tase.connect(live.url) as link:
                assert link.query("SYSTEM_VERSION").name == "SYSTEM_VERSION"


@pytest.mark.parametrize(
    "kw, text",
    [
        # a review: baud=1200 started tase-sim, whose url connect() then
        # refused; virtual="" gave the url "virtual:"; "x" and can=5 were
        # TypeErrors from deep inside
        (dict(baud=1200), "baud 1200 is not one of 9600"),
        (dict(baud="x"), "baud 'x'"),
        (dict(virtual=""), "virtual ''"),
        (dict(can=5), "can 5"),
    ],
)
def test_start_refuses_what_connect_would_refuse(tase_sim, kw, text):
    with pytest.raises(tase.FieldError, match=text):
        tase.sim.start(**kw)
    with tase.sim.start(baud=9600) as sim, tase.connect(sim.url) as link:
        assert sim.url.endswith(":9600")
        assert link.query("SYSTEM_VERSION").name == "SYSTEM_VERSION"
