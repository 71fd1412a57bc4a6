#!/usr/bin/env python3
"""The plotting script (scripts/plot_history.py, matplotlib) makes every figure from fresh histories,
with a unit on every axis, and refuses bad input with exit status 2.

    check_plots.py HILLDEM SOURCE_DIR WORK_DIR
"""
import re
import subprocess
import sys
from pathlib import Path

hilldem, source, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
plot = ["/usr/bin/python3", str(source / "scripts/plot_history.py")]
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def history(example):
    out = work / example
    subprocess.run([hilldem, "run", "-q", str(source / "examples" / f"{example}.toml"), "-o", str(out), "--no-checkpoints"],
                   check=True, stdout=subprocess.DEVNULL)
    return str(out / "history.csv")


def make(args, name, labels, png=False):
    """Plot to SVG (text kept as text) and, with png, PNG; the SVG must show each axis label, unit included."""
    for ext in ("svg", "png") if png else ("svg",):
        target = work / f"{name}.{ext}"
        r = subprocess.run(plot + args + ["-o", str(target)], capture_output=True, text=True)
        check(r.returncode == 0, f"{name}.{ext}: exit {r.returncode}: {r.stderr.strip()}")
        check(target.is_file() and target.stat().st_size > 5000, f"{name}.{ext} is missing or tiny")
    if png:
        check((work / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{name}.png is not a PNG")
    svg = (work / f"{name}.svg").read_text()
    texts = [re.sub(r"\s+", " ", t) for t in re.findall(r"<text[^>]*>(.*?)</text>", svg, re.S)]
    for want in labels:
        check(any(want in t for t in texts), f"{name}: no axis label '{want}' in {texts[:12]}")
    # Every axis label ends with a unit in brackets.
    units = [t for t in texts if re.search(r"\[[^\]]+\]$", t.strip())]
    check(len(units) >= 2, f"{name}: fewer than two axis labels with units: {texts}")


hill, linear, moist = history("two_grains_hill"), history("two_grains_linear"), history("moisture_test")
make(["force-displacement", hill, "--steps", "0:300"], "fd_hill",
     ["overlap δ_o [mm]", "normal force F_n [N]", "shear displacement δ_s [µm]", "shear force |F_s| [N]"], png=True)
make(["stiffness", hill, linear, "--steps", "0:100"], "stiffness", ["overlap δ_o [mm]", "normal force F_n [N]", "28.29 mm"])
make(["moisture", moist, "--suction", "200e3", "--r-o", "5e-3", "--steps", "1:"], "moisture",
     ["gap g_c [mm]", "moisture force |F^m| [N]"])
make(["xy", moist, "--x", "top_z", "--x-scale", "1e3", "--x-unit", "mm", "--y", "normal_force"], "xy",
     ["top_z [mm]", "normal_force [N]"])

# Bad input: exit status 2 and a message.
nounit = work / "nounit.csv"
nounit.write_text("step,time[s],force\n0,0,1\n1,1,2\n")
for args, message in ((["xy", str(nounit), "--x", "time", "--y", "force"], "has no unit"),
                      (["xy", moist, "--x", "time", "--y", "nope"], "no column 'nope'"),
                      (["moisture", str(work / "missing.csv")], "No such file"),
                      (["xy", moist, "--x", "time", "--y", "gap", "--y-scale", "1e3"], "needs its new unit")):
    r = subprocess.run(plot + args + ["-o", str(work / "bad.png")], capture_output=True, text=True)
    check(r.returncode == 2 and message in r.stderr, f"{args}: exit {r.returncode}, stderr {r.stderr.strip()!r}")

if failures:
    sys.exit(1)
print("ok: every figure written with units on its axes; bad input refused")
