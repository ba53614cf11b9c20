"""`python3 -m tase plot CAPTURE -o FILE.png`: commanded against reported
pan and tilt (and rates) over the time of a `tase record` capture, drawn
with matplotlib (Debian python3-matplotlib)."""

import os

from .capture import read_capture

__all__ = ["series", "plot_capture"]

# GIMBAL_CMD flags (spec table 5, tase/flags.h): the drawn kind of each
# value; impulse and SPOI error commands (and values outside the table)
# are not drawn and leave the command in force as it was.
_DRAWN = {
    0x00: "_rate",  # legacy rate
    0x02: "_rate",  # legacy rate, stabilised
    0x10: "_rate",
    0x90: "_rate",
    0x01: "",  # legacy position
    0x03: "",  # legacy position, stabilised
    0x20: "",
    0xA0: "",
}


def series(path, baud=57600):
    """The curves of a capture: dict of name -> (times, values), times in
    seconds from the first packet. Reported: GIMBAL_ANGLE pan/tilt (deg)
    and GIMBAL_RATE pan_rate/tilt_rate (deg/s). Commanded (GIMBAL_CMD sent
    to the gimbal): pan_cmd/tilt_cmd (deg) while position commands are in
    force and pan_rate_cmd/tilt_rate_cmd (deg/s) while rate commands are
    (the legacy flags values included), each value held until the next
    command (NaN between: no line drawn); impulse and SPOI error commands
    change neither."""
    out = {}
    t0 = None
    last = None
    mode = None  # the kind of command in force: "" (position) or "_rate"

    def add(name, t, v):
        ts, vs = out.setdefault(name, ([], []))
        ts.append(t)
        vs.append(v)

    def hold(t, end=False):
        if mode is not None:
            for axis in ("pan", "tilt"):
                name = axis + mode + "_cmd"
                add(name, t, out[name][1][-1])
                if end:
                    add(name, t, float("nan"))

    for t, p in read_capture(path, baud):
        if t is None:
            continue
        if t0 is None:
            t0 = t
        t -= t0
        last = t
        if p.error is not None or p.size == 0:
            continue
        if p.name == "GIMBAL_ANGLE":
            f = p.fields
            add("pan", t, f["pan"])
            add("tilt", t, f["tilt"])
        elif p.name == "GIMBAL_RATE":
            f = p.fields
            add("pan_rate", t, f["pan_rate"])
            add("tilt_rate", t, f["tilt_rate"])
        elif p.name == "GIMBAL_CMD" and p.dir == "in":
            r = p.raw
            kind = _DRAWN.get(r["flags"])
            if kind is None:
                continue  # the gimbal keeps the position or rate command it had
            hold(t, end=kind != mode)
            mode = kind
            add("pan" + kind + "_cmd", t, r["pan"] / 100.0)
            add("tilt" + kind + "_cmd", t, r["tilt"] / 100.0)
    if last is not None:
        hold(last)
    return out


def plot_capture(path, out, baud=57600, title=None):
    """Draw the capture's curves into image file `out` (in the format of
    its extension, PNG, SVG, PDF or another matplotlib writes such as
    JPEG; PNG for one it does not know or none, under the name given: the file
    written is `out`, never `out` + ".png"). A directory is a ValueError.
    Returns the series drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if os.path.isdir(out):
        raise ValueError("%s is a directory: give the image file's name" % out)
    s = series(path, baud)
    if not s:
        raise ValueError("%s: no GIMBAL_ANGLE, GIMBAL_RATE or GIMBAL_CMD to plot" % path)
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(10, 7))
    for ax, names, unit in (
        (ax1, ("pan", "tilt"), "deg"),
        (ax2, ("pan_rate", "tilt_rate"), "deg/s"),
    ):
        for name, colour in zip(names, ("tab:blue", "tab:orange")):
            if name in s:
                ax.plot(*s[name], color=colour, label="%s reported" % name)
            if name + "_cmd" in s:
                ax.plot(*s[name + "_cmd"], color=colour, linestyle="--",
                        label="%s commanded" % name)
        ax.set_ylabel(unit)
        ax.grid(True, alpha=0.3)
        if ax.lines:
            ax.legend(loc="best", fontsize="small")
    ax2.set_xlabel("time since the first packet (s)")
    fig.suptitle(title or path)
    fig.tight_layout()
    ext = os.path.splitext(out)[1][1:].lower()
    fmt = ext if ext in fig.canvas.get_supported_filetypes() else "png"
    fig.savefig(out, format=fmt)
    plt.close(fig)
    return s
