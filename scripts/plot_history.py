#!/usr/bin/python3
"""Plots of hilldem history files (history.csv: columns step,time[s],<name>[<unit>]...) with matplotlib.

Every axis carries its unit, taken from the column header (a column without a unit is refused).
Output is PNG or SVG, from the file name's extension.

  plot_history.py force-displacement HISTORY.csv [--steps A:B] -o OUT
      Memo Figs. 10-11: normal force against overlap and shear force against shear displacement of a
      two-grain example (columns overlap, normal_force, shear_disp, shear_force).
  plot_history.py stiffness HILL.csv LINEAR.csv [--steps A:B] -o OUT
      Memo Fig. 12: the normal force of the hill and linear runs against overlap, log-log (slopes
      1.5 and 1).
  plot_history.py moisture HISTORY.csv [--suction PA --r-o M] -o OUT
      Memo Fig. 6: moisture force against gap in the moisture test (columns gap, moisture_force);
      with --suction and --r-o, Eq. 12 (as reconstructed: -psi pi R_o^2 exp(-g / 2 s_cr), rupture at
      2 s_cr, s_cr = R_o) is drawn for comparison.
  plot_history.py xy HISTORY.csv --x COL --y COL [--x-scale S --x-unit U --x-label L] [same for y]
                  [--x-offset first] [--steps A:B] [--title T] -o OUT
      Any two columns, e.g. stress against strain (memo Figs. 20-22): --x-offset first subtracts the
      first value (a displacement from a position), --x-scale converts (e.g. 1e3 with --x-unit mm, or
      -1/H0 with --x-unit - and --x-label "axial strain").

Exit status 2 with a message for bad input (missing file or column, no unit, nothing to plot).
"""
import argparse
import csv
import math
import re
import sys


def pyplot():
    """matplotlib, imported when the first figure is made (bad input fails fast without it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.rcParams.update({"svg.fonttype": "none", "figure.dpi": 110, "axes.grid": True, "grid.alpha": 0.3})
    return plt


def fail(message):
    print(f"plot_history: error: {message}", file=sys.stderr)
    sys.exit(2)


class History:
    """Columns of a history CSV by name, with their units."""

    def __init__(self, path):
        try:
            with open(path, newline="") as f:
                rows = list(csv.reader(f))
        except OSError as e:
            fail(f"{path}: {e.strerror}")
        if not rows:
            fail(f"{path}: empty file")
        self.path = path
        self.units, self.columns = {}, {}
        names = []
        for head in rows[0]:
            m = re.fullmatch(r"(.+)\[(.*)\]|(.+)", head)
            name = m.group(1) or m.group(3)
            self.units[name] = m.group(2)
            names.append(name)
        for name in names:
            self.columns[name] = []
        for line, row in enumerate(rows[1:], start=2):
            if len(row) != len(names):
                fail(f"{path}: line {line} has {len(row)} fields, the header has {len(names)}")
            for name, value in zip(names, row):
                try:
                    self.columns[name].append(float(value) if value != "" else math.nan)
                except ValueError:
                    fail(f"{path}: line {line}: '{value}' in column '{name}' is not a number")

    def column(self, name):
        if name not in self.columns:
            fail(f"{self.path}: no column '{name}'; columns: {', '.join(self.columns)}")
        if not self.units[name]:
            fail(f"{self.path}: column '{name}' has no unit in its header; cannot label the axis")
        return self.columns[name]

    def unit(self, name):
        self.column(name)
        return self.units[name]


def step_range(text):
    if not text:
        return None
    m = re.fullmatch(r"(\d*):(\d*)", text)
    if not m:
        fail(f"--steps must be A:B (either may be empty); got '{text}'")
    return (int(m.group(1)) if m.group(1) else -math.inf, int(m.group(2)) if m.group(2) else math.inf)


def pairs(h, x, y, steps=None, x_scale=1.0, y_scale=1.0, x_offset=None):
    """(x, y) points where both are finite, within the step range."""
    xs, ys, st = h.column(x), h.column(y), h.columns["step"]
    out = [(a, b) for s, a, b in zip(st, xs, ys)
           if math.isfinite(a) and math.isfinite(b) and (steps is None or steps[0] <= s <= steps[1])]
    if not out:
        fail(f"{h.path}: no rows with both '{x}' and '{y}' in range")
    x0 = out[0][0] if x_offset == "first" else 0.0
    return [(a - x0) * x_scale for a, _ in out], [b * y_scale for _, b in out]


def label(name, unit):
    return f"{name} [{unit}]"


def save(fig, path):
    if not path.lower().endswith((".png", ".svg")):
        fail(f"-o {path}: the output must end in .png or .svg")
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


def force_displacement(args):
    h = History(args.history)
    steps = step_range(args.steps)
    fig, (a, b) = pyplot().subplots(1, 2, figsize=(10, 4.2))
    x, y = pairs(h, "overlap", "normal_force", steps, x_scale=1e3)
    a.plot(x, y, ".-", markersize=3, color="C0")
    a.set_xlabel(label("overlap δ_o", "mm"))
    a.set_ylabel(label("normal force F_n", h.unit("normal_force")))
    a.set_title("Stage A: top grain pressed down")
    x, y = pairs(h, "shear_disp", "shear_force", steps, x_scale=1e6)
    b.plot(x, y, ".-", markersize=3, color="C3")
    b.set_xlabel(label("shear displacement δ_s", "µm"))
    b.set_ylabel(label("shear force |F_s|", h.unit("shear_force")))
    b.set_title("Stage B: top grain rotated (trial shear force)")
    fig.suptitle(args.title or "Two granite grains: force against displacement (memo Figs. 10-11)")
    save(fig, args.output)


def stiffness(args):
    """Normal force against overlap of the hill and linear runs on log-log axes (memo Fig. 12), each
    extended (dashed) with the stiffness its own run shows, up to where the two forces are equal."""
    steps = step_range(args.steps)
    fig, ax = pyplot().subplots(figsize=(6.8, 4.8))
    fits = {}
    for path, name, power, color in ((args.hill, "hill", 1.5, "C0"), (args.linear, "linear", 1.0, "C3")):
        h = History(path)
        x, y = pairs(h, "overlap", "normal_force", steps)
        pts = [(a, b) for a, b in zip(x, y) if a > 0 and b > 0]
        if not pts:
            fail(f"{path}: no rows with positive overlap and normal force")
        k = pts[-1][1] / pts[-1][0] ** power  # k_n from the last sample: F = k δ^power
        fits[name] = k
        ax.loglog([p[0] * 1e3 for p in pts], [p[1] for p in pts], ".-", markersize=3, color=color,
                  label=f"{name} model (engine), F ∝ δ^{power:g}")
    cross = (fits["linear"] / fits["hill"]) ** 2  # k_l δ = k_h δ^1.5
    xs = [1e-4 * (cross / 1e-4) ** (k / 100) for k in range(0, 121)]
    ax.loglog([x * 1e3 for x in xs], [fits["hill"] * x ** 1.5 for x in xs], "--", color="C0", linewidth=1)
    ax.loglog([x * 1e3 for x in xs], [fits["linear"] * x for x in xs], "--", color="C3", linewidth=1,
              label="extended with the same k_n")
    ax.axvline(cross * 1e3, color="0.4", linestyle=":", label=f"equal forces at δ_o = {cross * 1e3:.2f} mm")
    ax.set_xlabel(label("overlap δ_o", "mm"))
    ax.set_ylabel(label("normal force F_n", History(args.hill).unit("normal_force")))
    ax.set_title(args.title or "Linear against hill stiffness (memo Fig. 12)")
    ax.legend(fontsize=8)
    save(fig, args.output)


def moisture(args):
    h = History(args.history)
    steps = step_range(args.steps)
    x, y = pairs(h, "gap", "moisture_force", steps, x_scale=1e3)
    fig, ax = pyplot().subplots(figsize=(6.4, 4.4))
    ax.plot(x, [-v for v in y], ".", markersize=3, color="C0", label="engine (history samples)")
    if args.suction is not None and args.r_o is not None:
        s_cr = args.r_o
        fmax = args.suction * math.pi * args.r_o ** 2
        gs = [2 * s_cr * k / 400 for k in range(401)]
        ax.plot([g * 1e3 for g in gs], [fmax * math.exp(-g / (2 * s_cr)) for g in gs], "-", color="C1",
                label="Eq. 12 (reconstructed)")
        ax.axvline(2 * s_cr * 1e3, color="0.4", linestyle=":", label="rupture gap 2 s_cr")
    ax.set_xlabel(label("gap g_c", "mm"))
    ax.set_ylabel(label("moisture force |F^m|", h.unit("moisture_force")))
    ax.set_title(args.title or "Moisture test: liquid-bridge force against gap (memo Fig. 6)")
    ax.legend()
    save(fig, args.output)


def xy(args):
    h = History(args.history)
    if (args.x_scale != 1.0 and not args.x_unit) or (args.y_scale != 1.0 and not args.y_unit):
        fail("a scaled axis needs its new unit: give --x-unit / --y-unit with --x-scale / --y-scale")
    x, y = pairs(h, args.x, args.y, step_range(args.steps), args.x_scale, args.y_scale, args.x_offset)
    fig, ax = pyplot().subplots(figsize=(6.4, 4.4))
    ax.plot(x, y, ".-", markersize=3)
    ax.set_xlabel(label(args.x_label or args.x, args.x_unit or h.unit(args.x)))
    ax.set_ylabel(label(args.y_label or args.y, args.y_unit or h.unit(args.y)))
    if args.title:
        ax.set_title(args.title)
    save(fig, args.output)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="kind", required=True)
    fd = sub.add_parser("force-displacement", help="memo Figs. 10-11")
    fd.add_argument("history")
    st = sub.add_parser("stiffness", help="memo Fig. 12")
    st.add_argument("hill", help="history of the hill-model two-grain run")
    st.add_argument("linear", help="history of the linear-model two-grain run")
    mo = sub.add_parser("moisture", help="memo Fig. 6")
    mo.add_argument("history")
    mo.add_argument("--suction", type=float, help="psi [Pa], to draw Eq. 12")
    mo.add_argument("--r-o", type=float, help="R_o = min(R1, R2) [m], to draw Eq. 12")
    g = sub.add_parser("xy", help="any two columns (stress-strain, memo Figs. 20-22)")
    g.add_argument("history")
    for axis in ("x", "y"):
        g.add_argument(f"--{axis}", required=True, help=f"column for the {axis} axis")
        g.add_argument(f"--{axis}-scale", type=float, default=1.0)
        g.add_argument(f"--{axis}-unit", help="unit after scaling")
        g.add_argument(f"--{axis}-label", help="axis name (default: the column)")
    g.add_argument("--x-offset", choices=["first"], help="subtract the first x value")
    for s in (fd, st, mo, g):
        s.add_argument("-o", "--output", required=True, help="output file (.png or .svg)")
        s.add_argument("--steps", help="only steps A:B")
        s.add_argument("--title")
    args = p.parse_args()
    {"force-displacement": force_displacement, "stiffness": stiffness, "moisture": moisture, "xy": xy}[args.kind](args)


if __name__ == "__main__":
    main()
