// ForcePass: §1.2 step 4, the force-displacement law of every row and the balls' and walls' sums.
//
// Blocks of balls, each with its own rows (ball-ball rows are sorted by their first ball); each row
// writes only its own columns. Each thread takes a range of balls of equal work (WorkSplit) in
// blocks from its start, and runs the blocks from the last down (run_range). Every ball's force is
// summed in one order whatever the ranges: its ball-ball rows in descending row order, then its
// wall rows in row order. The pair loop runs over the balls a of a range from its last ball down,
// through a's ball-ball rows (NeighbourList::first_rows: keys are sorted by kind, then a, then
// b > a) from the last down, and adds each row's share to a and to b: b's own rows came before
// (b > a), and every row (x, b) with x < a comes after. A row whose b lies beyond the thread's range
// leaves b's share in a crossing list, added in descending row order once the thread's own rows are
// done (by b's thread): those rows (x below the range of b's thread) come last in b's order. Then
// the wall rows. So results depend neither on the blocks (ContactBatch::pad_lanes) nor on the
// thread count; the first failing row is found by a min-reduction, for the same reason.
//
// Existing hill and linear ball-ball contacts go through the batches (engine/contact_batch.hpp),
// whose lanes run the same law templates (models/) as force_row, the path of every other row.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/bodies/wall_store.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/engine/ball_records.hpp"
#include "hilldem/engine/contact_batch.hpp"
#include "hilldem/engine/hill_param_sets.hpp"
#include "hilldem/engine/live_rows.hpp"
#include "hilldem/engine/neighbour_list.hpp"
#include "hilldem/engine/row_results.hpp"
#include "hilldem/engine/simulation_settings.hpp"
#include "hilldem/engine/stiffness_sums.hpp"
#include "hilldem/engine/work_split.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

// What a force pass reads and writes, owned by the Simulation (pointers: a Simulation may move).
struct PassWorld {
  BallStore* balls = nullptr;
  WallStore* walls = nullptr;
  ContactStore* contacts = nullptr;
  const ModelTable* table = nullptr;
  const SimulationSettings* settings = nullptr;
  NeighbourList* neighbours = nullptr;
  BallRecords* kin = nullptr;       // current: filled before the pass (Simulation::prepare_pass)
  LiveRows* live = nullptr;         // made before the pass, if it visits them
  WorkSplit* split = nullptr;
  HillParamSets* hill_sets = nullptr;
  StiffnessSums* stiffness = nullptr;
};

// Active row c's share in its wall's sums (force, moment about the wall's rotation centre, normal
// force and stiffness, active contacts), from the row's results and its ball at `position` [m] of
// `radius` [m]. A wall's sums are these shares added in row order from zero: the force pass, and the
// ranks of a domain decomposition over the rows of all ranks (parallel/domain.cpp).
void add_wall_row(Wall& w, const ContactStore& contacts, std::size_t c, const Vec3& position, double radius);
// That share, and its addition: add_wall_row(w, ...) is add_wall_share(w, wall_row_share(w, ...)),
// so that a rank can send the shares of its balls' rows to the others (parallel/domain.cpp).
struct WallShare {
  Vec3 force;                     // [N]
  Vec3 moment;                    // [N m] about the wall's rotation centre
  double normal_force = 0.0;      // [N]
  double normal_stiffness = 0.0;  // [N/m]
};
WallShare wall_row_share(const Wall& w, const ContactStore& contacts, std::size_t c, const Vec3& position, double radius);
void add_wall_share(Wall& w, const WallShare& s);
// The sums add_wall_row adds to, zeroed.
void clear_wall_sums(Wall& w);

// How one pass runs.
struct PassOptions {
  double dt = 0.0;                // Δt [s] of the shear increments (0: forces at the current state)
  bool write_results = true;      // the reported columns too (Simulation::cycle)
  std::int64_t step = 0;          // steps done (for the error message)
  const std::vector<double>* thread_shares = nullptr;  // given shares of the work (Simulation::thread_shares)
  std::size_t balls_per_block = 128;
};

class ForcePass {
 public:
  // The pass: every row's law, the balls' sums (ended) and the walls'. Throws RunError on a
  // non-finite force, naming the row.
  void run(const PassWorld& world, const PassOptions& options);
  // The rows changed (a rebuild, a restore): what the pass keeps per row or per split is made again.
  void rows_changed(std::size_t rows);
  // Rows that went through the batched law in the last pass.
  std::int64_t batched_rows() const { return batched_rows_; }

 private:
  // What one thread reuses from block to block.
  struct BlockScratch {
    ContactBatch hill, linear;
  };
  struct Block;  // one force_block call's state (force_block.cpp)

  // The law of one row (any model and kind), written into its columns; the share both bodies get.
  RowShare force_row(std::size_t c, double dt);
  // Thread t's part: its blocks, its crossing list (crossing_done[t] once final; late_share: a
  // share came after), the crossing shares into its balls, its wall rows.
  void run_range(std::size_t t, BlockScratch& scratch, std::atomic<bool>* crossing_done, std::atomic<bool>& late_share,
                 std::size_t& bad_row, std::int64_t& batched);
  // The rows of balls a0..a1-1 (ball-ball), summed into both balls; a second ball at or beyond
  // range_end (outside this thread's range) gets its share in `crossing`. bad_row: the lowest row
  // with a non-finite force; batched: + the rows that went through a batch.
  void force_block(std::size_t a0, std::size_t a1, std::size_t range_end, BlockScratch& scratch,
                   std::vector<CrossShare>& crossing, std::size_t& bad_row, std::int64_t& batched);
  // Within force_block: ball a's rows k1 − 1 down to k0 of a row sequence, its live records, and a
  // batch's law with its results into the rows and the balls.
  template <class RowAt>
  void block_rows(Block& blk, std::size_t a, std::size_t k1, std::size_t k0, RowAt row_at);
  void block_records(Block& blk, std::size_t a);
  void flush(Block& blk, ContactBatch& batch);
  void scatter_lane(Block& blk, ContactBatch& batch, std::size_t lane);
  std::size_t scatter_simple_hill_lanes(Block& blk, ContactBatch& batch);
  void add_to_balls(Block& blk, std::size_t a, std::size_t b, const Vec3& force, const Vec3& moment1,
                    const Vec3& moment2, double k_tran, double k_shear, double gap);
  void add_share(Block& blk, std::size_t c, const RowShare& s);
  void prefetch_ball(const Block& blk, std::size_t a) const;
  // The wall rows k0..k1 (of NeighbourList::wall_rows): existing linear contacts that touch their
  // wall through a linear batch (the wall's geometry given), the rest row by row (force_row). Each
  // row's results go to its columns and share_moment_; collect_forces() sums them in row order, so
  // the batches need no order.
  void wall_block(std::size_t k0, std::size_t k1, BlockScratch& scratch, std::size_t& bad_row, std::int64_t& batched);
  // The lowest ball of balls first..last-1 with a ball-ball row into a later range (last: none).
  std::size_t crossing_floor(std::size_t first, std::size_t last) const;
  // The shares of `list` into balls first..last-1, in list order; the wall rows k0..k1 into their
  // balls, in row order (both with their stiffness terms when those are summed).
  void add_crossing(const std::vector<CrossShare>& list, std::size_t first, std::size_t last);
  void add_wall_rows(std::size_t k0, std::size_t k1);
  // The walls' sums (the balls' sums were ended by the pass's threads).
  void collect_forces();
  [[noreturn]] void throw_bad_row(std::size_t bad_row) const;
  bool want_stiffness() const { return w_.settings->auto_timestep || w_.settings->density_scaling; }

  PassWorld w_;    // (set by run)
  PassOptions o_;
  std::int64_t batched_rows_ = 0;
  std::vector<Vec3> share_moment_;                 // [N m] moment of wall row r on its ball
  std::vector<std::vector<CrossShare>> crossing_;  // per thread of the last pass
  // Per range of the split, its lowest ball with a ball-ball row into a later range: below it the
  // range's thread adds no crossing share. Made once per split and row lists.
  std::vector<std::size_t> crossing_floor_;
  static constexpr std::size_t kFloorUnknown = ~std::size_t{0};
};

}  // namespace hilldem
