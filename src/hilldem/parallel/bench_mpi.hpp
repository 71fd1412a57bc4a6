// `hilldem bench` decomposed over the MPI ranks (docs/mpi.md): the bed of bench/bed_bench.hpp,
// each rank one sub-domain, the digest that of the whole state (the same as one process's).
#pragma once

#include <string>

#include <mpi.h>

#include "hilldem/bench/bed_bench.hpp"

namespace hilldem::parallel {

struct DecomposedBenchResult {
  BedBenchResult bench;  // (on rank 0: digest, particles and contacts of the whole bed)
  std::string halo;      // one line on rank 0: ranks, balls and ghosts per rank, bytes sent per step per rank
};

DecomposedBenchResult run_bed_bench_mpi(const BedBenchOptions& options, MPI_Comm comm);

}  // namespace hilldem::parallel
