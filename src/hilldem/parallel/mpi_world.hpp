// The MPI session of the CLI (docs/mpi.md): MPI is started only when an MPI launcher (mpirun)
// started the process, so that the MPI build run on its own behaves exactly as the plain build.
#pragma once

#include <mpi.h>

namespace hilldem::parallel {

// Whether this process was started by an MPI launcher (OpenMPI's, or a PMI/PMIx one).
bool launched_by_mpirun();

// MPI_Init (funnelled threads: only the main thread calls MPI; OpenMP threads run the passes) and
// Zoltan's initialisation, when launched_by_mpirun(); MPI_Finalize at the end.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  bool active() const { return active_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  bool active_ = false;
  int rank_ = 0, size_ = 1;
};

// The session's communicator (MPI_COMM_WORLD), or MPI_COMM_NULL when MPI was not started.
MPI_Comm world();

}  // namespace hilldem::parallel
