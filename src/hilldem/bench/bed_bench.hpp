// The speed benchmark of issue #4: the settled dense bed of shared/bench/lammps (granite spheres,
// radii 4-6 mm, periodic in x and y, floor at z = 0, gravity, Δt = 1e-6 s) run with the hill model
// (E 29 GPa, ν 0.15, μ 0.4, γ_h 0.07 ≈ restitution 0.906) and a linear floor (E* 29 GPa).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/packing_import.hpp"

namespace hilldem {

struct BedBenchOptions {
  std::string data;           // LAMMPS data file written by in.pack
  int replicate = 1;          // copies in x and y (3 -> 100,800 spheres)
  std::int64_t warmup = 200;  // untimed steps
  std::int64_t steps = 1000;  // timed steps
  int threads = 0;            // 0 = OpenMP default
  std::size_t block = 0;
  // Also the state digest after the timed steps (io/state_io.hpp): it serialises the whole state,
  // ≈ 2.4 kB a ball in memory, and is for checking bits (thread counts, builds), not for timing.
  bool digest = false;      // balls per block of the force pass (0: the engine's default); tuning only
  // A named clump template (bodies/clump_shapes.hpp, named_template): each sphere of the bed becomes a
  // clump of it, scaled to the sphere's diameter as its enclosing diameter (so that its pebbles lie
  // inside the sphere and overlap no more than the spheres did), in a random orientation; the box is
  // then not periodic (clumps are not supported in one). "pairs": the dense bed of make_pair_bed.
  // Empty: the spheres.
  std::string clumps;
};

struct BedBenchResult {
  std::size_t particles = 0;  // balls, pebbles included
  std::size_t clumps = 0;     // (printed when > 0)
  std::int64_t steps = 0;
  double wall_seconds = 0.0;
  double particle_steps_per_second = 0.0;
  double contacts_per_particle = 0.0;  // Z: 2 × contacts / particles
  int threads = 1;
  std::int64_t rebuilds = 0;           // neighbour-list rebuilds during the timed steps
  std::string line() const;            // one machine-readable line
  // The state digest after the timed steps, when asked for (BedBenchOptions::digest): the same for any
  // thread count and block size, and for a plain and a profile-guided build of one source.
  std::string digest;
};

// What a run decomposed over MPI ranks changes in the bench (parallel/bench_mpi.cpp): the Simulation
// becomes one rank's part (attach), the clock waits for every rank (barrier), the counts are summed
// over the ranks, and the digest is that of the whole state.
struct BenchDecomposition {
  std::function<void(Simulation&)> attach;
  std::function<void()> barrier;
  std::function<std::size_t(const Simulation&)> particles;      // balls owned, summed over the ranks
  std::function<std::size_t(const Simulation&)> ball_contacts;  // active ball-ball rows, the same
  std::function<std::string(const Simulation&)> digest;
};

// The bed as a Simulation, ready to cycle.
Simulation make_bed(const Packing& packing);
// `decomposition`: null for the whole bed in this process.
BedBenchResult run_bed_bench(const BedBenchOptions& options, const BenchDecomposition* decomposition = nullptr);
// The bed with each sphere a clump of `unit` (see BedBenchOptions::clumps), orientations from `seed`.
Simulation make_clump_bed(const Packing& packing, const ClumpTemplate& unit, std::uint64_t seed);
// The dense, settled clump bed: the sphere bed (its contacts after one step) with touching spheres
// joined into two-pebble clumps, each pebble where its sphere is — greedily in bed order, each free
// ball with its free partner of largest overlap; a ball left without one is a one-pebble clump. Pairs
// across the periodic boundary are not joined (the clump bed is not periodic). Each clump's mass
// properties are exact (two overlapping spheres). The geometry and the contacts between clumps are
// the sphere bed's; no settling is needed. Deterministic.
Simulation make_pair_bed(const Packing& packing);

// Settle a bed under hilldem's own contact laws (local damping 0.7, to a mean unbalanced-force
// ratio of `ratio`) and write it as a LAMMPS data file, so that both codes time the same bed.
// LAMMPS settles with a Hertz floor; hilldem's floor is linear (hill contacts are grain-grain
// only), so a LAMMPS bed starts with a kick at the floor. Returns the steps used.
std::int64_t settle_bed(const std::string& in, const std::string& out, double ratio);

}  // namespace hilldem
