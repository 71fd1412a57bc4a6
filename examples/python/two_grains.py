#!/usr/bin/python3
"""The memo's two-grain hill test (memo §2.1, spec §5.1) from Python, against the memo's values.

    /usr/bin/python3 examples/python/two_grains.py [--quick]

1. examples/two_grains_hill.toml run through Simulation.run_stages(): each probe (H1-H8, D2, D3) next
   to the memo's value and tolerance (data/reference-values.csv).
2. The same contact built by hand with hilldem.ScenarioBuilder: the top grain pushed down 0.1 mm in
   100 steps of 1 us, the contact's normal force read with Simulation.contacts() against H4 and against
   the hill law F_n = k_n d^1.5 with k_n = (4/3) E_e sqrt(R_e) (spec Eq. 24, memo H3).

Exit status 1 if any value is outside its tolerance. --quick changes nothing (the test is fast); it
is accepted so that CTest runs every example the same way."""
import argparse
import csv
import math
import pathlib
import sys

import hilldem

REPO = pathlib.Path(__file__).resolve().parents[2]


def memo_values():
    """{id: (memo value, unit, relative tolerance [-])} from data/reference-values.csv."""
    out = {}
    with open(REPO / "data" / "reference-values.csv", newline="") as f:
        for row in csv.DictReader(f):
            out[row["id"]] = (float(row["memo_value"]), row["unit"], float(row["tolerance"].split()[0]))
    return out


def check(label, value, memo, failures):
    ref, unit, tol = memo[label]
    rel = abs(value - ref) / abs(ref)
    ok = rel <= tol
    print(f"{label:4s} {value:14.6g} {ref:14.6g} {unit:10s} {rel:9.2e} {tol:7.0e}  {'pass' if ok else 'FAIL'}")
    if not ok:
        failures.append(label)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="accepted for CTest; the example is already fast")
    ap.add_argument("--out", help="accepted for CTest; nothing is written")
    ap.parse_args()
    memo = memo_values()
    failures = []
    print("id         computed           memo unit        rel. err     tol")

    sim = hilldem.load_scenario(REPO / "examples" / "two_grains_hill.toml")
    for label, p in sim.run_stages()["probes"].items():
        if label in memo:
            check(label, p["value"], memo, failures)

    # By hand: granite grains of 7.5 mm and 5 mm radius [m], touching, both fixed; ball 2 is moved at
    # an imposed velocity (fixed balls keep the velocity they are given).
    b = hilldem.ScenarioBuilder("two grains by hand")
    b.simulation(timestep=1e-6, local_damping=0.7)
    b.material("granite", density=2650, young_mod=29e9, pois_ratio=0.15)
    b.ball(1, [0.0, 0.0, 0.0], 7.5e-3, "granite", fix=["all"])
    b.ball(2, [0.0, 0.0, 12.5e-3], 5.0e-3, "granite", fix=["all"])
    b.contact_model(name="hill", between="ball-ball", model="hill", fric_coef=1000.0, damp_con=0.0, suction=200e3)
    by_hand = b.build()
    steps, dt, overlap = 100, 1e-6, 1e-4  # [-], [s], [m]
    by_hand.set_velocities([[0.0, 0.0, -overlap / (steps * dt)]], indices=[1])
    by_hand.cycle(steps)
    by_hand.set_velocities([[0.0, 0.0, 0.0]], indices=[1])
    by_hand.update_forces()
    c = by_hand.contacts()
    fn = float(c["normal_force"][0])
    e_e = 29e9 / (2 * (1 - 0.15**2))  # E_e = E / (2 (1 - nu^2)) for equal grains [Pa]
    r_e = 7.5e-3 * 5e-3 / 12.5e-3     # R_e = R1 R2 / (R1 + R2) [m]
    law = 4.0 / 3.0 * e_e * math.sqrt(r_e) * float(c["overlap"][0]) ** 1.5
    print(f"by hand: overlap {c['overlap'][0] * 1e3:.6f} mm, normal force {fn:.6g} N, hill law {law:.6g} N")
    check("H4", fn, memo, failures)
    if abs(fn - law) > 1e-9 * law:
        failures.append("hill law")
    if failures:
        print("FAILED:", ", ".join(failures))
        return 1
    print("every value within the memo's tolerance")
    return 0


if __name__ == "__main__":
    sys.exit(main())
