#!/usr/bin/python3
"""Calibration: the grain friction coefficient mu [-] that gives a target peak deviator stress q_peak
[Pa] in a triaxial test, found by the Illinois (safeguarded secant) method on one packed specimen.

    /usr/bin/python3 examples/python/calibrate_friction.py [--quick] [--target 250e3] [--scale 0.15]
        [--grading fine|C5n|C5b|FILE] [--iterations 6] [--final-strain 0.01] [--out DIR]

The specimen is packed once (hilldem.lab.pack_specimen; frictionless, so it does not depend on mu),
then for each trial mu a copy is finalized with that friction (lab.finalize) and loaded
monotonically to --final-strain (lab.triaxial). The figure (q against axial strain for every trial,
and q_peak against mu with the target) is written to <out>/calibrate_friction.png.

The default is small and fast: the memo's vessel scaled by 0.15 (25 mm x 36 mm) of 5.6-8 mm grains,
about 45 grains. A realistic run: --scale 0.5 --grading C5b --iterations 8 (about 1,900 grains; an
hour or more). --quick: 3 trials and loading to 0.5 %, for the test suite. Exit status 1 when the
best trial misses the target by more than --tolerance."""
import argparse
import pathlib
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from hilldem import lab  # noqa: E402

MEMO_RADIUS, MEMO_HEIGHT = 0.085, 0.240  # the memo's vessel [m]


def grading(name):
    """'fine' (5.6-8 mm, a quick grading), C5n, C5b or a CSV file (lab.grading)."""
    if name == "fine":
        return lab.Grading("fine", [lab.GradingBin(5.6e-3, 8.0e-3, 1.0)])
    return lab.grading(name)


def peak_q(packed, mu, t, walls, equilibrium):
    """Finalize a copy of the packed specimen at friction mu [-] and test it: (q_peak [Pa], result)."""
    s = packed.copy()
    material = lab.Class5Material()  # granite hill grains of the memo's Table 7
    material.fric = mu
    lab.finalize(s, material, walls, equilibrium)
    res = lab.triaxial(s, t)
    return res["peak_q"], res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="3 trials, loading to 0.5 %% (the test suite's run)")
    ap.add_argument("--target", type=float, default=250e3, help="peak deviator stress to reach [Pa]")
    ap.add_argument("--scale", type=float, default=0.15, help="vessel size relative to the memo's 170 mm x 240 mm")
    ap.add_argument("--grading", default="fine", help="fine (5.6-8 mm), C5n, C5b or a grading CSV file")
    ap.add_argument("--iterations", type=int, default=6, help="trials of mu, the two bracket ends included")
    ap.add_argument("--bracket", type=float, nargs=2, default=[0.1, 1.0], help="mu bracket [-]")
    ap.add_argument("--final-strain", type=float, default=0.01, help="axial strain of the test [-] (0.01 = 1 %%)")
    ap.add_argument("--confinement", type=float, default=150e3, help="confining pressure sigma_c [Pa]")
    ap.add_argument("--seed", type=int, default=42, help="seed of the grain cloud")
    ap.add_argument("--tolerance", type=float, default=0.05,
                    help="exit status 1 unless the best trial is within this fraction of the target [-]")
    ap.add_argument("--out", default="out/python_examples", help="folder of the figure")
    a = ap.parse_args()
    if a.quick:
        a.iterations, a.final_strain = 3, 0.005
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)

    spec = lab.GenesisSpec()
    spec.grading = grading(a.grading)
    spec.vessel_radius, spec.vessel_height = MEMO_RADIUS * a.scale, MEMO_HEIGHT * a.scale
    spec.packing.seed = a.seed
    spec.packing.equilibrium.pressure = a.confinement
    t0 = time.perf_counter()
    packed = lab.pack_specimen(spec)
    print(f"packed {packed.grains} grains in {time.perf_counter() - t0:.1f} s; porosity {packed.state()['porosity']:.4f}")

    t = lab.TriaxialSettings()
    t.confinement = a.confinement
    t.cycle_strains = []  # monotonic loading
    t.final_strain = a.final_strain
    walls, equilibrium = lab.WallContact(), spec.packing.equilibrium

    trials = []  # (mu, q_peak [Pa], result)

    def trial(mu):
        start = time.perf_counter()
        q, res = peak_q(packed, mu, t, walls, equilibrium)
        trials.append((mu, q, res))
        print(f"mu = {mu:.4f}: q_peak = {q / 1e3:8.2f} kPa (target {a.target / 1e3:.2f} kPa), "
              f"{res['steps']} steps, {time.perf_counter() - start:.1f} s")
        return q - a.target

    lo, hi = a.bracket
    f_lo, f_hi = trial(lo), trial(hi)
    side = 0
    for _ in range(max(0, a.iterations - 2)):
        if f_lo * f_hi > 0:
            print("the target is outside the bracket's peak stresses; widen --bracket")
            break
        mu = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)  # secant through the bracket ends
        f = trial(mu)
        if f * f_hi > 0:  # Illinois: halve the end that stays, so the bracket closes from both sides
            hi, f_hi = mu, f
            if side == -1:
                f_lo /= 2
            side = -1
        else:
            lo, f_lo = mu, f
            if side == 1:
                f_hi /= 2
            side = 1
    best = min(trials, key=lambda x: abs(x[1] - a.target))
    print(f"best: mu = {best[0]:.4f}, q_peak = {best[1] / 1e3:.2f} kPa ({100 * (best[1] / a.target - 1):+.2f} % from the target)")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    for mu, q, res in sorted(trials, key=lambda x: x[0]):
        h = res["history"]
        ax1.plot(100 * h["eps_a"], h["q"] / 1e3, label=f"mu = {mu:.3f}")
    ax1.axhline(a.target / 1e3, color="k", ls="--", lw=0.8)
    ax1.set_xlabel("axial strain [%]")
    ax1.set_ylabel("deviator stress q [kPa]")
    ax1.legend(fontsize=8)
    by_mu = sorted(trials, key=lambda x: x[0])
    ax2.plot([x[0] for x in by_mu], [x[1] / 1e3 for x in by_mu], "o-")
    for k, (mu, q, _) in enumerate(trials):
        ax2.annotate(str(k + 1), (mu, q / 1e3), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax2.axhline(a.target / 1e3, color="k", ls="--", lw=0.8, label="target")
    ax2.set_xlabel("friction coefficient mu [-]")
    ax2.set_ylabel("peak deviator stress [kPa]")
    ax2.legend()
    fig.suptitle(f"{packed.grains} grains, sigma_c = {a.confinement / 1e3:g} kPa")
    fig.tight_layout()
    png = out / "calibrate_friction.png"
    fig.savefig(png, dpi=110)
    print(f"figure {png}")
    return 0 if abs(best[1] / a.target - 1) <= a.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
