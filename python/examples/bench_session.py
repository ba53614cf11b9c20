#!/usr/bin/env python3
"""A bench session: connect, query, point, record telemetry, plot.

    python3 bench_session.py [URL] [-o DIR]

URL is a link (serial:/dev/ttyUSB0:57600, socketcan:can0, virtual:NAME);
without one the script starts the simulator (tase-sim) and uses it.
"""

import argparse
import contextlib
import os

import tase


def session(url, out):
    capture = os.path.join(out, "session.pcap")
    if os.path.exists(capture):
        os.remove(capture)
    # record= keeps every byte of the session in a capture that
    # `tase decode`, Wireshark and tase.read_capture() read
    with tase.connect(url, timeout=0.5, retries=2, record=capture) as link:
        version = link.query("SYSTEM_VERSION")  # TimeoutError if no gimbal answers
        v = version.fields
        print("gimbal software %d.%d.%d, board %d" % (v["major"], v["minor"], v["sub"], v["board_sn"]))

        rates = link.query("PACKET_RATE")
        # port 2 is the gimbal's second serial port (Com3), tase-sim's link
        print("telemetry rates on port 2:", rates.raw["angle_2"], rates.raw["rate_2"], "per second")

        # look 30 degrees right and 10 down, then wait until the gimbal is there
        link.point(30, -10)
        for p in link.packets(timeout=5.0):
            if p.name == "GIMBAL_ANGLE":
                pan, tilt = p.fields["pan"], p.fields["tilt"]
                if abs(pan - 30) < 0.5 and abs(tilt + 10) < 0.5:
                    print("on target at pan %.2f, tilt %.2f deg" % (pan, tilt))
                    break
        else:
            raise SystemExit("the gimbal did not reach pan 30, tilt -10 within 5 s")

        # a slow pan to the left for one second, then stop (in a finally:
        # an exception or Ctrl-C must not leave the gimbal turning)
        link.rate(-20, 0)
        try:
            telemetry = list(link.packets(timeout=1.0))
        finally:
            link.rate(0, 0)
        angles = [p for p in telemetry if p.name == "GIMBAL_ANGLE"]
        print("%d packets in 1 s, %d GIMBAL_ANGLE" % (len(telemetry), len(angles)))
        with open(os.path.join(out, "telemetry.jsonl"), "w") as f:
            for p in telemetry:
                f.write(p.json(units=True) + "\n")  # `tase monitor --json --units --time`'s, + "dir"
        print("link statistics:", link.stats)

    tase.plot.plot_capture(capture, os.path.join(out, "session.png"))
    print("wrote", capture, "and", os.path.join(out, "session.png"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("url", nargs="?")
    ap.add_argument("-o", "--out", default=".")
    a = ap.parse_args()
    with contextlib.ExitStack() as stack:
        url = a.url or stack.enter_context(tase.sim.start()).url
        session(url, a.out)


if __name__ == "__main__":
    main()
