// Domain: one rank's part of a run decomposed over MPI ranks (docs/mpi.md).
//
// The rank's Simulation holds the balls whose centres lie in its sub-domain (owned) and ghost
// copies of every ball within `ghost_width()` of it, all in the relative order of the whole run
// (by global index: a ball's index in the whole run's BallStore). The engine sums each ball's rows
// in one order by local index (engine/force_pass.hpp), and local order is global order, so each
// owned ball sees the same rows, with the same inputs, in the same order as in the whole run: the
// same bits for any rank count. Every row between two local balls is kept, ghost-ghost rows too, and
// is bitwise the whole run's row: its inputs are exact copies.
//
// Per step (DomainHooks): after the law of motion each owner sends its balls' position, velocity and
// spin to the ranks that ghost them (after_motion); the rebuild decision is the OR of the ranks'
// (rebuild_anywhere); after the force pass the walls' sums are made from every rank's owned rows in
// the whole run's row order (after_forces); before a rebuild (before_rebuild) the balls go to their new owner and ghost
// ranks with every column, and each row goes from the owner of its first ball to every rank that
// will hold both its balls, with its history (the pattern of LAMMPS's fix neigh/history). The
// sub-domains are cut again by Zoltan RCB, weighted by rows per ball, when the rows per rank are out
// of balance by more than kImbalance.
//
// Clumps (docs/mpi.md, "Clumps over ranks"): a clump is owned by the rank whose sub-domain holds its
// centre of mass, and held whole (its state and every pebble) by each rank it comes near, in the
// whole run's clump and pebble order; its pebbles are balls with its owner and its ranks. The owner
// has every row of every pebble, so it sums the clump's loads as the whole run does; after the law
// of motion it sends the clump's state (16 doubles) to the ranks that ghost it, which place its
// pebbles from it: every copy is bitwise the owner's.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <mpi.h>

#include "hilldem/engine/simulation.hpp"
#include "hilldem/parallel/partition.hpp"

namespace hilldem::parallel {

// Bytes this rank sent, for docs/mpi.md's halo volume.
struct ExchangeBytes {
  std::uint64_t ghost = 0;      // after_motion: ghosts' motion
  std::uint64_t migration = 0;  // before_rebuild: balls and rows
  std::uint64_t walls = 0;      // after_forces: the walls' shares of owned rows
  std::int64_t steps = 0, rebuilds = 0, repartitions = 0;
};

class Domain final : public DomainHooks {
 public:
  // Rebalance when the largest rank's rows exceed the mean by this factor [-].
  static constexpr double kImbalance = 1.10;

  // Make `sim`, the whole run (the same on every rank: balls, walls, rows), this rank's part, and
  // attach to it (sim.domain). A run that has cycled (its neighbour list built: a restored
  // checkpoint) keeps its cycle state, each rank the positions at the last rebuild of its balls, so
  // that it rebuilds when the whole run would. sim must stay where it is while attached; a Simulation that outlives
  // its Domain is detached by setting sim.domain = nullptr (the destructor does not touch sim).
  // min_reach [m]: the ghosts cover pairs this far apart beyond their radii (make_wet's gap), as they
  // do the normal reach (proximity) and every existing row's gap.
  Domain(MPI_Comm comm, Simulation& sim, double min_reach = 0.0);
  ~Domain() override;
  Domain(const Domain&) = delete;
  Domain& operator=(const Domain&) = delete;

  void after_motion(Simulation& sim) override;
  bool rebuild_anywhere(bool here) override;
  void before_rebuild(Simulation& sim) override;
  // Every active wall row of an owned ball gives its share (wall_row_share) to every rank; each rank
  // adds them all, by key (global ball index, wall), from zero: the whole run's sums, bitwise.
  void after_forces(Simulation& sim) override;
  double min_over_ranks(double x) override;

  // The whole run's state on rank 0 (balls by global index, rows by key in global indices, the walls'
  // sums over all rows in row order); an empty Simulation on other ranks. Collective. with_cycle:
  // with the whole run's cycle state too (the positions at the last rebuild from the balls' owners),
  // so that a checkpoint of it resumes with the next rebuild where the whole run makes it.
  Simulation gather(bool with_cycle = false) const;

  int rank() const { return rank_; }
  int size() const { return size_; }
  std::size_t owned() const;  // balls owned here
  bool owns(std::size_t local) const { return owner_[local] == rank_; }
  // The global index of local ball i.
  std::uint32_t global_index(std::size_t local) const { return global_[local]; }
  // The local index of the whole run's ball `global`, owned or ghost, or -1 where this rank does not
  // hold it (a binary search: local order is global order).
  std::int64_t local_of(std::uint32_t global) const;
  std::size_t ghosts() const { return global_.size() - owned(); }
  // The ghost layer's width [m] for balls: the reach (the largest of proximity, min_reach and every
  // existing row's gap, + skin) + twice the largest radius + clump_extent() (a pebble of a clump
  // owned here lies that far outside the sub-domain). A clump is held where its centre of mass comes
  // within ghost_width() + clump_extent(): then any of its pebbles within ghost_width() is.
  double ghost_width() const { return width_; }
  // The largest distance [m] of a pebble's centre from its clump's centre of mass (0 without clumps).
  double clump_extent() const { return extent_; }
  std::size_t owned_clumps() const;
  const ExchangeBytes& bytes() const { return bytes_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  Simulation* sim_;
  double min_reach_ = 0.0;           // [m]
  double skin_given_ = 0.0;          // the scenario's skin (0: from the radii, fixed at the attach)
  std::unique_ptr<RcbPartition> rcb_;
  double width_ = 0.0;               // [m]
  double extent_ = 0.0;              // [m] (clump_extent)
  std::vector<std::uint32_t> global_;  // per local ball: its global index (ascending)
  std::vector<int> owner_;             // per local ball: its owner's rank
  // after_motion's lists: per rank, the local balls sent (owned here, ghosted there) and received.
  std::vector<std::vector<std::uint32_t>> send_, recv_;
  // The same for clumps: per local clump its global index (ascending) and owner, per local pebble
  // its global index (ascending); after_motion's clump lists.
  std::vector<std::uint32_t> clump_global_, pebble_global_;
  std::vector<int> clump_owner_;
  std::vector<std::vector<std::uint32_t>> clump_send_, clump_recv_;
  std::vector<std::vector<std::uint32_t>> pebbles_of_;  // per local clump, its pebbles
  ExchangeBytes bytes_;
  std::vector<char> wall_in_;  // after_forces: every rank's shares

  void set_width(const Simulation& sim);
  void cut(const Simulation& sim, bool weighted);
  // Every rank that is to hold a body at x [m] (position as in the columns) as far as `width` [m]:
  // its owner first, then its ghost ranks, sorted.
  void ranks_of(const Vec3& x, double width, std::vector<int>& out) const;
  // The same for each of sim's balls and clumps: a ball that is not a pebble by its position and
  // ghost_width(), a clump by its centre of mass and ghost_width() + clump_extent(), a pebble where
  // its clump is.
  void places(const Simulation& sim, std::vector<std::vector<int>>& balls, std::vector<std::vector<int>>& clumps) const;
  void make_lists(const Simulation& sim);
};

}  // namespace hilldem::parallel
