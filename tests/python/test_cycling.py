"""Cycling from Python: chunks change no bit, callbacks, Ctrl-C, the GIL released."""
import os
import signal
import threading
import time

import pytest

import hilldem


def test_chunking_changes_no_bit(source_dir):
    path = source_dir / "examples" / "assembly_27.toml"
    one = hilldem.load_scenario(path)
    one.cycle(600)
    loop = hilldem.load_scenario(path)
    for _ in range(600):
        loop.cycle(1)
    calls = []
    cb = hilldem.load_scenario(path)
    cb.cycle(600, callback=lambda s: calls.append(s.steps), every=7)
    assert loop.state_difference(one) == "" and cb.state_difference(one) == ""
    assert calls == list(range(7, 600, 7))  # after every 7 cycles


def test_a_callback_returning_false_stops(assembly):
    ran = assembly.cycle(1000, callback=lambda s: s.steps < 30, every=10)
    assert ran == 30 and assembly.steps == 30


def test_solve_returns_cycles_or_raises(assembly):
    used = assembly.solve(1e-2, 200000)
    assert 0 < used == assembly.steps and assembly.mean_unbalanced_ratio <= 1e-2
    with pytest.raises(hilldem.RunError, match="no equilibrium within max_steps = 3"):
        assembly.solve(1e-30, 3)
    assembly.cycle(5)  # not converging is no failure: the run goes on


def test_ctrl_c_stops_between_cycles(assembly, source_dir):
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        assembly.cycle(10**9)
    assert time.monotonic() - start < 5.0
    steps = assembly.steps
    assert 0 < steps < 10**9
    # One engine call, stopped by the interrupt: the state of cycle(steps), to the bit.
    fresh = hilldem.load_scenario(source_dir / "examples" / "assembly_27.toml")
    fresh.cycle(steps)
    assert assembly.state_difference(fresh) == ""
    assembly.cycle(10)  # the simulation stopped at a cycle boundary and goes on
    assert assembly.steps == steps + 10


def test_the_gil_is_released_while_cycling(assembly):
    counter = 0
    done = threading.Event()

    def run():
        assembly.cycle(20000)
        done.set()

    t = threading.Thread(target=run)
    t.start()
    refused = None
    while not done.is_set():
        counter += 1
        if refused is None and assembly.steps < 20000:
            try:
                assembly.cycle(1)
            except RuntimeError as e:
                refused = str(e)
    t.join()
    assert counter > 100  # Python ran meanwhile
    assert "cycling in another thread" in refused  # a second call is refused, not raced
    assert assembly.steps == 20000


def test_progress_lines(assembly, capfd):
    """progress=0.1: a line on stderr every 0.1 s of a run of a second or more."""
    start = time.monotonic()
    assembly.cycle(10**9, callback=lambda s: time.monotonic() - start < 1.0, every=1000, progress=0.1)
    err = capfd.readouterr().err
    assert "cycle 'Simulation'" in err and "steps/s" in err and "stage" in err
    with pytest.raises(hilldem.InputError, match="progress must be the seconds"):
        assembly.cycle(1, progress=-1.0)


def test_the_bench_bed_from_python_is_the_clis(source_dir, cli):
    """20 steps of `hilldem bench`'s bed cycled from Python, one call per step: the CLI's digest."""
    run = cli("bench", "--steps", 20, "--warmup", 0, "--digest")
    digest = run.stdout.split("digest=")[1].split()[0]
    bed = hilldem.bench_bed(source_dir / "bench" / "bed_settled.data")
    assert bed.ball_count == 11200
    for _ in range(20):
        bed.cycle(1)
    assert bed.state_digest() == digest


def test_ctrl_c_stops_the_stages_between_cycles(source_dir):
    """A scenario's stages run from Python (run_stages) answer Ctrl-C too: KeyboardInterrupt within
    about 0.05 s, the simulation at a cycle boundary, ready to go on."""
    text = (source_dir / "examples" / "assembly_27.toml").read_text()
    text = text[:text.index("[[stage]]")] + '[[stage]]\nname = "long"\ntype = "cycle"\nsteps = 1000000000\n'
    sim = hilldem.scenario_from_text(text, "long.toml")
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        sim.run_stages()
    assert time.monotonic() - start < 5.0
    steps = sim.steps
    assert 0 < steps < 10**9
    fresh = hilldem.scenario_from_text(text, "long.toml")
    fresh.cycle(steps)
    assert sim.state_difference(fresh) == ""  # stopped cleanly, at a cycle boundary
    sim.cycle(10)
    assert sim.steps == steps + 10 and sim.failure == ""
