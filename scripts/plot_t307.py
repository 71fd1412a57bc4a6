#!/usr/bin/python3
"""Figure of `hilldem t307` runs: M_r against the bulk stress theta, with the universal-model fit.

    scripts/plot_t307.py OUTPUT_DIR [OUTPUT_DIR ...] [--out FILE]
    scripts/plot_t307.py --against-pulse OUTPUT_DIR [OUTPUT_DIR ...] [--out FILE]
                                   (Debian's /usr/bin/python3, which python3-matplotlib serves)

--against-pulse: the time-scaling study. The runs (the same specimen, the pulse duration changed)
are grouped by their case (C5b_Hill, C5b_Hill_wet: the first line of t307_summary.txt), one panel
each: M_r [MPa] of every sequence against the pulse duration [ms] (log scale), one line per sequence
coloured by sigma3. Prints the same numbers as a table (one line per case and sequence) and writes
t307_time_scaling.png into the first OUTPUT_DIR (or FILE).

Reads each OUTPUT_DIR/t307_sequences.csv (and t307_fit.csv when the fit was made); writes
t307_mr_theta.png into the first OUTPUT_DIR (or FILE): M_r [MPa] against theta [kPa], one marker
per sequence, coloured by the confining pressure sigma3; the fitted model as a line through each
sigma3 group (theta = 3 sigma3 + sigma_d, tau_oct = sqrt(2)/3 sigma_d, sigma_d from half the
group's smallest sigma_max to its largest). Several folders (e.g. dry and wet) share the axes, one marker shape each.
Needs matplotlib (Debian: python3-matplotlib).
"""
import csv
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

P_A = 101.325e3  # Pa
MARKERS = ["o", "s", "^", "D"]
LINES = ["-", "--", ":", "-."]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run_timing(d):
    """(case, pulse [s], cycles) of a run, from its t307_summary.txt."""
    with open(os.path.join(d, "t307_summary.txt")) as f:
        first, second = f.readline(), f.readline()
    case = re.match(r"hilldem t307: (\S+)", first)
    pulse = re.search(r"pulse ([0-9.eE+-]+) s", second)
    cycles = re.search(r"(\d+) cycles per sequence", second)
    if not (case and pulse and cycles):
        sys.exit(f"{d}/t307_summary.txt: no case, pulse or cycles in its first two lines")
    return case.group(1), float(pulse.group(1)), int(cycles.group(1))


def against_pulse(dirs, out):
    runs = {}  # case -> [(pulse, cycles, {seq: (sigma3, M_r)})]
    for d in dirs:
        case, pulse, cycles = run_timing(d)
        rows = read_rows(os.path.join(d, "t307_sequences.csv"))
        runs.setdefault(case, []).append(
            (pulse, cycles, {int(r["seq"]): (float(r["sigma3[Pa]"]), float(r["M_r[Pa]"])) for r in rows}))
    cases = sorted(runs)
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.4), squeeze=False, sharey=True)
    cmap = plt.get_cmap("viridis")
    s3_all = sorted({round(v[0]) for c in cases for _, _, m in runs[c] for v in m.values()})
    colour = {s3: cmap(k / max(1, len(s3_all) - 1)) for k, s3 in enumerate(s3_all)}
    for ax, case in zip(axes[0], cases):
        series = sorted(runs[case], key=lambda r: r[0])
        seqs = sorted({q for _, _, m in series for q in m})
        for q in seqs:
            pts = [(p, c, m[q][1]) for p, c, m in series if q in m]
            s3 = round(next(m[q][0] for _, _, m in series if q in m))
            ax.plot([p * 1e3 for p, _, _ in pts], [v / 1e6 for _, _, v in pts], "o-", color=colour[s3], ms=4, lw=1,
                    label=f"seq {q} (σ₃ {s3 / 1e3:.1f} kPa)")
            print(f"{case} seq {q}: " + ", ".join(f"{p * 1e3:g} ms ({c} cycles) {v / 1e6:.1f} MPa" for p, c, v in pts))
        ax.set_xscale("log", base=2)
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda x, _: f"{x:g}"))
        ax.set_xlabel("pulse duration T_p [ms]")
        ax.set_ylabel("resilient modulus M_r [MPa]")
        ax.set_title(case)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6, loc="best")
    fig.suptitle("AASHTO T 307, time-scaled: M_r against the pulse duration")
    fig.tight_layout()
    out = out or os.path.join(dirs[0], "t307_time_scaling.png")
    fig.savefig(out, dpi=130)
    print(f"figure: {out}")


def main(argv):
    out = None
    dirs = []
    pulse_mode = False
    i = 0
    while i < len(argv):
        if argv[i] == "--out":
            out = argv[i + 1]
            i += 2
        elif argv[i] == "--against-pulse":
            pulse_mode = True
            i += 1
        else:
            dirs.append(argv[i])
            i += 1
    if not dirs:
        sys.exit(__doc__)
    if pulse_mode:
        return against_pulse(dirs, out)
    out = out or os.path.join(dirs[0], "t307_mr_theta.png")
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    cmap = plt.get_cmap("viridis")
    s3_all = sorted({round(float(r["sigma3[Pa]"])) for d in dirs for r in read_rows(os.path.join(d, "t307_sequences.csv"))})
    colour = {s3: cmap(k / max(1, len(s3_all) - 1)) for k, s3 in enumerate(s3_all)}
    for n, d in enumerate(dirs):
        rows = read_rows(os.path.join(d, "t307_sequences.csv"))
        label = os.path.basename(os.path.normpath(d))
        fit_path = os.path.join(d, "t307_fit.csv")
        fit = read_rows(fit_path)[0] if os.path.exists(fit_path) else None
        for r in rows:
            s3 = round(float(r["sigma3[Pa]"]))
            ax.plot(float(r["theta[Pa]"]) / 1e3, float(r["M_r[Pa]"]) / 1e6, MARKERS[n % 4], color=colour[s3], ms=6,
                    mfc="none" if n else colour[s3])
        if fit:
            k1, k2, k3 = (float(fit[k]) for k in ("k1[-]", "k2[-]", "k3[-]"))
            for s3 in sorted({round(float(r["sigma3[Pa]"])) for r in rows}):
                group = [float(r["sigma_max[Pa]"]) for r in rows if round(float(r["sigma3[Pa]"])) == s3]
                lo, hi = 0.5 * min(group), max(group)
                xs, ys = [], []
                for j in range(41):
                    sd = lo + (hi - lo) * j / 40
                    theta, tau = 3 * s3 + sd, math.sqrt(2) / 3 * sd
                    xs.append(theta / 1e3)
                    ys.append(k1 * P_A * (theta / P_A) ** k2 * (tau / P_A + 1) ** k3 / 1e6)
                ax.plot(xs, ys, LINES[n % 4], color=colour[s3], lw=1)
            label += f": k1 {k1:.0f}, k2 {k2:.3f}, k3 {k3:.3f}, R² {float(fit['r_squared[-]']):.3f}"
        ax.plot([], [], MARKERS[n % 4] + LINES[n % 4], color="0.3", mfc="none" if n else "0.3", label=label)
    for s3 in s3_all:
        ax.plot([], [], "s", color=colour[s3], label=f"σ₃ = {s3 / 1e3:.1f} kPa")
    ax.set_xlabel("bulk stress θ [kPa]")
    ax.set_ylabel("resilient modulus M_r [MPa]")
    ax.set_title("AASHTO T 307 (time-scaled): M_r against θ")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(out, dpi=130)
    print(f"figure: {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
