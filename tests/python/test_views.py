"""numpy views of the ball arrays: zero-copy, read-only, right across cycles and neighbour-list
rebuilds, and what happens when balls are added."""
import gc

import numpy as np
import pytest

import hilldem


def test_views_are_zero_copy_read_only_and_typed(assembly):
    p = assembly.positions
    assert p.shape == (27, 3) and p.dtype == np.float64 and not p.flags.writeable
    assert np.shares_memory(p, assembly.positions)  # two views, one column: no copy
    assert assembly.ids.dtype == np.int64 and assembly.groups.dtype == np.uint64
    assert assembly.fixity.dtype == np.uint8 and assembly.radii.shape == (27,)
    with pytest.raises(ValueError, match="read-only"):
        p[0, 0] = 1.0


def test_views_follow_the_state_across_cycles_and_rebuilds(assembly):
    p, f = assembly.positions, assembly.forces
    before = p.copy()
    rebuilds = assembly.rebuilds
    for _ in range(6):
        assembly.cycle(500)
        assert np.array_equal(p, np.array(assembly.positions))  # the old view sees the new state
    assert assembly.rebuilds > rebuilds  # the neighbour list was rebuilt meanwhile
    assert not np.array_equal(p, before)
    # The forces view is the sum of the contact forces: F_c on piece 2, −F_c on piece 1.
    c = assembly.contacts()
    index = {int(i): k for k, i in enumerate(assembly.ids)}
    expect = np.zeros((27, 3))
    for k in range(len(c["ball1"])):
        expect[index[int(c["ball1"][k])]] -= c["force"][k]
        if c["kind"][k] == 0:
            expect[index[int(c["piece2"][k])]] += c["force"][k]
    scale = np.abs(expect).max()
    assert scale > 0
    np.testing.assert_allclose(f, expect, rtol=0, atol=1e-12 * scale)


def test_a_view_keeps_its_simulation_alive(source_dir):
    sim = hilldem.load_scenario(source_dir / "examples" / "assembly_27.toml")
    sim.cycle(10)
    r = sim.radii
    want = r.copy()
    del sim
    gc.collect()
    assert np.array_equal(r, want)


def test_adding_balls_with_live_views_is_refused(assembly):
    sand = {"sand": {"density": 2650.0, "young_mod": 29e9, "pois_ratio": 0.15}}
    ball = [{"id": 500, "position": [0.0, 0.0, 0.09], "radius": 2e-3, "material": "sand"}]
    p = assembly.positions
    view_of_view = p[:, 2]
    del p
    assert assembly.live_views == 1  # the slice holds the view's token
    with pytest.raises(BufferError, match="1 numpy view"):
        assembly.add_balls(sand, ball)
    assert assembly.ball_count == 27
    del view_of_view
    gc.collect()
    assert assembly.live_views == 0
    assembly.add_balls(sand, ball)
    assert assembly.positions.shape == (28, 3)  # a new view sees the new ball


def test_setters_validate_and_invalidate(assembly):
    assembly.cycle(200)
    i = assembly.index_of(14)
    z = assembly.positions[i, 2]
    assembly.set_positions([[0.0, 0.0, z + 0.05]], [i])  # lifted clear of its neighbours
    assert assembly.positions[i, 2] == z + 0.05
    assembly.update_forces()
    c = assembly.contacts()
    assert 14 not in set(c["ball1"][c["active"]]) | set(c["piece2"][c["active"] & (c["kind"] == 0)])
    assert np.all(assembly.forces[i] == 0.0)
    m = assembly.masses[i]
    assembly.set_radii([2 * assembly.radii[i]], [i])
    assert assembly.masses[i] == pytest.approx(8 * m, rel=1e-12)
    assembly.set_velocities(np.zeros((27, 3)))
    assembly.fix([i], hilldem.FIX_VELOCITY)
    assert assembly.fixity[i] & hilldem.FIX_VELOCITY == hilldem.FIX_VELOCITY
    assembly.set_velocities([[0.0, 0.0, -0.1]], [i])
    assembly.cycle(10)
    assert assembly.velocities[i, 2] == -0.1  # fixed: keeps its velocity
    assembly.free([i])
    assert assembly.fixity[i] == 0


def test_moving_a_wall(assembly):
    walls = assembly.walls()
    name = walls[0]["name"]
    assembly.set_wall(name, velocity=[0.0, 0.0, 0.01])
    assert assembly.walls()[0]["velocity"] == (0.0, 0.0, 0.01)
    assembly.cycle(20)
    moved = assembly.walls()[0]["vertices"][0][2] - walls[0]["vertices"][0][2]
    assert moved == pytest.approx(0.01 * assembly.time, rel=1e-9)  # facets move with their velocity [m/s]
