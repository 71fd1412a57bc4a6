#!/usr/bin/python3
"""The bench bed of `hilldem bench` cycled from Python (hilldem.bench_bed, Simulation.cycle), printing
a line like the CLI's, to measure what driving the engine from Python costs.

    /usr/bin/python3 bench/python_bench.py [--replicate 3] [--warmup 200] [--steps 1000] [--chunk 0]
                                           [--digest]

--chunk 0 runs the timed steps as one cycle(steps) call (one engine call, which polls for Ctrl-C
every 0.05 s); --chunk N calls cycle(N) in a Python loop (N = 1: one call per cycle). OpenMP threads:
OMP_NUM_THREADS (`hilldem bench --threads`)."""
import argparse
import pathlib
import time

import hilldem


def main():
    here = pathlib.Path(__file__).resolve().parent
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=str(here / "bed_settled.data"), help="LAMMPS data file of the bed")
    ap.add_argument("--replicate", type=int, default=3, help="copies in x and y (3: 100,800 spheres)")
    ap.add_argument("--warmup", type=int, default=200, help="untimed steps first")
    ap.add_argument("--steps", type=int, default=1000, help="timed steps")
    ap.add_argument("--chunk", type=int, default=0, help="cycles per Python call (0: one call for all)")
    ap.add_argument("--digest", action="store_true", help="also print the state digest after the timed steps")
    a = ap.parse_args()
    sim = hilldem.bench_bed(a.data, a.replicate)
    sim.cycle(a.warmup)
    start = time.perf_counter()
    if a.chunk <= 0:
        sim.cycle(a.steps)
    else:
        done = 0
        while done < a.steps:
            done += sim.cycle(min(a.chunk, a.steps - done))
    seconds = time.perf_counter() - start
    line = (f"python particles={sim.ball_count} steps={a.steps} chunk={a.chunk} wall_s={seconds:.4f} "
            f"particle_steps_per_s={sim.ball_count * a.steps / seconds:.4e}")
    if a.digest:
        line += f" digest={sim.state_digest()}"
    print(line)


if __name__ == "__main__":
    main()
