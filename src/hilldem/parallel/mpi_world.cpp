#include "hilldem/parallel/mpi_world.hpp"

#include <cstdlib>
#include <stdexcept>
#include <zoltan.h>

namespace hilldem::parallel {

namespace {
bool g_active = false;
}

bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpirun()) return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  if (provided < MPI_THREAD_FUNNELED) throw std::runtime_error("MPI does not support funnelled threads");
  float version = 0.0f;
  if (Zoltan_Initialize(argc, argv, &version) != ZOLTAN_OK) throw std::runtime_error("Zoltan_Initialize failed");
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  active_ = g_active = true;
}

MpiSession::~MpiSession() {
  if (!active_) return;
  g_active = false;
  MPI_Finalize();
}

MPI_Comm world() { return g_active ? MPI_COMM_WORLD : MPI_COMM_NULL; }

}  // namespace hilldem::parallel
