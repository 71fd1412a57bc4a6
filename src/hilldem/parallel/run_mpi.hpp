// The scenario runner over MPI ranks (docs/mpi.md): RunDecomposition (io/runner.hpp) on a Domain.
#pragma once

#include <memory>

#include <mpi.h>

#include "hilldem/io/runner.hpp"
#include "hilldem/parallel/domain.hpp"

namespace hilldem::parallel {

class RunOverRanks final : public RunDecomposition {
 public:
  explicit RunOverRanks(MPI_Comm comm);
  ~RunOverRanks() override;  // (detaches the Simulation)
  RunOverRanks(const RunOverRanks&) = delete;
  RunOverRanks& operator=(const RunOverRanks&) = delete;

  void attach(Simulation& sim, double reach) override;
  void detach() override;
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  bool owns(std::size_t local) const override { return domain_->owns(local); }
  std::int64_t local_of(std::size_t global) const override {
    return global > UINT32_MAX ? -1 : domain_->local_of(static_cast<std::uint32_t>(global));
  }
  Simulation gather(bool with_cycle) override { return domain_->gather(with_cycle); }
  std::int64_t from_root(std::int64_t v) override;
  double from_root(double v) override;
  std::string from_root(const std::string& s) override;
  std::int64_t max(std::int64_t v) override;
  std::uint64_t sum(std::uint64_t v) override;

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  Simulation* sim_ = nullptr;
  std::unique_ptr<Domain> domain_;
};

}  // namespace hilldem::parallel
