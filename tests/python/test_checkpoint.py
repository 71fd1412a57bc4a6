"""Checkpoints from Python, and a CLI-written checkpoint continued in Python bitwise."""
import hilldem


def test_save_load_continues_bitwise(assembly, tmp_path):
    assembly.cycle(300)
    path = tmp_path / "at300.hdc"
    assembly.save_checkpoint(path)
    assembly.cycle(300)
    restored = hilldem.load_checkpoint(path)
    assert restored.steps == 300
    restored.cycle(300)
    assert restored.state_difference(assembly) == ""


CYCLING = """
[simulation]
gravity = [0.0, 0.0, -9.81]
local_damping = 0.2
[checkpoints]
every = 150
every_seconds = 0
keep = 10
[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[ball_grid]]
first_id = 1
origin = [0.0, 0.0, 0.006]
counts = [3, 3, 3]
spacing = 0.0105
radius = 5e-3
material = "granite"
[[wall]]
name = "floor"
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[contact_model]]
name = "grains"
between = "ball-ball"
model = "hill"
fric_coef = 0.4
damp_con = 0.2
[[contact_model]]
name = "floor"
between = "ball-wall"
model = "linear"
emod = 5e8
fric = 0.3
[[stage]]
type = "cycle"
steps = 600
"""


def test_a_cli_checkpoint_continues_bitwise_in_python(tmp_path, cli):
    """`hilldem run` writes checkpoints every 150 steps; the one at step 150, continued 450 steps in
    Python, is bit for bit the CLI's state at step 600."""
    scenario = tmp_path / "drop.toml"
    scenario.write_text(CYCLING)
    cli("run", "-q", scenario, "-o", tmp_path / "out")
    by_step = {}
    for f in (tmp_path / "out" / "checkpoints").glob("ckpt-*.hdc"):
        sim = hilldem.load_checkpoint(f)
        by_step[sim.steps] = f
    assert {150, 600} <= set(by_step)
    sim = hilldem.load_checkpoint(by_step[150])
    sim.cycle(450)
    cli_final = hilldem.load_checkpoint(by_step[600])
    assert sim.state_difference(cli_final) == ""
    assert sim.state_digest() == cli_final.state_digest()
