#!/usr/bin/env python3
"""Footprint of the core on Cortex-M0+ and Cortex-M4 at -Os: flash and RAM
per module (object file), the receive path and the whole core as linked,
sizeof of every public struct type, worst-case stack depths from
-fstack-usage/-fcallgraph-info, and the example gimbal (examples/firmware)
and autopilot (examples/autopilot) images with their measured stacks.
Writes docs/FOOTPRINT.md (or --out FILE).
Run through bench/footprint.sh, which installs what it needs.

Works on whatever src/*.c exist: modules are found by object file, the
receive path is framing (tase_rx_*) plus every public function of
src/tase_dispatch.c when that module exists, and optional name strings are
src/*names*.c and src/tase_strerror.c."""
import argparse
import glob
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CPUS = ["cortex-m0plus", "cortex-m4"]
TARGET_RX_FLASH = 1024
TARGET_FRAMING_FLASH = 1500
# Framing alone (issue 12): what a firmware that does its own packet
# decoding links of the receiver.
FRAMING_ROOTS = ["tase_rx_init", "tase_rx_push", "tase_rx_feed", "tase_rx_flush"]
TARGET_CORE_FLASH = 4096
TARGET_RX_RAM = 360  # issue 21: the window of a resumable scan
TARGET_RX_STACK = 128


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw).stdout


def optional(module):
    return "names" in module or module == "strerror"


# The "whole core" of issue 8: framing, dispatch, all codecs, CAN and KLV.
# Other modules (host/gimbal roles, candump text logs, port helpers) are
# reported on their own row, outside the 4 KB budget.
CORE_MODULES = ("frame", "frame_time", "dispatch", "schema", "codec", "can", "klv")

# Engineering-unit conversions done in double precision (they pull the
# soft-float library on most MCUs); firmware that forwards raw values does
# not call them. Reported with and without.
FLOAT_HELPER = re.compile(r"^tase_klv_\w+_(deg|raw|m|mps|s)$")


def build(cpu, out):
    """Core library through the toolchain file, with stack and call-graph
    dumps. CFLAGS reaches CMAKE_C_FLAGS without replacing the CPU flags the
    toolchain file puts in CMAKE_C_FLAGS_INIT."""
    bdir = os.path.join(out, cpu)
    env = dict(os.environ, CFLAGS="-fstack-usage -fcallgraph-info=su")
    run(["cmake", "-S", ROOT, "-B", bdir, "-DTASE_CPU=" + cpu,
         "-DCMAKE_TOOLCHAIN_FILE=" + os.path.join(ROOT, "cmake", "arm-none-eabi.cmake")], env=env)
    run(["cmake", "--build", bdir, "-j2"])
    objs = sorted(glob.glob(os.path.join(bdir, "CMakeFiles", "tase.dir", "src", "*.c.obj")))
    # Module names drop the files' "tase_" prefix (tase_frame.c -> frame).
    return bdir, {os.path.basename(o)[:-len(".c.obj")].replace("tase_", "", 1): o for o in objs}


def port_objs(bdir):
    """The bare-metal port's objects (port/baremetal, library tase_baremetal)."""
    return sorted(glob.glob(os.path.join(bdir, "port", "baremetal", "CMakeFiles",
                                         "tase_baremetal.dir", "*.c.obj")))


def berkeley(path):
    line = run(["arm-none-eabi-size", "-B", path]).splitlines()[1].split()
    return int(line[0]), int(line[1]), int(line[2])  # text(+rodata), data, bss


def globals_of(obj):
    syms = []
    for line in run(["arm-none-eabi-nm", "--defined-only", "-g", obj]).splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1] == "T":
            syms.append(parts[2])
    return syms


def link_name(objs, name):
    """The symbol a function links as: the initialisers guarded by
    tase/config.h carry the ABI level, and any configuration that may
    join it later (tase_rx_init -> tase_rx_init_abi2)."""
    for o in objs.values():
        for s in globals_of(o):
            if s == name or re.fullmatch(re.escape(name) + r"_abi\d+(?:_[A-Za-z0-9_]+)?", s):
                return s
    return name


def linked_size(cpu, objs, roots, out):
    """Flash of what `roots` pull in, after --gc-sections. libc (memcpy,
    memchr, ...) is left unresolved: a firmware links it anyway."""
    elf = os.path.join(out, cpu, "path-%s.elf" % roots[0])
    cmd = ["arm-none-eabi-gcc", "-mcpu=" + cpu, "-mthumb", "-nostdlib", "-nostartfiles",
           "-Wl,--gc-sections", "-Wl,--unresolved-symbols=ignore-all", "-Wl,-e," + roots[0]]
    cmd += ["-Wl,-u," + r for r in roots[1:]]
    run(cmd + list(objs) + ["-o", elf])
    text, data, bss = berkeley(elf)
    return text + data, data + bss


def sizeof_types(cpu, out):
    """sizeof of every struct typedef in include/tase: a probe for the
    target defines one array per type, sized by sizeof; nm reads them."""
    headers = sorted(glob.glob(os.path.join(ROOT, "include", "tase", "*.h")))
    types = []
    for h in headers:
        text = open(h).read()
        for m in re.finditer(r"typedef\s+struct\b[^;]*?\{", text):
            depth, i = 0, m.end() - 1
            while True:
                if text[i] == "{":
                    depth += 1
                elif text[i] == "}":
                    depth -= 1
                    if depth == 0:
                        break
                i += 1
            name = re.match(r"\s*(tase_\w+_t)\s*;", text[i + 1:])
            if name:
                types.append((os.path.basename(h), name.group(1)))
    probe = os.path.join(out, cpu, "sizeof_probe.c")
    with open(probe, "w") as f:
        for h in headers:
            f.write('#include "tase/%s"\n' % os.path.basename(h))
        for _, t in types:
            f.write("extern const unsigned char sizeof_%s[sizeof(%s)];\n" % (t, t))
            f.write("const unsigned char sizeof_%s[sizeof(%s)] = {0};\n" % (t, t))
        f.write("extern const unsigned char probe_frame_max[TASE_FRAME_MAX];\n")
        f.write("const unsigned char probe_frame_max[TASE_FRAME_MAX] = {0};\n")
    obj = probe[:-2] + ".o"
    run(["arm-none-eabi-gcc", "-std=c99", "-mcpu=" + cpu, "-mthumb", "-Os", "-I",
         os.path.join(ROOT, "include"), "-c", probe, "-o", obj])
    sizes = {}
    for line in run(["arm-none-eabi-nm", "-S", "--defined-only", obj]).splitlines():
        parts = line.split()
        if len(parts) == 4:
            sizes[parts[3]] = int(parts[1], 16)
    return [(h, t, sizes["sizeof_" + t]) for h, t in types], sizes["probe_frame_max"]


def stack_graph(bdir):
    """Nodes (title -> own frame bytes) and edges from the .ci files of the
    core and of the bare-metal port (whose calls into the core join it)."""
    own, edges, names = {}, {}, {}
    cis = glob.glob(os.path.join(bdir, "CMakeFiles", "tase.dir", "src", "*.ci"))
    cis += glob.glob(os.path.join(bdir, "port", "baremetal", "CMakeFiles", "tase_baremetal.dir",
                                  "*.ci"))
    for ci in cis:
        for line in open(ci):
            m = re.match(r'node: \{ title: "([^"]+)" label: "([^"\\]+)[^"]*?(\d+) bytes', line)
            if m:
                own[m.group(1)] = int(m.group(3))
                names[m.group(1)] = m.group(2)
                continue
            m = re.match(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"', line)
            if m:
                edges.setdefault(m.group(1), set()).add(m.group(2))
    return own, edges, names


def rx_handler_sites(bdir):
    """Functions of the receiver (tase_frame*.c, tase_rx*.c) that call
    through a function pointer: the call of the frame handler."""
    sites = set()
    for ci in glob.glob(os.path.join(bdir, "CMakeFiles", "tase.dir", "src", "*.ci")):
        base = os.path.basename(ci)
        if not (base.startswith("tase_frame") or base.startswith("tase_rx")):
            continue
        for line in open(ci):
            m = re.match(r'edge: \{ sourcename: "([^"]+)" targetname: "__indirect_call"', line)
            if m:
                sites.add(m.group(1))
    return sites


# Role entry points (issue 26): the frame handler a role gives its own
# receiver is followed from the receiver's call site; the application's
# callbacks and the port's functions are not (their stack is theirs).
ROLE_ROOTS = [
    ("tase_gimbal_feed", "gimbal_rx", 256),
    ("tase_gimbal_poll", None, 256),
    ("tase_gimbal_service", "gimbal_rx", None),
    ("tase_gimbal_handle_frame", None, None),
    ("tase_gimbal_send", None, None),
    ("tase_gimbal_send_msg", None, None),
    ("tase_host_feed", "host_rx", None),
    ("tase_host_service", "host_rx", None),
    ("tase_host_drain", "host_rx", None),
    ("tase_host_poll", None, None),
    ("tase_host_send_msg", None, None),
    ("tase_port_send_frame", None, None),
    ("tase_port_send_msg", None, 128),
]


def role_stack(root, handler, own, edges, names, sites):
    """worst_stack() of root with the receiver's handler call bound to the
    role's own handler (a static function, matched by name)."""
    if root not in own:
        return None
    if handler is None:
        return worst_stack(root, own, edges, names, {})
    h = [t for t in own if t.endswith(":" + handler) or t == handler]
    if not h:
        return None
    own2 = dict(own)
    own2["__rx_handler"] = 0
    names2 = dict(names)
    names2["__rx_handler"] = "(frame handler)"
    edges2 = {k: set(v) for k, v in edges.items()}
    for src in sites:
        if src in edges2 and "__indirect_call" in edges2[src]:
            edges2[src].discard("__indirect_call")
            edges2[src].add("__rx_handler")
    edges2["__rx_handler"] = {h[0]}
    return worst_stack(root, own2, edges2, names2, {})


def worst_stack(fn, own, edges, names, memo):
    """Deepest chain below fn (the core has no recursion, so a plain
    depth-first walk ends). Returns (bytes, chain, externals reached)."""
    if fn in memo:
        return memo[fn]
    if fn not in own:  # libc or the user's callback: not ours to measure
        memo[fn] = (0, [], {fn})
        return memo[fn]
    best, chain, ext = 0, [], set()
    for callee in sorted(edges.get(fn, ())):
        d, c, e = worst_stack(callee, own, edges, names, memo)
        ext |= e
        if d > best or not chain:
            best, chain = d, c
    memo[fn] = (own[fn] + best, [names.get(fn, fn)] + chain, ext)
    return memo[fn]


def to_callback(fn, own, edges, names, memo):
    """Deepest stack at a call through a function pointer below fn
    (fn's frame included), or (-1, []) when there is none."""
    if fn in memo:
        return memo[fn]
    if fn not in own:
        return (-1, [])
    best = (0, []) if "__indirect_call" in edges.get(fn, ()) else (-1, [])
    for callee in sorted(edges.get(fn, ())):
        d, c = to_callback(callee, own, edges, names, memo)
        if d >= 0 and d > best[0]:
            best = (d, c)
    memo[fn] = (own[fn] + best[0], [names.get(fn, fn)] + best[1]) if best[0] >= 0 else (-1, [])
    return memo[fn]


def met(value, target):
    return "met" if value <= target else "**missed** (+%d)" % (value - target)


def contributors(obj, n=4):
    """The n largest functions/constants of an object file (name, bytes)."""
    syms = []
    for line in run(["arm-none-eabi-nm", "-S", "--size-sort", "--defined-only", obj]).splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tTrRdD":
            syms.append((parts[3], int(parts[1], 16)))
    return sorted(syms, key=lambda x: -x[1])[:n]


def map_shares(path, app_dir, app_label):
    """Flash and RAM of each part of a linked image from its link map: the
    input sections kept, by archive member (libtase.a / libtase_baremetal.a
    objects), the application's own objects (app_dir is its CMake object
    directory) and the C library."""
    share = {}
    pending = None
    for line in open(path):
        if line.startswith("Linker script and memory map"):
            share.clear()
            pending = None
        m = re.match(r"^ (\.(?:text|rodata|data|bss)\S*)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (\.(?:text|rodata|data|bss)\S*)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+)$",
                     line)
        if m and (m.group(1) or pending):
            path = m.group(4)
            a = re.search(r"(libtase(?:_baremetal)?\.a)\((\w+)\.c\.obj\)", path)
            if a:  # module names drop the files' "tase_" prefix, as in build()
                key = "%s %s" % (a.group(1), a.group(2).replace("tase_", "", 1))
            elif app_dir in path:
                key = app_label
            else:
                key = "newlib, libgcc (printf, semihosting, memcpy, ...)"
            sec = m.group(1) or pending
            kind = "ram" if sec.startswith((".data", ".bss")) else "flash"
            share.setdefault(key, {"flash": 0, "ram": 0})[kind] += int(m.group(3), 16)
        pending = None
    return share


def build_image(out, example, cpu, elf):
    """Configure and build examples/<example> for cpu; the ELF's path."""
    bdir = os.path.join(out, example)
    run(["cmake", "-S", os.path.join(ROOT, "examples", example), "-B", bdir,
         "-DCMAKE_TOOLCHAIN_FILE=" + os.path.join(ROOT, "cmake", "arm-none-eabi.cmake"),
         "-DTASE_CPU=" + cpu])
    run(["cmake", "--build", bdir, "-j2"])
    return os.path.join(bdir, elf)


def stack_printed(output):
    """The stack high-water mark an example image prints, or None."""
    m = re.search(r"\+ (\d+) B stack used", output or "")
    return int(m.group(1)) if m else None


def firmware_image(out):
    """Build examples/firmware (Cortex-M3) and measure the ELF: totals from
    arm-none-eabi-size, the library's share per object from the link map,
    and (when QEMU is there) the stack high-water mark the image prints."""
    elf = build_image(out, "firmware", "cortex-m3", "tase_gimbal.elf")
    text, data, bss = berkeley(elf)
    share = map_shares(elf[:-len(".elf")] + ".map", "tase_gimbal.elf.dir",
                       "application (startup.c, main.c, gimbal.c)")
    stack = None
    try:
        o = subprocess.run(["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor",
                            "none", "-icount", "shift=5,sleep=off", "-semihosting-config",
                            "enable=on,target=native", "-kernel", elf],
                           capture_output=True, text=True, timeout=120).stdout
        stack = stack_printed(o)
    except (OSError, subprocess.TimeoutExpired):
        pass
    return {"text": text, "data": data, "bss": bss, "share": share, "stack": stack}


def autopilot_image(out, sim):
    """Build examples/autopilot (Cortex-M4F) and measure it like the gimbal
    image. Its stack high-water mark needs the mission flown against a live
    tase-sim (scripts/checks/autopilot.sh); sim is that binary, or None to
    build one in the host tree under `out`."""
    elf = build_image(out, "autopilot", "cortex-m4", "tase_autopilot.elf")
    text, data, bss = berkeley(elf)
    share = map_shares(elf[:-len(".elf")] + ".map", "tase_autopilot.elf.dir",
                       "application (startup.c, board.c, link.c, flight.c, main.c)")
    stack = bm_uart = None
    try:
        if sim is None:
            host = os.path.join(out, "host")
            run(["cmake", "-S", ROOT, "-B", host, "-DTASE_BUILD_TESTS=OFF", "-DTASE_CHECKS=OFF"])
            run(["cmake", "--build", host, "--target", "tase_sim", "-j2"])
            sim = os.path.join(host, "tools", "tase-sim")
        o = subprocess.run([os.path.join(ROOT, "scripts", "checks", "autopilot.sh"), sim,
                            os.path.dirname(elf)], capture_output=True, text=True,
                           timeout=300).stdout
        stack = stack_printed(o)
        m = re.search(r"tase_bm_uart_t (\d+)", o)
        bm_uart = int(m.group(1)) if m else None
    except (OSError, subprocess.SubprocessError):
        pass
    return {"text": text, "data": data, "bss": bss, "share": share, "stack": stack,
            "bm_uart": bm_uart}


def image_tables(p, img, stack_what):
    """The size table and the per-part table of an example image."""
    p("| | bytes |")
    p("|---|---:|")
    p("| flash (text + rodata + data) | %d |" % (img["text"] + img["data"]))
    p("| RAM, static (data + bss) | %d |" % (img["data"] + img["bss"]))
    if img["stack"] is not None:
        p("| stack high-water mark measured by the image under QEMU (%s) | %d |" % (
            stack_what, img["stack"]))
    p("")
    p("| part | flash | static RAM |")
    p("|---|---:|---:|")
    lib = [k for k in img["share"] if k.startswith("libtase.a")]
    port = [k for k in img["share"] if k.startswith("libtase_baremetal.a")]
    for k in sorted(lib) + sorted(port):
        p("| %s | %d | %d |" % (k, img["share"][k]["flash"], img["share"][k]["ram"]))
    p("| **library total (libtase.a)** | %d | %d |" % (
        sum(img["share"][k]["flash"] for k in lib), sum(img["share"][k]["ram"] for k in lib)))
    p("| **bare-metal port total (libtase_baremetal.a)** | %d | %d |" % (
        sum(img["share"][k]["flash"] for k in port),
        sum(img["share"][k]["ram"] for k in port)))
    for k in sorted(img["share"]):
        if k not in lib and k not in port:
            p("| %s | %d | %d |" % (k, img["share"][k]["flash"], img["share"][k]["ram"]))
    p("")


# The static functions of tase_bm_uart.c that tase_bm_uart_ops holds.
PORT_OPS = [("tase_bm_uart_ops.write", "bm_write"), ("tase_bm_uart_ops.read", "bm_read"),
            ("tase_bm_uart_ops.now_ms", "bm_now_ms")]


def stack_cells(stacks, fn):
    """The cells of a stack table row: fn's worst depth on every CPU ("-"
    where it is not linked), and on Cortex-M4 its deepest chain and what the
    walk did not count. fn is a global name, or ":name" for a static one,
    matched at the end of its object-qualified key."""
    def resolve(own):
        return next((k for k in own if k.endswith(fn)), None) if fn.startswith(":") else fn

    cols = []
    for c in CPUS:
        own, edges, names, memo = stacks[c]
        f = resolve(own)
        cols.append(str(worst_stack(f, own, edges, names, memo)[0]) if f in own else "-")
    own4, edges4, names4, memo4 = stacks["cortex-m4"]
    _, chain, ext = worst_stack(resolve(own4) or fn, own4, edges4, names4, memo4)
    ext = sorted(e.replace("__indirect_call", "callback") for e in ext)
    return cols, " > ".join(chain), ", ".join(ext) or "-"


def stack_table(p, stacks, rows):
    """A stack table: its head, then a row of stack_cells() per (label, fn),
    the label already in Markdown."""
    p("| function | " + " | ".join(CPUS) + " | deepest chain (Cortex-M4) | not counted |")
    p("|---|" + "---:|" * len(CPUS) + "---|---|")
    for label, fn in rows:
        cols, chain, ext = stack_cells(stacks, fn)
        p("| %s | %s | %s | %s |" % (label, " | ".join(cols), chain, ext))


def port_stack_table(p, stacks, objs):
    """The worst-case stack table of the bare-metal port's public functions
    (and of the port functions tase_bm_uart_ops holds), made as the core's:
    the deepest chain, into the core where a poll feeds its receiver."""
    if not objs:
        return
    p("### Bare-metal port (port/baremetal)")
    p("")
    p("The public functions of the bare-metal port (tase/ring.h, tase/bm_uart.h, tase/bm_dma.h; "
      "library `tase_baremetal`, built for each CPU beside the core), walked like the table "
      "above; the polls' chains go on into the receiver they feed. Not counted: the hooks "
      "(tx, millis, idle, irq_off, irq_on), the frame handler and libc. "
      "`tase_bm_uart_rx_isr` runs in the RX interrupt: its depth is added to whatever it "
      "interrupts (plus the exception frame, 32 B, or 104 B with floating-point context).")
    p("")
    own4 = stacks["cortex-m4"][0]
    rows = [(fn, fn) for fn in sorted({s for o in objs for s in globals_of(o)})]
    for label, static in PORT_OPS:
        t = [k for k in own4 if k.endswith(":" + static)]
        if t:
            rows.append((label, ":" + static))
    stack_table(p, stacks, [("`%s`" % label, fn) for label, fn in rows])
    p("")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "FOOTPRINT.md"))
    ap.add_argument("--build", default=os.path.join(ROOT, "build-footprint"))
    ap.add_argument("--sim", default=None,
                    help="tase-sim binary for the autopilot image's mission (default: build one)")
    args = ap.parse_args()
    os.makedirs(args.build, exist_ok=True)

    img = firmware_image(args.build)
    apimg = autopilot_image(args.build, args.sim)
    res = {}
    for cpu in CPUS:
        bdir, objs = build(cpu, args.build)
        mods = {m: berkeley(o) for m, o in objs.items()}
        frame_roots = [link_name(objs, r) for r in FRAMING_ROOTS]
        rx_roots = list(frame_roots)
        has_dispatch = "dispatch" in objs
        if has_dispatch:
            rx_roots += globals_of(objs["dispatch"])
        core = [o for m, o in objs.items() if m in CORE_MODULES]
        roots_all = [s for o in core for s in globals_of(o)]
        roots_core = [s for s in roots_all if not FLOAT_HELPER.match(s)]
        rest = [o for m, o in objs.items() if m not in CORE_MODULES and not optional(m)]
        roots_rest = [s for o in rest for s in globals_of(o)]
        res[cpu] = {
            "mods": mods,
            "rx": linked_size(cpu, objs.values(), rx_roots, args.build),
            "rx_frame": linked_size(cpu, objs.values(), frame_roots, args.build),
            "core": linked_size(cpu, core, roots_core, args.build),
            "core_float": linked_size(cpu, core, roots_all, args.build),
            "rest": linked_size(cpu, list(objs.values()), roots_rest, args.build)
            if roots_rest else (0, 0),
            "rest_names": sorted(m for m in objs if m not in CORE_MODULES and not optional(m)),
            "types": sizeof_types(cpu, args.build),
            "graph": stack_graph(bdir),
            "sites": rx_handler_sites(bdir),
            "objs": objs,
            "port_objs": port_objs(bdir),
            "dispatch": has_dispatch,
        }

    w = []
    p = w.append
    p("# Footprint on Cortex-M")
    p("")
    p("<!-- GENERATED by bench/footprint.sh from the sources; do not edit by hand. -->")
    p("Generated by `bench/footprint.sh` (arm-none-eabi-gcc %s, `-Os -ffunction-sections "
      "-fdata-sections -mthumb`, through `cmake/arm-none-eabi.cmake`). Regenerate it after "
      "changing anything in `src/` or `include/`." %
      run(["arm-none-eabi-gcc", "-dumpversion"]).strip())
    p("")
    p("Flash = code + read-only data + initialised data; RAM = initialised + zeroed data. "
      "The core has no globals, so its RAM is entirely in the instances the caller owns "
      "(see the sizeof table).")
    p("")
    p("## Per module (object file, everything compiled in)")
    p("")
    p("| module | " + " | ".join("%s flash | %s RAM" % (c, c) for c in CPUS) + " |")
    p("|---|" + "---:|---:|" * len(CPUS))
    mods = sorted(res[CPUS[0]]["mods"])
    for m in mods:
        row = []
        for c in CPUS:
            t, d, b = res[c]["mods"][m]
            row += [str(t + d), str(d + b)]
        p("| %s%s | %s |" % (m, " (optional strings)" if optional(m) else "", " | ".join(row)))
    row = []
    for c in CPUS:
        row += [str(sum(t + d for t, d, _ in res[c]["mods"].values())),
                str(sum(d + b for _, d, b in res[c]["mods"].values()))]
    p("| **total** | %s |" % " | ".join(row))
    p("")
    p("## Targets")
    p("")
    dispatch = res[CPUS[0]]["dispatch"]
    rxname = "framing + dispatch" if dispatch else "framing only (no src/tase_dispatch.c yet)"
    p("Linked sizes: only what the named entry points pull in after `--gc-sections`; libc's "
      "`memcpy`/`memmove`/`memchr`/`memset` are not counted (every firmware links them).")
    p("")
    p("| what | " + " | ".join(CPUS) + " | target | status (Cortex-M4) |")
    p("|---|" + "---:|" * len(CPUS) + "---:|---|")
    m4 = res["cortex-m4"]
    p("| receive path flash: %s | %s | 1024 | %s |" % (
        rxname, " | ".join(str(res[c]["rx"][0]) for c in CPUS), met(m4["rx"][0], TARGET_RX_FLASH)))
    p("| framing only: %s | %s | %d | %s |" % (
        ", ".join(FRAMING_ROOTS), " | ".join(str(res[c]["rx_frame"][0]) for c in CPUS),
        TARGET_FRAMING_FLASH, met(m4["rx_frame"][0], TARGET_FRAMING_FLASH)))
    p("| whole core flash (%s), optional name strings and floating-point unit helpers "
      "excluded | %s | 4096 | %s |" % (
        ", ".join(m for m in CORE_MODULES if m in m4["objs"]),
        " | ".join(str(res[c]["core"][0]) for c in CPUS), met(m4["core"][0], TARGET_CORE_FLASH)))
    p("| whole core flash with the KLV floating-point unit helpers (soft-float library "
      "routines not counted) | %s | - | informational |" % (
        " | ".join(str(res[c]["core_float"][0]) for c in CPUS)))
    if m4["rest_names"]:
        p("| other modules, linked on their own (%s) | %s | - | informational |" % (
            ", ".join(m4["rest_names"]), " | ".join(str(res[c]["rest"][0]) for c in CPUS)))
    types = {t: s for _, t, s in m4["types"][0]}
    rxsz = types.get("tase_rx_t", 0)
    p("| RAM per receiver: sizeof(tase_rx_t) | %s | 360 | %s |" % (
        " | ".join(str({t: s for _, t, s in res[c]["types"][0]}.get("tase_rx_t", 0)) for c in CPUS),
        met(rxsz, TARGET_RX_RAM)))
    stacks = {}
    for c in CPUS:
        own, edges, names = res[c]["graph"]
        memo = {}
        stacks[c] = (own, edges, names, memo)
    # Every receive entry point: a byte (push), a buffer (feed), end of
    # input (flush) and the clock (tick).
    rx_roots = ("tase_rx_push", "tase_rx_feed", "tase_rx_flush", "tase_rx_tick")

    def rx_stack(c, with_dispatch=False):
        """Deepest of the receiver's own chains (a trivial callback), or,
        with_dispatch, the chain down to its frame-callback call site plus
        the dispatcher's deepest chain."""
        own, edges, names, memo = stacks[c]
        best = max((worst_stack(r, own, edges, names, memo) for r in rx_roots if r in own),
                   key=lambda x: x[0])
        if not with_dispatch or not res[c]["dispatch"]:
            return best
        disp = max((worst_stack(s, own, edges, names, memo)
                    for s in globals_of(res[c]["objs"]["dispatch"])), key=lambda x: x[0])
        site = max((to_callback(r, own, edges, names, {}) for r in rx_roots if r in own),
                   key=lambda x: x[0])
        via = (site[0] + disp[0], site[1] + ["(callback)"] + disp[1], disp[2])
        return via if via[0] > best[0] else best
    p("| receive path stack (push/feed/flush/tick, worst chain, trivial callback) | %s | 128 | %s |" % (
        " | ".join(str(rx_stack(c)[0]) for c in CPUS), met(rx_stack("cortex-m4")[0], TARGET_RX_STACK)))
    if dispatch:
        p("| receive path stack, the dispatcher as the frame callback | %s | - | informational |" % (
            " | ".join(str(rx_stack(c, True)[0]) for c in CPUS)))
    p("")
    p("For comparison (as issue 8 states it): MAVLink's `mavlink_parse_char` alone links to about "
      "1.8 KB of code plus a 2.8 KB CRC table on Cortex-M4 `-Os`.")
    p("")
    frame_max = m4["types"][1]
    stats = types.get("tase_rx_stats_t", 0)
    mods4 = m4["mods"]
    fl = lambda m: mods4[m][0] + mods4[m][1] if m in mods4 else 0
    top = {m: contributors(o) for m, o in m4["objs"].items()}
    biggest = lambda m, k=2: ", ".join("`%s` %d" % x for x in top.get(m, [])[:k])
    p("### Gaps and their reasons (Cortex-M4)")
    p("")
    rx_gap = m4["rx"][0] - TARGET_RX_FLASH
    p("- **Receive path flash, %d B against 1024 (%s).** Framing alone (%s) links to %d B "
      "(%s against its own target of %d B): the greedy receiver's resumable scan over a "
      "window (a budget per byte, running sums, compaction), the bulk paths of "
      "tase_rx_feed() and the byte paths of tase_rx_push() (largest symbols: %s). "
      "Dispatch adds %d B: the generic decoder of the "
      "codec (largest symbols of tase_codec.c: %s) and the schema's ROM tables and lookup "
      "(tase_schema.c: %s), which describe every packet of the spec once." % (
          m4["rx"][0], "met" if rx_gap <= 0 else "+%d" % rx_gap, ", ".join(FRAMING_ROOTS),
          m4["rx_frame"][0], met(m4["rx_frame"][0], TARGET_FRAMING_FLASH), TARGET_FRAMING_FLASH,
          biggest("frame", 3), m4["rx"][0] - m4["rx_frame"][0], biggest("codec"),
          biggest("schema")))
    core_gap = m4["core"][0] - TARGET_CORE_FLASH
    p("- **Whole core flash, %d B against 4096 (%s).** By module (object file, everything "
      "compiled in): %s. Framing (frame, frame_time) is the receiver above plus its time bound and the encoder; KLV (the spec's KLV "
      "metadata encoder, decoder and stream receiver; not MISB ST 0601, PROTOCOL-NOTES.md) is the other large one; the schema is the ROM description of all 21 packets and their fields that the "
      "codec, dispatcher and tools share." % (
          m4["core"][0], "met" if core_gap <= 0 else "+%d" % core_gap,
          ", ".join("%s %d" % (m, fl(m)) for m in sorted(CORE_MODULES, key=lambda x: -fl(x))
                    if m in mods4)))
    p("- **RAM per receiver, %d B against 360 (%s).** A maximal frame is %d bytes; the "
      "window holds one and the bytes that arrive while a lagging scan catches up "
      "(TASE_RX_WINDOW, docs/DESIGN.md), beside %d bytes of counters (%d of them) and the "
      "scan's state (%d bytes with padding, the time bound's included). "
      "include/tase/frame.h sets the budget at 360 (TASE_RX_SIZE_BUDGET)." % (
          rxsz, "met" if rxsz <= TARGET_RX_RAM else "+%d" % (rxsz - TARGET_RX_RAM), frame_max,
          stats, stats // 4, rxsz - 300 - stats))
    st4 = rx_stack("cortex-m4")[0]
    own4 = stacks["cortex-m4"][0]
    frame_of = lambda fn: next((v for k, v in own4.items() if k.endswith(":" + fn) or k == fn), 0)
    p("- **Receive path stack, %d B against 128 (%s)**, plus the application's handler: the "
      "deepest of tase_rx_push(), tase_rx_feed(), tase_rx_flush() and tase_rx_tick() down to "
      "the frame callback (run() %d B, scan() %d B). bench/bench.sh also measures the "
      "push path by painting (docs/PERFORMANCE.md)." % (
          st4, met(st4, TARGET_RX_STACK), frame_of("run"), frame_of("scan")))
    p("")
    p("### Biggest contributors per module (Cortex-M4, `arm-none-eabi-nm --size-sort`)")
    p("")
    p("| module | flash | largest symbols (bytes) |")
    p("|---|---:|---|")
    for m in sorted(mods4, key=lambda x: -fl(x)):
        p("| %s | %d | %s |" % (m, fl(m), biggest(m, 4)))
    p("")
    if img is not None:
        p("## The example firmware image (Cortex-M3, QEMU mps2-an385)")
        p("")
        p("`examples/firmware` linked with `--gc-sections` (`arm-none-eabi-size` of "
          "`tase_gimbal.elf`; the share of each object from the link map). It uses the receiver, "
          "the dispatcher with typed decode, the typed encoder, the gimbal role and the "
          "bare-metal port (circular-DMA receive, UART transmit); everything else is "
          "semihosting and newlib's printf, "
          "which a real firmware would not carry.")
        p("")
        image_tables(p, img, "main loop + SysTick interrupt, before printf")
        p("The library has no static data: its RAM is the instances the application owns "
          "(two tase_rx_t of %d B, the host-side one only for the self-check; a "
          "tase_gimbal_t of %d B, initialised without receivers because this image feeds "
          "its own receiver through the dispatcher and hands setup frames to the role; a "
          "tase_dispatch_t of %d B)." % (rxsz, types.get("tase_gimbal_t", 0),
                                         types.get("tase_dispatch_t", 0)))
        p("")
    if apimg is not None:
        p("## The example autopilot image (Cortex-M4F, QEMU mps2-an386)")
        p("")
        p("`examples/autopilot` linked with `--gc-sections` (`arm-none-eabi-size` of "
          "`tase_autopilot.elf`; the share of each object from the link map), the host side: "
          "it uses the host role (requests with retries, its receiver), the dispatcher with "
          "typed decode, the typed encoder and the bare-metal ring/UART port. Everything else "
          "is the application (board, flight model, mission), the flight model's "
          "single-precision maths (newlib's libm), double-precision unit conversions in "
          "software, semihosting and newlib's printf with floating point; a real autopilot "
          "carries most of that anyway and would not carry printf.")
        p("")
        image_tables(p, apimg, "main loop + UART0 and SysTick interrupts over the whole "
                     "mission against tase-sim, before printf")
        p("The library has no static data: its RAM is the instances the application owns "
          "(a tase_host_t of %d B holding its tase_rx_t of %d B and a copy of the pending "
          "request for re-sending, a tase_dispatch_t of %d B, and the bare-metal port's "
          "tase_bm_uart_t%s with its 512-byte ring, sized for about 45 ms of 115200 baud)." % (
              types.get("tase_host_t", 0), rxsz, types.get("tase_dispatch_t", 0),
              " of %d B" % apimg["bm_uart"] if apimg["bm_uart"] is not None else ""))
        p("")
        p("The stack high-water mark depends on where the interrupts happen to land in the "
          "deepest call chain (an exception frame with floating-point context is 104 B), so it "
          "varies by up to about 150 B from run to run; `scripts/checks/autopilot.sh` prints it "
          "with every run.")
        p("")
    p("## sizeof of the public types")
    p("")
    p("| header | type | " + " | ".join(CPUS) + " |")
    p("|---|---|" + "---:|" * len(CPUS))
    per = [{t: s for _, t, s in res[c]["types"][0]} for c in CPUS]
    for h, t, _ in res[CPUS[0]]["types"][0]:
        p("| %s | `%s` | %s |" % (h, t, " | ".join(str(x[t]) for x in per)))
    p("")
    p("## Worst-case stack depth")
    p("")
    p("From `-fstack-usage` frames summed along the deepest call chain of `-fcallgraph-info` "
      "(the core has no recursion and no VLAs, so every frame is static and the walk is "
      "exact). Calls into libc and through function pointers (your frame handler) are not "
      "included: add your handler's depth to the receive path.")
    p("")
    publics = sorted({s for o in m4["objs"].values() for s in globals_of(o)})
    stack_table(p, stacks, [("`%s`%s" % (fn, " (encoder)" if "encode" in fn or
                                          fn == "tase_frame_build" else ""), fn)
                            for fn in publics])
    p("")
    d, chain, ext = rx_stack("cortex-m4")
    p("Receive path on Cortex-M4: %d bytes, %s." % (d, " > ".join(chain)))
    p("")
    p("### Role entry points")
    p("")
    p("The deepest stack of each entry point of the roles and the send calls, with the frame "
      "handler a role gives its own receiver followed from the receiver's call site (so "
      "`tase_gimbal_feed` includes handling a setup packet). Not counted: the application's "
      "callbacks (on_frame, apply_setup, fill_telemetry, the dispatcher's handlers), the port's "
      "functions, and libc.")
    p("")
    p("| entry point | " + " | ".join(CPUS) + " | target | status (Cortex-M4) | deepest chain (Cortex-M4) |")
    p("|---|" + "---:|" * len(CPUS) + "---:|---|---|")
    for root, handler, target in ROLE_ROOTS:
        got = {}
        for c in CPUS:
            own, edges, names, _ = stacks[c]
            got[c] = role_stack(root, handler, own, edges, names, res[c]["sites"])
        if got["cortex-m4"] is None:
            continue
        p("| `%s` | %s | %s | %s | %s |" % (
            root, " | ".join(str(got[c][0]) if got[c] else "-" for c in CPUS),
            target if target else "-",
            met(got["cortex-m4"][0], target) if target else "informational",
            " > ".join(got["cortex-m4"][1])))
    p("")
    port_stack_table(p, stacks, m4["port_objs"])
    with open(args.out, "w") as f:
        f.write("\n".join(w))
    print("wrote %s" % args.out)
    print("\n".join(l for l in w if l.startswith("| receive") or l.startswith("| whole")
                    or l.startswith("| RAM")))


if __name__ == "__main__":
    sys.exit(main())
