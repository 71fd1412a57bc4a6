#include "hilldem/parallel/bench_mpi.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <memory>
#include <vector>

#include "hilldem/io/state_io.hpp"
#include "hilldem/parallel/domain.hpp"

namespace hilldem::parallel {

namespace {
unsigned long long sum_over(MPI_Comm comm, unsigned long long x) {
  MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, comm);  // (integers: exact in any order)
  return x;
}
}  // namespace

DecomposedBenchResult run_bed_bench_mpi(const BedBenchOptions& options, MPI_Comm comm) {
  std::unique_ptr<Domain> domain;
  ExchangeBytes bytes0;
  bool timing = false;
  std::size_t owned = 0, ghosts = 0;
  BenchDecomposition dec;
  dec.attach = [&](Simulation& sim) { domain = std::make_unique<Domain>(comm, sim); };
  dec.barrier = [&] {
    MPI_Barrier(comm);
    if (!timing) bytes0 = domain->bytes();  // (the first barrier: the timed steps start)
    timing = true;
  };
  dec.particles = [&](const Simulation&) { return static_cast<std::size_t>(sum_over(comm, domain->owned())); };
  dec.ball_contacts = [&](const Simulation& sim) {
    unsigned long long n = 0;
    for (std::size_t c = 0; c < sim.contacts.size(); ++c)
      n += sim.contacts.active[c] && sim.contacts.key[c].kind == ContactKind::BallBall && domain->owns(sim.contacts.key[c].a);
    owned = domain->owned();
    ghosts = domain->ghosts();
    return static_cast<std::size_t>(sum_over(comm, n));
  };
  dec.digest = [&](const Simulation&) {
    const Simulation whole = domain->gather();
    return domain->rank() == 0 ? state_digest(whole) : std::string();
  };
  DecomposedBenchResult r;
  r.bench = run_bed_bench(options, &dec);
  // Bytes this rank sent over the timed steps, per step; then the spread over the ranks.
  const ExchangeBytes& b = domain->bytes();
  const double steps = static_cast<double>(std::max<std::int64_t>(1, b.steps - bytes0.steps));
  double mine[5] = {static_cast<double>(owned), static_cast<double>(ghosts),
                    static_cast<double>(b.ghost - bytes0.ghost) / steps,
                    static_cast<double>(b.migration - bytes0.migration) / steps,
                    static_cast<double>(b.repartitions)};
  const int size = domain->size();
  std::vector<double> all(static_cast<std::size_t>(5 * size));
  MPI_Gather(mine, 5, MPI_DOUBLE, all.data(), 5, MPI_DOUBLE, 0, comm);
  if (domain->rank() == 0) {
    double mean[5] = {}, most[5] = {};
    for (int q = 0; q < size; ++q)
      for (int k = 0; k < 5; ++k) {
        mean[k] += all[5 * q + k] / size;
        most[k] = std::max(most[k], all[5 * q + k]);
      }
    r.halo = fmt::format(
        "ranks={} owned_mean={:.0f} owned_max={:.0f} ghosts_mean={:.0f} ghosts_max={:.0f} "
        "ghost_bytes_per_step_mean={:.0f} ghost_bytes_per_step_max={:.0f} migration_bytes_per_step_mean={:.0f} "
        "migration_bytes_per_step_max={:.0f} ghost_width_m={:.4g} cuts={:.0f}",
        size, mean[0], most[0], mean[1], most[1], mean[2], most[2], mean[3], most[3], domain->ghost_width(), most[4]);
  }
  return r;
}

}  // namespace hilldem::parallel
