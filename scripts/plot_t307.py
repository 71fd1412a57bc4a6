#!/usr/bin/python3
"""Figure of `hilldem t307` runs: M_r against the bulk stress theta, with the universal-model fit.

    scripts/plot_t307.py OUTPUT_DIR [OUTPUT_DIR ...] [--out FILE]
                                   (Debian's /usr/bin/python3, which python3-matplotlib serves)

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
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

P_A = 101.325e3  # Pa
MARKERS = ["o", "s", "^", "D"]
LINES = ["-", "--", ":", "-."]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main(argv):
    out = None
    dirs = []
    i = 0
    while i < len(argv):
        if argv[i] == "--out":
            out = argv[i + 1]
            i += 2
        else:
            dirs.append(argv[i])
            i += 1
    if not dirs:
        sys.exit(__doc__)
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
