"""tase.read_capture(): a capture recorded by `tase record` reads back with
the same packets and times as `tase decode`; capture: links."""

import subprocess

import pytest

import tase


@pytest.fixture(scope="module")
def recorded(tase_cli, tase_sim, tmp_path_factory):
    """A capture of a bench session against tase-sim, recorded by the CLI:
    a query, a command and 1.5 s of telemetry, both directions."""
    cap = str(tmp_path_factory.mktemp("cap") / "session.pcap")
    with tase.sim.start() as sim:
        dev = sim.link
        for args in (["query", "PACKET_RATE"], ["point", "10", "20"],
                     ["monitor", "--seconds", "1.5"]):
            r = subprocess.run([tase_cli] + args + ["--serial", dev, "--record", cap],
                               capture_output=True, timeout=30)
            assert r.returncode == 0, r.stderr
    r = subprocess.run([tase_cli, "decode", cap], capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    return cap, r.stdout.splitlines()


def test_read_capture_equals_tase_decode(recorded):
    cap, lines = recorded
    got = list(tase.read_capture(cap))
    assert len(got) == len(lines) > 10
    assert [p.json() for _, p in got] == lines
    assert all(t == p.time for t, p in got)
    dirs = {p.dir for _, p in got}
    assert dirs == {"in", "out"}
    names = {p.name for _, p in got}
    assert {"PACKET_RATE", "GIMBAL_CMD", "GIMBAL_ANGLE"} <= names


def test_capture_link_is_read_only(recorded):
    cap, lines = recorded
    with tase.connect("capture:" + cap) as link:
        first = list(link.packets(count=3))
        assert [p.json() for p in first] == lines[:3]
        with pytest.raises(tase.Error, match="read only"):
            link.point(0, 0)


def test_not_a_capture(tmp_path):
    p = tmp_path / "x.pcap"
    p.write_bytes(b"hello world, not pcap")
    with pytest.raises(ValueError, match="not a pcap"):
        list(tase.read_capture(str(p)))
