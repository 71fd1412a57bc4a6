// NeighbourList: the contact rows of every pair within proximity + skin, their per-ball row lists,
// and when they must be made again.
//
// Why: finding the pairs near each ball is a pass over a cell grid, far dearer than a step; the
// list holds the pairs within proximity + skin [m] and lasts until something may have moved more
// than half the skin since (then a pair outside it may be within proximity). Its rows are the
// ContactStore's rows, sorted by key (kind, then ball a, then b); history survives a rebuild by a
// sorted merge with the old rows.
//
// The row lists fix the order of every ball's force sum, the same for any thread count: a ball's
// ball-ball rows where it is piece 1 (first_rows, which are contiguous), in descending row order,
// those where it is piece 2 (late_rows), then its wall rows (wall_rows) in row order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/bodies/wall_store.hpp"
#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

class NeighbourList {
 public:
  // Computes a new row's mapping from its parameters (compute_mapping, engine/model_dispatch.hpp).
  using MapRow = std::function<void(ContactStore&, std::size_t)>;

  // Make the rows for the current positions: every ball-ball pair within `reach` [m] (proximity +
  // skin) and every ball-wall pair whose gap is within it, merged with `contacts` by key, and an
  // old row that is no longer a candidate kept only while it must be (a wet hill contact, spec
  // §2.5). A new row takes its assignment rule's model and parameters (`table`); pairs no rule
  // matches are counted (unassigned_pairs). Positions are wrapped into the periodic box first.
  // Throws RunError for a ball with a non-finite position (`step`: for the message). The row lists
  // are left to build_row_lists; built() ends the rebuild. clump_of: per ball its clump
  // (ClumpBodies::clump_of_balls), empty without clumps: no rows between pebbles of one clump.
  void rebuild(ContactStore& contacts, BallStore& balls, const WallStore& walls, const ModelTable& table,
               const PeriodicBox& box, double reach, std::int64_t step, const MapRow& map_row,
               const std::vector<std::uint32_t>& clump_of = {});
  // After restore(): the rows of the last rebuild again, from a checkpoint that saved only the
  // contacts and the wall rows (`contacts`, sorted by key): the ball-ball rows that are not
  // contacts are made as the rebuild made them, from its positions (position_at_build; clump_of as
  // for rebuild). Positions are not wrapped, and the next rebuild comes when the saved run's
  // would: the cycles go on bitwise, in a periodic box too.
  void restore_rows(ContactStore& contacts, const BallStore& balls, const WallStore& walls, const ModelTable& table,
                    const PeriodicBox& box, double reach, const MapRow& map_row,
                    const std::vector<std::uint32_t>& clump_of = {}) const;
  // The per-ball row lists of `n` balls from the current rows (in row order).
  void build_row_lists(const ContactStore& contacts, std::size_t n);
  // The rebuild is done at these positions [m]: the travel since counts from here.
  void built(const std::vector<Vec3>& position) {
    position_at_build_ = position;
    travel_bound_ = 0.0;
    wall_travel_ = 0.0;
    rebuild_needed_ = false;
    ++rebuilds_;
  }

  // Rebuild before the next force evaluation.
  void invalidate() { rebuild_needed_ = true; }
  // Whether the list must be made again whatever the travel (asked for, or other balls).
  bool stale(std::size_t n) const { return rebuild_needed_ || position_at_build_.size() != n; }
  const std::vector<Vec3>& position_at_build() const { return position_at_build_; }  // [m]
  // Whether a ball travel [m] since the rebuild, with the walls', leaves every pair outside the
  // list beyond proximity (`half`: half the skin [m]).
  bool holds(double ball_travel, double half) const {
    return ball_travel <= half && ball_travel + wall_travel_ <= 2.0 * half;
  }
  // A bound on any wall point's motion since the rebuild [m], grown by `d` [m].
  void add_wall_travel(double d) { wall_travel_ += d; }
  // The bound grown by how far any point of wall w can move in a step of dt [s] with its velocity,
  // radial velocity and spin (a spinning plane: unbounded, the list is rebuilt).
  void add_wall_motion(const Wall& w, double dt);
  // A bound on the largest travel of a ball since the rebuild [m]: exact after a measuring pass over
  // the positions (set_travel_bound; 0 at a rebuild), then grown by each record motion by the step's
  // largest |V| Δt (grow_travel_bound). A bound within the limit gives the exact check's answer
  // without a pass over the positions.
  double travel_bound() const { return travel_bound_; }
  void set_travel_bound(double travel) { travel_bound_ = travel; }
  void grow_travel_bound(double growth) {
    travel_bound_ += growth;
    motion_bound_ = true;
  }
  // Whether the bound was grown by this step's motion; cleared by the call.
  bool take_motion_bound() {
    const bool grown = motion_bound_;
    motion_bound_ = false;
    return grown;
  }

  // Per ball a: its ball-ball rows first_rows()[a] .. [a + 1] (piece 1); the rows where it is piece 2,
  // late_rows()[late_rows_start()[a] .. [a + 1]]; its wall rows wall_rows()[wall_rows_start()[a] ..
  // [a + 1]]. wall_rows(): every ball-wall row, in row order.
  const std::vector<std::uint32_t>& first_rows() const { return first_rows_; }
  const std::vector<std::uint32_t>& late_rows_start() const { return late_rows_start_; }
  const std::vector<std::uint32_t>& late_rows() const { return late_rows_; }
  const std::vector<std::uint32_t>& wall_rows_start() const { return wall_rows_start_; }
  const std::vector<std::uint32_t>& wall_rows() const { return wall_rows_; }
  std::size_t row_span() const { return row_span_; }  // the largest b − a of a ball-ball row

  std::int64_t rebuilds() const { return rebuilds_; }
  std::size_t unassigned_pairs() const { return unassigned_pairs_; }
  bool rebuild_needed() const { return rebuild_needed_; }
  double wall_travel() const { return wall_travel_; }
  // Put back the bookkeeping of a checkpoint (Simulation::restore_cycle_state).
  void restore(bool rebuild_needed, std::int64_t rebuilds, std::size_t unassigned_pairs,
               std::vector<Vec3> position_at_build, double wall_travel) {
    rebuild_needed_ = rebuild_needed;
    rebuilds_ = rebuilds;
    unassigned_pairs_ = unassigned_pairs;
    position_at_build_ = std::move(position_at_build);
    wall_travel_ = wall_travel;
  }

 private:
  bool rebuild_needed_ = true;
  std::size_t unassigned_pairs_ = 0;
  std::int64_t rebuilds_ = 0;
  std::vector<Vec3> position_at_build_;  // [m]
  double wall_travel_ = 0.0;             // [m]
  double travel_bound_ = 0.0;            // [m]
  bool motion_bound_ = false;
  std::vector<std::uint32_t> first_rows_;
  std::vector<std::uint32_t> late_rows_start_;
  std::vector<std::uint32_t> late_rows_;
  std::vector<std::uint32_t> wall_rows_start_;
  std::vector<std::uint32_t> wall_rows_;
  std::size_t row_span_ = 0;
};

}  // namespace hilldem
