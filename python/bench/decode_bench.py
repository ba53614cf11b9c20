#!/usr/bin/env python3
"""Throughput of tase.decode() against `tase decode` (issue 22).

    python3 python/bench/decode_bench.py --tase build/tools/tase [--mb 50] [--runs 3]

Writes two dense telemetry files of --mb MB into a temporary directory
(GIMBAL_ANGLE only; GIMBAL_ANGLE, GIMBAL_RATE and GEOREFERENCE_DATA in
tase-sim's default 10:10:4 ratio), then times, best of --runs each, in one
run of this program:
  - `tase decode FILE > /dev/null` (JSON lines, the CLI's decoder), and
  - tase.decode(open(FILE, "rb").read()) into a list of Packet objects,
and prints the ratio. Exit status 1 when tase.decode is more than 10 times
slower (the bound of issue 22) on either file. Uses the tase package on
sys.path (PYTHONPATH=build/python after ctest's python_build).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

import tase


def telemetry(names, mb):
    frames = []
    for n in names:
        t = tase.packet_type(n)
        raw = {f.name: (i * 37 + 11) % (f.max + 1) if f.min == 0 else (i * 37) % f.max
               for i, f in enumerate(t.fields)}
        frames.append(tase.encode(tase.Packet(n, raw=raw)))
    block = b"".join(frames)
    return block * (mb * 1000 * 1000 // len(block))


def best(fn, runs):
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        r = fn()
        times.append(time.perf_counter() - t)
    return min(times), r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tase", required=True, help="the tase program")
    ap.add_argument("--mb", type=int, default=50)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    mixes = [
        ("GIMBAL_ANGLE only", ["GIMBAL_ANGLE"]),
        ("angle + rate + georef (10:10:4)",
         (["GIMBAL_ANGLE", "GIMBAL_RATE"] * 5 + ["GEOREFERENCE_DATA"] * 2) * 2),
    ]
    worst = 0.0
    print("| telemetry | size | frames | `tase decode` | `tase.decode()` | ratio |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        for label, names in mixes:
            path = os.path.join(d, "t.bin")
            data = telemetry(names, a.mb)
            with open(path, "wb") as f:
                f.write(data)
            del data
            with open(os.devnull, "wb") as null:
                c, _ = best(lambda: subprocess.run([a.tase, "decode", path], stdout=null,
                                                   check=True), a.runs)

            def py():
                with open(path, "rb") as f:
                    return len(tase.decode(f.read()))

            p, n = best(py, a.runs)
            size = os.path.getsize(path)
            ratio = p / c
            worst = max(worst, ratio)
            print("| %s | %.0f MB | %d | %.3f s (%.0f MB/s) | %.3f s (%.0f MB/s) | %.1f |"
                  % (label, size / 1e6, n, c, size / 1e6 / c, p, size / 1e6 / p, ratio))
    print("worst ratio %.1f (bound 10)" % worst)
    return 0 if worst <= 10 else 1


if __name__ == "__main__":
    sys.exit(main())
