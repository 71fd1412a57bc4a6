"""A scenario built in Python equals the same TOML run by the CLI, bit for bit."""
import csv

import numpy as np

import hilldem


def pile_builder(out_dir):
    """Eight grains dropped in a box of planes, hill contacts between grains, linear to the walls."""
    b = hilldem.ScenarioBuilder(title="eight grains in a box")
    b.simulation(gravity=[0.0, 0.0, -9.81], local_damping=0.3)
    b.output(dir=str(out_dir))
    b.checkpoints(every_seconds=0)
    b.material("granite", density=2650.0, young_mod=29e9, pois_ratio=0.15)
    rng = np.random.default_rng(7)
    ids = np.arange(1, 9)
    pos = np.array([[0.01 * (i % 2), 0.01 * (i // 2 % 2), 0.006 + 0.011 * (i // 4)] for i in range(8)])
    pos += rng.uniform(-1e-3, 1e-3, pos.shape)
    b.balls(ids, pos, rng.uniform(4e-3, 5e-3, 8), "granite", groups=["grains"])
    for name, point, normal in [("floor", [0, 0, 0], [0, 0, 1]), ("x0", [-0.006, 0, 0], [1, 0, 0]),
                                ("x1", [0.016, 0, 0], [-1, 0, 0]), ("y0", [0, -0.006, 0], [0, 1, 0]),
                                ("y1", [0, 0.016, 0], [0, -1, 0])]:
        b.wall(name, "plane", point=point, normal=normal)
    b.contact_model(name="grains", between="ball-ball", model="hill", fric_coef=0.4, damp_con=0.2)
    b.contact_model(name="walls", between="ball-wall", model="linear", emod=5e8, kratio=1.5, fric=0.3)
    b.history(name="z1", quantity="ball.pos_z", ball=1)
    b.history(name="vz8", quantity="ball.vel_z", ball=8)
    b.stage("cycle", name="fall", steps=400)
    return b


def test_builder_toml_is_what_the_cli_runs(tmp_path, cli):
    """Python's build and cycle against `hilldem run` of builder.toml(): every history value (printed
    to 10 digits by both) and the final state (the CLI's last checkpoint) are the same bits."""
    b = pile_builder(tmp_path / "cli")
    scenario = tmp_path / "pile.toml"
    scenario.write_text(b.toml())
    cli("run", "-q", scenario)

    sim = b.build()
    assert (sim.ball_count, sim.wall_count) == (8, 5)
    i1, i8 = sim.index_of(1), sim.index_of(8)
    rows = []

    def record(s):
        rows.append([str(s.steps), f"{s.time:.9e}", f"{s.positions[i1, 2]:.9e}", f"{s.velocities[i8, 2]:.9e}"])

    sim.update_forces()  # as the runner does before its first stage and first history row
    record(sim)
    sim.cycle(400, callback=record, every=1)
    with open(tmp_path / "cli" / "history.csv") as f:
        cli_rows = list(csv.reader(f))
    assert cli_rows[0] == ["step", "time[s]", "z1[m]", "vz8[m/s]"]
    assert cli_rows[1:] == rows

    checkpoints = sorted((tmp_path / "cli" / "checkpoints").glob("ckpt-*.hdc"))
    final = hilldem.load_checkpoint(checkpoints[-1])
    assert final.steps == 400
    assert sim.state_difference(final) == ""
    assert sim.state_digest() == final.state_digest()


def test_builder_errors_name_the_key():
    """The builder's input goes through the scenario reader: its error names the table and key."""
    b = hilldem.ScenarioBuilder()
    b.material("m", density=2650.0, pois_ratio=0.7)
    b.ball(1, [0, 0, 0], 1e-3, "m")
    try:
        b.build(name="mine.toml")
    except hilldem.InputError as e:
        assert "mine.toml" in str(e) and "material[1].pois_ratio" in str(e) and "(-1, 0.5]" in str(e)
    else:
        raise AssertionError("no InputError")


def test_add_balls_checked_and_counted(assembly):
    """add_balls reads its tables with the scenario reader; a duplicate id is refused."""
    n = assembly.ball_count
    added = assembly.add_balls({"sand": {"density": 2650.0, "young_mod": 29e9, "pois_ratio": 0.15}},
                               [{"id": 1000, "position": [0.0, 0.0, 0.08], "radius": 2e-3, "material": "sand",
                                 "groups": ["extra"]}])
    assert added == 1 and assembly.ball_count == n + 1
    assert "extra" in assembly.group_names
    assert assembly.radii[-1] == 2e-3
    try:
        assembly.add_balls({"sand": {"density": 2650.0}},
                           [{"id": 1000, "position": [0, 0, 0.1], "radius": 1e-3, "material": "sand"}])
    except hilldem.InputError as e:
        assert "ball id 1000 is already in the simulation" in str(e)
    else:
        raise AssertionError("no InputError")
    assembly.cycle(50)
    assert np.all(np.isfinite(assembly.positions))
