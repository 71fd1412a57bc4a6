#!/usr/bin/python3
"""Figures of a `hilldem triaxial` run (one case or the study), like the memo's Figs. 18 and 20-22.

    scripts/plot_triaxial.py OUTPUT_DIR      (Debian's /usr/bin/python3, which python3-matplotlib serves)

Reads OUTPUT_DIR/summary.csv and, per case, OUTPUT_DIR/<case>/history.csv and gsd.csv; writes PNG files
into OUTPUT_DIR:
  fig18_grading.png        % passing by volume: target and realised, per grading (memo Fig. 18)
  fig20_stress_strain.png  deviator stress and volumetric strain vs axial strain, dry cases (Fig. 20)
  fig21_cycles.png         the load-unload cycles, one panel per dry case (Fig. 21)
                           (a run with no dry case plots its wet case in these two)
  fig22_wet_dry.png        C5b hill, wet vs dry: whole test and cycles (Fig. 22), when both were run
Needs matplotlib (Debian: python3-matplotlib; scripts/setup.sh installs it).
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

STYLE = {  # (colour, line style) per case
    "C5n_Linear": ("tab:blue", "--"),
    "C5n_Hill": ("tab:blue", "-"),
    "C5b_Linear": ("tab:red", "--"),
    "C5b_Hill": ("tab:red", "-"),
    "C5b_Hill_wet": ("tab:green", "-"),
}


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def read_history(path):
    rows = read_rows(path)
    h = {k: [] for k in ("eps_a", "eps_v", "q", "phase")}
    for r in rows:
        h["eps_a"].append(100.0 * float(r["eps_a[-]"]))
        h["eps_v"].append(100.0 * float(r["eps_v[-]"]))
        h["q"].append(float(r["q[Pa]"]) / 1e3)
        h["phase"].append(r["phase"])
    return h


def read_gsd(path):
    """The passing curve (first block of gsd.csv)."""
    size, target, realised = [], [], []
    with open(path) as f:
        next(f)
        for line in f:
            if not line.strip():
                break
            s, t, r = line.strip().split(",")
            size.append(float(s))
            target.append(float(t))
            realised.append(float(r))
    return size, target, realised


def style(name):
    return STYLE.get(name, (None, "-"))


def cycles_end(h):
    """Index of the last history row before the final monotonic loading."""
    for i, p in enumerate(h["phase"]):
        if p == "final":
            return i
    return len(h["phase"])


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    out = sys.argv[1]
    summary = read_rows(os.path.join(out, "summary.csv"))
    cases = [r["case"] for r in summary]
    hist = {c: read_history(os.path.join(out, c, "history.csv")) for c in cases}
    written = []

    # Fig. 18: grading curves, one per grading.
    fig, ax = plt.subplots(figsize=(6, 4.2))
    seen = set()
    lo, hi = 1e9, 0.0
    for r in summary:
        g = r["grading"]
        if g in seen:
            continue
        seen.add(g)
        size, target, realised = read_gsd(os.path.join(out, r["case"], "gsd.csv"))
        lo, hi = min(lo, min(size) * 0.9), max(hi, max(size) * 1.1)
        colour = "tab:red" if g == "C5b" else ("tab:blue" if g == "C5n" else None)
        ax.plot(size, target, color=colour, lw=2.5, alpha=0.35, label=f"{g} target")
        ax.plot(size, realised, color=colour, lw=1.2, label=f"{g} realised ({r['grains']} grains)")
    ax.set_xscale("log")
    ticks = [t for t in (2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100) if lo <= t <= hi] if seen else []
    ax.xaxis.set_major_locator(matplotlib.ticker.FixedLocator(ticks))
    ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("grain diameter [mm]")
    ax.set_ylabel("passing by volume [%]")
    ax.set_ylim(0, 100)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Grain-size distributions (cf. memo Fig. 18)")
    fig.tight_layout()
    written.append(os.path.join(out, "fig18_grading.png"))
    fig.savefig(written[-1], dpi=130)
    plt.close(fig)

    dry = [c for c in cases if not c.endswith("_wet")] or cases  # the dry cases (all, if a run has no dry case)
    # Fig. 20: whole test, dry cases.
    if dry:
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.5, 7), sharex=True)
        for c in dry:
            col, ls = style(c)
            a1.plot(hist[c]["eps_a"], hist[c]["q"], color=col, ls=ls, lw=1.2, label=c)
            a2.plot(hist[c]["eps_a"], hist[c]["eps_v"], color=col, ls=ls, lw=1.2, label=c)
        a1.set_ylabel("deviator stress q [kPa]")
        a2.set_ylabel("volumetric strain [%] (compression > 0)")
        a2.set_xlabel("axial strain [%]")
        for a in (a1, a2):
            a.grid(True, alpha=0.3)
        a1.legend(fontsize=8)
        a1.set_title("Triaxial tests at 150 kPa confinement (cf. memo Fig. 20)")
        fig.tight_layout()
        written.append(os.path.join(out, "fig20_stress_strain.png"))
        fig.savefig(written[-1], dpi=130)
        plt.close(fig)

        # Fig. 21: the cycles, one panel per dry case, common axes.
        n = len(dry)
        cols = 2 if n > 1 else 1
        rows = (n + cols - 1) // cols
        fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 3.8 * rows), squeeze=False, sharex=True, sharey=True)
        for k, c in enumerate(dry):
            a = axes[k // cols][k % cols]
            end = cycles_end(hist[c])
            col, ls = style(c)
            a.plot(hist[c]["eps_a"][:end + 1], hist[c]["q"][:end + 1], color=col, ls="-", lw=1.0, marker=".", ms=2)
            a.set_title(c, fontsize=10)
            a.grid(True, alpha=0.3)
        for k in range(n, rows * cols):
            axes[k // cols][k % cols].axis("off")
        for a in axes[-1]:
            a.set_xlabel("axial strain [%]")
        for r_ in axes:
            r_[0].set_ylabel("q [kPa]")
        fig.suptitle("Load-unload cycles (cf. memo Fig. 21)", fontsize=11)
        fig.tight_layout()
        written.append(os.path.join(out, "fig21_cycles.png"))
        fig.savefig(written[-1], dpi=130)
        plt.close(fig)

    # Fig. 22: wet vs dry C5b hill.
    if "C5b_Hill_wet" in hist and "C5b_Hill" in hist:
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
        for c in ("C5b_Hill", "C5b_Hill_wet"):
            col, ls = style(c)
            label = "wet (20 kPa, 3 mm)" if c.endswith("_wet") else "dry"
            a1.plot(hist[c]["eps_a"], hist[c]["q"], color=col, lw=1.2, label=label)
            end = cycles_end(hist[c])
            a2.plot(hist[c]["eps_a"][:end + 1], hist[c]["q"][:end + 1], color=col, lw=1.0, label=label)
        a1.set_title("C5b hill: whole test")
        a2.set_title("C5b hill: cycles")
        for a in (a1, a2):
            a.set_xlabel("axial strain [%]")
            a.set_ylabel("q [kPa]")
            a.grid(True, alpha=0.3)
            a.legend(fontsize=8)
        fig.suptitle("Wet vs dry (cf. memo Fig. 22)", fontsize=11)
        fig.tight_layout()
        written.append(os.path.join(out, "fig22_wet_dry.png"))
        fig.savefig(written[-1], dpi=130)
        plt.close(fig)

    for w in written:
        print("figure:", w)
    return 0


if __name__ == "__main__":
    sys.exit(main())
