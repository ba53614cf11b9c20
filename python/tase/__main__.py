"""python3 -m tase: small commands over the package.

    python3 -m tase plot CAPTURE -o FILE.png [--baud N]
    python3 -m tase decode FILE        (JSON lines, as `tase decode`)
    python3 -m tase version
"""

import argparse
import errno
import signal
import sys

import tase


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m tase")
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("plot", help="commanded vs reported pan/tilt of a capture")
    p.add_argument("capture")
    p.add_argument("-o", "--output", required=True, help="image file (.png, .svg, .pdf)")
    p.add_argument("--baud", type=int, default=57600, help="serial line rate (default 57600)")
    d = sub.add_parser("decode", help="a raw serial capture or a tase record capture as JSON")
    d.add_argument("file")
    sub.add_parser("version")
    a = ap.parse_args(argv)
    try:
        if a.cmd == "version":
            print(tase.__version__)
        elif a.cmd == "plot":
            s = tase.plot.plot_capture(a.capture, a.output, a.baud)
            print("%s: %s" % (a.output, ", ".join("%s (%d)" % (k, len(v[0])) for k, v in s.items())))
        elif a.cmd == "decode":
            try:
                with open(a.file, "rb") as f:
                    head = f.read(4)
            except OSError as e:
                # `tase decode`'s words
                print(
                    "tase: cannot %s %s: %s"
                    % ("open" if e.errno == errno.ENOENT else "read", a.file, e.strerror or e),
                    file=sys.stderr,
                )
                return 1
            n = 0
            if head[:4] in tase.capture.MAGICS:
                cap = tase.capture.Capture(a.file)
                for _, pkt in cap:
                    print(pkt.json())
                    n += 1
                # as `tase decode`: each bad record said, the rest decoded, exit 4
                for index, why in cap.bad:
                    print("tase: %s: record %d skipped: %s" % (a.file, index, why), file=sys.stderr)
                if cap.bad:
                    n = len(cap.bad)
                    print(
                        "tase: %s: %d bad record%s (the rest was decoded)"
                        % (a.file, n, "" if n == 1 else "s"),
                        file=sys.stderr,
                    )
                    return 4
                if n == 0 and cap.records > 0:
                    print("tase: no TASE packet found in %s" % a.file, file=sys.stderr)
                    return 4
            else:
                with open(a.file, "rb") as f:
                    data = f.read()
                for pkt in tase.decode(data):
                    print(pkt.json())
                    n += 1
                if n == 0 and data:
                    # as `tase decode`: bytes but no packet is exit 4
                    print(
                        "tase: no TASE packet found in %s (not a capture of a TASE serial line?)"
                        % a.file,
                        file=sys.stderr,
                    )
                    return 4
    except (tase.Error, OSError, ValueError) as e:
        print("tase: %s" % e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    # as `tase decode | head`: a reader that went away ends the program as
    # SIGPIPE does a C one (exit 141, no message), not with "Broken pipe"
    # (only here: main() called from Python keeps its caller's handling)
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    sys.exit(main())
