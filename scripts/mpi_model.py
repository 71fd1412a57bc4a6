#!/usr/bin/python3
"""The performance model of the MPI domain decomposition (docs/mpi.md, "Beyond this machine").

Time per step on P ranks of one core each, for N balls in cubic sub-domains of n = N / P balls:
  T = (n + g) t_ball                  the force pass and motion of owned and ghost balls (ghost rows
                                      are computed too: the redundancy of the design)
    + m alpha + b g / beta            the ghosts' motion: m messages a step, b bytes a ghost
    + alpha log2(P)                   the rebuild decision (an MPI_LOR allreduce every step)
with g = rho ((s + 2 w)^3 - s^3) ghosts of a cube of side s = (n / rho)^(1/3) [m] (a layer w deep on
every face), and the efficiency E = N t_ball / (P T). Measured here (docs/mpi.md): t_ball, rho, w, b.
Assumed (a cluster's interconnect, stated, not measured): alpha, beta, m.
"""
import argparse
import math

p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
p.add_argument("--t-ball", type=float, required=True, help="seconds per ball-step on one core (1 / particle-steps per s)")
p.add_argument("--rho", type=float, default=1.085e6, help="balls per m^3 (the bench bed: 1.085e6)")
p.add_argument("--width", type=float, default=0.013, help="ghost layer width w [m] (the bench bed: 0.013)")
p.add_argument("--bytes", type=float, default=72.0, help="bytes a ghost a step (position, velocity, spin: 72)")
p.add_argument("--alpha", type=float, default=2e-6, help="assumed message latency [s] (2 us: InfiniBand class)")
p.add_argument("--beta", type=float, default=5e9, help="assumed bandwidth a rank [B/s] (5 GB/s)")
p.add_argument("--messages", type=int, default=26, help="assumed neighbours a rank (26: faces, edges, corners)")
a = p.parse_args()


def step_time(n_total, ranks):
    n = n_total / ranks
    s = (n / a.rho) ** (1.0 / 3.0)
    g = a.rho * ((s + 2 * a.width) ** 3 - s ** 3) if ranks > 1 else 0.0
    comm = (a.messages * a.alpha + a.bytes * g / a.beta + a.alpha * math.log2(ranks)) if ranks > 1 else 0.0
    return (n + g) * a.t_ball + comm, g, comm


print(f"t_ball={a.t_ball:.3g} s rho={a.rho:.4g}/m3 w={a.width} m bytes/ghost={a.bytes:g} "
      f"alpha={a.alpha:g} s beta={a.beta:g} B/s messages={a.messages}")
print(f"{'N':>8} {'ranks':>6} {'balls/rank':>11} {'ghosts/rank':>12} {'step_s':>10} {'comm_s':>10} {'efficiency':>10}")
for n_total in (1e6, 1e7, 1e8):
    for ranks in (1, 10, 30, 100, 300, 1000):
        t, g, comm = step_time(n_total, ranks)
        e = n_total * a.t_ball / (ranks * t)
        print(f"{n_total:8.0e} {ranks:6d} {n_total / ranks:11.0f} {g:12.0f} {t:10.3g} {comm:10.3g} {e:10.2f}")
    ranks = 1
    while n_total * a.t_ball / (ranks * step_time(n_total, ranks)[0]) >= 0.8 and ranks < 10**7:
        ranks += 1
    print(f"{n_total:8.0e}: efficiency below 0.80 from {ranks} ranks ({n_total / ranks:.0f} balls a rank)")
