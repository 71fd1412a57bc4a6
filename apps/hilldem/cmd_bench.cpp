// hilldem bench: particle-steps per second on the dense bed of bench/.
#include <filesystem>
#include <iostream>
#include <string>

#include "commands.hpp"
#include "hilldem/bench/bed_bench.hpp"
#include "hilldem/bench/memory_bandwidth.hpp"
#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"
#ifdef HILLDEM_MPI
#include "hilldem/parallel/bench_mpi.hpp"
#include "hilldem/parallel/mpi_world.hpp"
#endif

namespace hilldem::cli {

Command add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BedBenchOptions>();
  auto settle_out = std::make_shared<std::string>();
  auto memory = std::make_shared<bool>(false);
  auto caches = std::make_shared<bool>(false);
  auto* bench = app.add_subcommand(
      "bench", "Time the dense bed of bench/ (hill model, periodic x-y, floor, gravity, dt 1e-6 s); prints one line");
  bench->add_option("--data", o->data, "LAMMPS data file of the bed (default bench/bed_settled.data)");
  bench->add_option("--replicate", o->replicate, "copies in x and y (3: 100,800 spheres)")->check(CLI::Range(1, 20));
  bench->add_option("--steps", o->steps, "timed steps")->check(CLI::Range(1, 100000000));
  bench->add_option("--warmup", o->warmup, "untimed steps first")->check(CLI::Range(0, 100000000));
  bench->add_option("--threads", o->threads, "OpenMP threads (0: default)")->check(CLI::Range(0, 1024));
  bench->add_option("--block", o->block,
                    "balls per block of the force pass (0: the default, " +
                        std::to_string(Simulation::kDefaultBallsPerBlock) +
                        "); a tuning knob, results do not depend on it")
      ->check(CLI::Range(0, 1000000));
  bench->add_flag("--digest", o->digest,
                  "also print the state digest after the timed steps (the same for any thread count and block "
                  "size; serialises the whole state once)");
  bench->add_flag("--memory", *memory,
                  "instead of timing the bed: the memory bandwidth of one core in GB/s (STREAM copy and triad, "
                  "the triad's real traffic with write-allocate, and a read-modify-write update; 3 x 256 MiB), "
                  "the hardware limit of docs/performance.md");
  bench->add_flag("--caches", *caches,
                  "instead of timing the bed: what one core sees at working sets from 256 KiB to 256 MiB, one line "
                  "each: a streaming read-modify-write in GB/s and the latency of a load at a random line in ns "
                  "(why a bed whose step data fit in the caches runs faster per particle; docs/performance.md)");
  bench->add_option("--clumps", o->clumps,
                    std::string("each sphere a clump of this template (") + kNamedTemplates +
                        "), as large as the sphere, randomly oriented; or \"pairs\": touching spheres joined into two-pebble "
                        "clumps, the dense bed; the box not periodic (docs/clumps.md)");
  bench->add_option("--settle", *settle_out,
                    "instead of timing: settle the --data bed under hilldem's laws and write it to this file");
  return {bench, [o, settle_out, memory, caches] {
            if (*memory) {
              std::cout << measure_memory_bandwidth().line() << std::endl;
              return 0;
            }
            if (*caches) {
              for (const CacheLevel& level : measure_cache_levels(default_cache_sweep()))
                std::cout << level.line() << std::endl;
              return 0;
            }
            BedBenchOptions opt = *o;
            if (opt.data.empty()) {
              for (const std::string p : {std::string("bench/bed_settled.data"),
                                          std::string(HILLDEM_SOURCE_DIR) + "/bench/bed_settled.data"})
                if (std::filesystem::exists(p)) {
                  opt.data = p;
                  break;
                }
              if (opt.data.empty())
                throw InputError("no bed: pass --data FILE (a LAMMPS data file from bench/lammps/in.pack)");
            }
            if (!settle_out->empty()) {
              const auto steps = settle_bed(opt.data, *settle_out, 1e-3);
              std::cout << "settled in " << steps << " steps: " << *settle_out << std::endl;
              return 0;
            }
#ifdef HILLDEM_MPI
            if (const MPI_Comm comm = parallel::world(); comm != MPI_COMM_NULL) {  // under mpirun: decomposed
              const parallel::DecomposedBenchResult r = parallel::run_bed_bench_mpi(opt, comm);
              if (!r.halo.empty()) std::cout << r.bench.line() << "\n" << r.halo << std::endl;
              return 0;
            }
#endif
            std::cout << run_bed_bench(opt).line() << std::endl;
            return 0;
          }};
}

}  // namespace hilldem::cli
