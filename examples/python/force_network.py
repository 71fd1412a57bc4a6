#!/usr/bin/python3
"""A checkpoint read back and its contact-force network plotted (matplotlib, written to a PNG).

    /usr/bin/python3 examples/python/force_network.py [--quick] [--checkpoint FILE] [--out DIR]

Without --checkpoint, the memo's 27-grain assembly (examples/assembly_27.toml) is settled under
gravity from Python and saved with Simulation.save_checkpoint; any checkpoint works, including a CLI
run's (`hilldem run ... --checkpoint-every N`: out/<run>/checkpoints/ckpt-*.hdc). The checkpoint is
read back with hilldem.load_checkpoint, and each contact is drawn in the x-z plane as a line from
ball centre to ball centre (to the contact point for a wall), its width proportional to the normal
force [N]. --quick settles to a looser ratio. Exit status 1 unless the walls carry the weight of the
assembly it settled (without --checkpoint) within 1 %."""
import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hilldem  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]


def make_checkpoint(path, ratio):
    """Settle the 27-grain assembly to a mean unbalanced-force ratio [-] and save its state."""
    sim = hilldem.load_scenario(REPO / "examples" / "assembly_27.toml")
    sim.solve(ratio, 2_000_000)
    sim.save_checkpoint(path)
    print(f"settled in {sim.steps} steps ({sim.time:.4g} s simulated); checkpoint {path}")


def plot_network(sim, png):
    """The contact-force network of sim in the x-z plane; returns the largest normal force [N]."""
    c = sim.contacts()
    pos = np.array(sim.positions)  # [m], a copy
    row_of = {int(i): k for k, i in enumerate(sim.ids)}
    fig, ax = plt.subplots(figsize=(6, 6))
    for x, r in zip(pos, sim.radii):
        ax.add_patch(plt.Circle((x[0], x[2]), r, fill=False, color="0.6", lw=0.8))
    fmax = max(float(np.max(c["normal_force"])), 1e-300) if len(c["normal_force"]) else 1.0
    for k in range(len(c["ball1"])):
        fn = c["normal_force"][k]
        if fn <= 0.0:
            continue
        a = pos[row_of[int(c["ball1"][k])]]
        b = pos[row_of[int(c["piece2"][k])]] if c["kind"][k] == 0 else c["point"][k]
        ax.plot([a[0], b[0]], [a[2], b[2]], color="tab:red" if c["kind"][k] == 0 else "tab:blue",
                lw=0.5 + 6.0 * fn / fmax, solid_capstyle="round")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(f"contact forces (red: ball-ball, blue: ball-wall); max {fmax:.3g} N")
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return fmax


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="settle to ratio 1e-3 instead of 1e-5 [-]")
    ap.add_argument("--checkpoint", help="plot this checkpoint instead of making one")
    ap.add_argument("--out", default="out/python_examples", help="folder for the checkpoint and the figure")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    ckpt = pathlib.Path(a.checkpoint) if a.checkpoint else out / "assembly_27.hdc"
    if not a.checkpoint:
        make_checkpoint(ckpt, 1e-3 if a.quick else 1e-5)
    sim = hilldem.load_checkpoint(ckpt)
    sim.update_forces()
    png = out / "force_network.png"
    fmax = plot_network(sim, png)
    total = -sum(w["force"][2] for w in sim.walls())  # downward push of the balls on the walls [N]
    weight = float(np.sum(sim.masses)) * 9.81
    print(f"{sim.ball_count} balls, {sim.contact_count} contacts, largest normal force {fmax:.4g} N; "
          f"walls carry {total:.4g} N of the {weight:.4g} N weight; figure {png}")
    # The settled assembly's walls carry its weight: a check that its checkpoint read back whole.
    settled = a.checkpoint or abs(total - weight) <= 0.01 * weight
    return 0 if png.stat().st_size > 0 and settled else 1


if __name__ == "__main__":
    sys.exit(main())
