#include "hilldem/parallel/run_mpi.hpp"

namespace hilldem::parallel {

RunOverRanks::RunOverRanks(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

RunOverRanks::~RunOverRanks() {
  if (sim_) sim_->domain = nullptr;
}

void RunOverRanks::attach(Simulation& sim, double reach) {
  detach();
  domain_ = std::make_unique<Domain>(comm_, sim, reach);
  sim_ = &sim;
}

void RunOverRanks::detach() {
  if (sim_) sim_->domain = nullptr;
  sim_ = nullptr;
  domain_.reset();
}

std::int64_t RunOverRanks::from_root(std::int64_t v) {
  MPI_Bcast(&v, 1, MPI_INT64_T, 0, comm_);
  return v;
}

double RunOverRanks::from_root(double v) {
  MPI_Bcast(&v, 1, MPI_DOUBLE, 0, comm_);
  return v;
}

std::string RunOverRanks::from_root(const std::string& s) {
  std::int64_t n = from_root(static_cast<std::int64_t>(s.size()));
  std::string out = rank_ == 0 ? s : std::string(static_cast<std::size_t>(n), '\0');
  MPI_Bcast(out.data(), static_cast<int>(n), MPI_CHAR, 0, comm_);
  return out;
}

std::int64_t RunOverRanks::max(std::int64_t v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT64_T, MPI_MAX, comm_);
  return v;
}

std::uint64_t RunOverRanks::sum(std::uint64_t v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_UINT64_T, MPI_SUM, comm_);  // (integers: exact in any order)
  return v;
}

}  // namespace hilldem::parallel
