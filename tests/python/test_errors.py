"""Engine errors become Python exceptions with the engine's message; no bad call crashes."""
import numpy as np
import pytest

import hilldem


def test_scenario_error_is_the_clis_message(source_dir, cli):
    bad = source_dir / "tests" / "data" / "bad" / "pois_ratio_above_half.toml"
    run = cli("check", bad, check=False)
    assert run.returncode == 2
    with pytest.raises(hilldem.InputError) as e:
        hilldem.load_scenario(bad)
    assert isinstance(e.value, ValueError)
    assert str(e.value) in run.stderr  # the same message (the CLI prefixes "error: ")
    assert "material[1].pois_ratio" in str(e.value) and "(-1, 0.5]" in str(e.value)


def test_missing_file_and_syntax_errors(tmp_path):
    with pytest.raises(hilldem.InputError, match="no_such.toml"):
        hilldem.load_scenario(tmp_path / "no_such.toml")
    with pytest.raises(hilldem.InputError, match="TOML syntax error at line"):
        hilldem.scenario_from_text("[[ball]\nid = ", "junk.toml")
    with pytest.raises(hilldem.InputError, match="not a checkpoint|magic|too short|truncated"):
        (tmp_path / "x.hdc").write_bytes(b"not a checkpoint at all")
        hilldem.load_checkpoint(tmp_path / "x.hdc")


@pytest.mark.parametrize("call, match", [
    (lambda s: s.set_positions([[0, 0, 0]], [27]), r"indices\[0\] = 27 is not a ball index; allowed: \[0, 27\)"),
    (lambda s: s.set_positions([[0, 0, 0]], [-1]), "is not a ball index"),
    (lambda s: s.set_positions([[0, 0]], [0]), r"must have shape \(1, 3\)"),
    (lambda s: s.set_positions(np.zeros((27, 3, 1))), "must have shape"),
    (lambda s: s.set_positions([["a", "b", "c"]], [0]), "array of numbers"),
    (lambda s: s.set_positions([[0, np.nan, 0]], [0]), r"values\[0, 1\] = nan is out of range"),
    (lambda s: s.set_velocities([[np.inf, 0, 0]], [0]), "out of range"),
    (lambda s: s.set_radii([0.0], [0]), r"allowed: \(0, inf\) \[m\]"),
    (lambda s: s.set_radii([1e-3], [[0]]), "1-d array"),
    (lambda s: s.fix([0], 64), "fixity mask"),
    (lambda s: s.cycle(-1), "n must be an integer >= 0"),
    (lambda s: s.cycle(10, callback=print), "a callback needs every >= 1"),
    (lambda s: s.cycle(10, callback=3, every=1), "callable"),
    (lambda s: s.solve(float("nan"), 10), "ratio must be a finite number"),
    (lambda s: s.solve(1e-3, 0), "max_steps must be an integer >= 1"),
    (lambda s: s.make_wet(-1.0, 1e-3), r"suction must be in \[0, inf\) \[Pa\]"),
    (lambda s: s.make_wet(1e3, float("nan")), "gap must be"),
    (lambda s: setattr(s, "local_damping", 1.0), r"local_damping: must be in \[0, 1\)"),
    (lambda s: setattr(s, "timestep", -1e-6), r"timestep: must be in \(0, 1\)"),
    (lambda s: setattr(s, "gravity", (0, 0, float("inf"))), "gravity: components must be finite"),
    (lambda s: s.set_wall("nope", velocity=(0, 0, 1)), "no wall named 'nope'"),
    (lambda s: s.set_wall(99, velocity=(0, 0, 1)), "wall index 99 out of range"),
    (lambda s: s.index_of(12345), "no ball with id 12345"),
])
def test_bad_calls_raise_input_error(assembly, call, match):
    before = assembly.state_digest()
    with pytest.raises(hilldem.InputError, match=match):
        call(assembly)
    assert assembly.state_digest() == before  # nothing was changed


def test_wrong_argument_types_raise_type_error(assembly):
    with pytest.raises(TypeError):
        assembly.cycle("ten")
    with pytest.raises(TypeError):
        assembly.make_wet("a", "b")


def test_calls_after_a_failed_step_raise(assembly):
    assembly.cycle(10)
    assembly.set_applied_forces([[0.0, 0.0, 1e308]], [3])
    with pytest.raises(hilldem.RunError, match="non-finite position"):
        assembly.cycle(100)
    failed_at = assembly.steps
    assert "non-finite" in assembly.failure
    for call in (lambda: assembly.cycle(1), lambda: assembly.solve(1e-3, 10), lambda: assembly.update_forces(),
                 lambda: assembly.run_stages()):
        with pytest.raises(hilldem.RunError, match=f"stopped at step {failed_at} with an error and cannot continue"):
            call()
    assert not np.all(np.isfinite(assembly.positions))  # the state where it stopped, readable
    assert len(assembly.contacts()["gap"]) >= 0
