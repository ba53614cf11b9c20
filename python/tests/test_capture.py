"""tase.read_capture(): a capture recorded by `tase record` reads back with
the same packets and times as `tase decode`; capture: links."""

import json
import os
import subprocess
import sys

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


def test_plot_commanded_vs_reported(recorded, tmp_path):
    pytest.importorskip("matplotlib")
    cap, _ = recorded
    out = tmp_path / "run.png"
    r = subprocess.run([sys.executable, "-m", "tase", "plot", cap, "-o", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    s = tase.plot.series(cap)
    assert s["pan_cmd"][1][0] == 10.0 and s["tilt_cmd"][1][0] == 20.0
    assert s["pan_cmd"][0][-1] > 1.0  # held to the end of the capture
    assert len(s["pan"][0]) > 5 and len(s["pan_rate"][0]) > 5


def test_module_decode_equals_tase_decode(recorded):
    cap, lines = recorded
    r = subprocess.run([sys.executable, "-m", "tase", "decode", cap],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == lines


def test_link_records_a_capture_tase_decode_reads(sim, tase_cli, tmp_path):
    cap = str(tmp_path / "py.pcap")
    with tase.connect(sim.url, record=cap) as link:
        link.query("SYSTEM_VERSION")
        link.point(5, 5)
        n = len(list(link.packets(timeout=0.5)))
    r = subprocess.run([tase_cli, "decode", cap], capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert [p.json() for _, p in tase.read_capture(cap)] == lines
    names = [json.loads(x)["name"] for x in lines]
    assert names[:2] == ["SYSTEM_VERSION", "SYSTEM_VERSION"] and "GIMBAL_CMD" in names
    assert len(lines) >= n + 3
    # appended to by a second session, refused for a file that is not one
    with tase.connect(sim.url, record=cap) as link:
        link.query("PACKET_RATE")
    assert len(list(tase.read_capture(cap))) > len(lines)
    bad = tmp_path / "bad.pcap"
    bad.write_bytes(b"not a capture at all, no")
    with pytest.raises(ValueError, match="not appending"):
        tase.connect(sim.url, record=str(bad))


def test_bench_script_of_the_docs_runs_against_tase_sim(tase_sim, tmp_path):
    from conftest import ROOT

    script = open(os.path.join(ROOT, "python", "examples", "bench_session.py")).read()
    doc = open(os.path.join(ROOT, "docs", "PYTHON.md")).read()
    assert script in doc  # the docs show the script that is tested
    r = subprocess.run([sys.executable, os.path.join(ROOT, "python", "examples",
                                                     "bench_session.py"), "-o", str(tmp_path)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "on target at pan" in r.stdout
    assert (tmp_path / "session.png").stat().st_size > 1000
    assert len(list(tase.read_capture(str(tmp_path / "session.pcap")))) > 20
