// Simulation: owns the stores, the assignment table and the clock, and runs the cycle of spec §1.2:
//   1. velocities to t+Δt/2 from the forces at t (local damping, gravity, fixity),
//   2. positions to t+Δt, walls moved by their imposed motion,
//   3. contact detection and resolution at the new positions: the neighbour list (pairs within
//      proximity + skin) is rebuilt only when something moved more than half the skin, history
//      kept by a sorted merge; contacts are created and deleted on it by proximity,
//   4. force-displacement law of every contact -> forces at t+Δt (existing ball-ball contacts in
//      vectorised batches, engine/contact_batch.hpp), summed per ball in one fixed order (its
//      ball-ball rows in descending row order, then its wall rows), so results are bitwise
//      identical for any number of threads.
// Lab-test drivers and the scenario runner use only this public API.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/bodies/wall_store.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/engine/ball_records.hpp"
#include "hilldem/engine/contact_batch.hpp"
#include "hilldem/engine/live_rows.hpp"
#include "hilldem/engine/neighbour_list.hpp"
#include "hilldem/engine/work_split.hpp"
#include "hilldem/models/model_table.hpp"
#include "hilldem/motion/ball_step.hpp"
#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

struct SimulationSettings {
  Vec3 gravity;                  // [m/s²]
  double local_damping = 0.0;    // α [-], [0, 1)
  bool auto_timestep = true;     // Δt from the stiffness estimate (spec §4) or fixed
  double timestep = 1e-6;        // [s] fixed Δt (when auto_timestep is false)
  double timestep_safety = 0.8;  // f [-], Δt = f Δt_crit
  double timestep_max = 1e-4;    // [s] Δt used when no contact reports a stiffness yet
  double proximity = 0.0;        // [m] contacts are created for gaps ≤ proximity
  double skin = 0.0;             // [m] neighbour-list skin; 0 = 0.1 × mean ball diameter
  // Density scaling (as PFC): with a fixed Δt, each ball's inertial mass and inertia are raised to
  // what that Δt needs for stability, m' = max(m, k_tran (Δt/f)²), I' = max(I, k_rot (Δt/f)²).
  // Static equilibria are unchanged; dynamics are not physical. For quasi-static runs only.
  bool density_scaling = false;
  // Accumulate each contact's relative shear displacement (ContactStore::shear_disp). A reported
  // quantity that no law uses: off by default, on when a scenario records contact.shear_disp.
  bool track_shear_displacement = false;
  PeriodicBox box;               // periodic directions and their period [lo, hi) [m]
};

// Geometry of a contact at the current positions.
struct ContactGeometry {
  Vec3 normal;        // n̂_c, piece 1 -> piece 2
  double gap = 0.0;   // g_c [m]
  Vec3 point;         // x_c [m]
  bool valid = true;  // false: a ball beyond a cylinder's end (no contact possible)
};

// The cycle's private bookkeeping, for checkpoints: with it a restored run rebuilds its neighbour
// list at the very steps the saved run would have (which matters with periodic boxes, where the
// rebuild wraps positions into the box).
struct CycleState {
  bool forces_ready = false;
  bool rebuild_needed = true;
  std::int64_t rebuilds = 0;
  std::uint64_t unassigned_pairs = 0;
  std::vector<Vec3> position_at_build;  // [m] ball positions at the last rebuild
  double wall_travel = 0.0;             // [m] bound on wall motion since then
};

class Simulation {
 public:
  BallStore balls;
  WallStore walls;
  ContactStore contacts;
  ModelTable table;
  GroupNames groups;
  SimulationSettings settings;

  double time = 0.0;        // [s]
  std::int64_t steps = 0;   // cycles done
  double last_dt = 0.0;     // [s] Δt of the last cycle

  // Called after every cycle (histories, progress).
  std::vector<std::function<void(const Simulation&)>> observers;
  // Called at the start of every cycle with its Δt [s], before the law of motion, with the forces
  // at t: servos and other controllers set wall or ball velocities here.
  std::vector<std::function<void(Simulation&, double)>> controllers;

  // Run n cycles. The contacts' reported results (ContactStore gap, force, normal_force,
  // moisture_force, trial_shear, active) are those of the last cycle when it returns, and of every
  // cycle for the observers and controllers while any is registered; between those, the batched
  // ball-ball contacts skip writing them (memory traffic: on the 100,800-sphere bench, whose cycles
  // nobody watches). The history and everything the next cycle uses are written on every cycle, and
  // the balls' force sums do not read these columns, so results do not depend on it (test
  // ContactResults.WrittenOnTheLastCycleAndForObservers).
  void cycle(std::int64_t n);
  // Cycle (at least once) until the mean unbalanced-force ratio is ≤ ratio; returns the cycles
  // used, or -1 if max_steps passed first. (Every cycle's contact results are written.)
  std::int64_t solve(double ratio, std::int64_t max_steps);

  // Δt the next cycle will use [s].
  double next_timestep() const;
  // f·Δt_crit from the contact stiffnesses (spec §4, hill Eqs. 19-21), or 0 if no contact reports one.
  double estimate_timestep() const;
  // Mean unbalanced force over free balls / mean contact force over active contacts [-]; a contact's
  // force counts as |F^s_n n̂ + F_s| + |F^m|.
  double mean_unbalanced_ratio() const;

  // Material-level wetting (spec §2.7): contacts for every ball pair within gap [m] (new ones
  // included), suction [Pa] on their hill contacts, make_wet(gap) on every hill contact. Returns the
  // number of wet contacts after the call.
  std::size_t make_wet(double suction, double gap);
  // make_dry on every hill contact; returns how many were wet.
  std::size_t make_dry();

  // How often the live rows were made (the rows the force pass visits: contacts, rows of other models
  // than hill, and the hill neighbour pairs within proximity + 2 s when the list was made; remade when
  // a ball has moved more than the slack s since).
  std::int64_t live_row_refreshes() const { return live_.refreshes(); }
  // How many force passes ran through the live records.
  std::int64_t live_record_passes() const { return live_.record_passes(); }
  // Given shares of the work per thread (one per thread, normalised) instead of those measured from
  // the threads' speeds: for tests, and for cores of known speeds. Results do not depend on them.
  std::vector<double> thread_shares;
  // Balls per block of the force pass (a block's contacts fill the batches together; blocks are
  // the unit of work of the threads). A tuning knob only: results do not depend on it (the batches
  // pad their lanes, ContactBatch::pad_lanes). 128: docs/performance.md.
  static constexpr std::size_t kDefaultBallsPerBlock = 128;
  std::size_t balls_per_block = kDefaultBallsPerBlock;
  // Rows that went through the batched law in the last force pass.
  std::int64_t batched_rows() const { return batched_rows_; }

  // Recompute every contact's mapping, and the per-ball terms and parameter sets the batched hill
  // law reads, after properties of bodies or contacts changed (radius, density, E, ν, a contact's
  // μ, γ_h, ψ: the cycle does not watch them).
  void refresh_mappings();
  // Rebuild the neighbour list before the next force evaluation (after bodies were added or moved
  // by hand, or the table changed).
  void invalidate_neighbours() { neighbours_.invalidate(); }
  // Number of contacts (rows that exist), and of neighbour-list rebuilds so far.
  std::size_t contact_count() const { return contacts.count_existing(); }
  std::int64_t rebuilds() const { return neighbours_.rebuilds(); }
  // Reorder balls along the cell grid for memory locality. Only before any contact exists.
  void sort_balls_spatially();
  // Forces are recomputed (without any shear increment) before the next cycle: call after moving
  // bodies by hand.
  void invalidate_forces() {
    forces_ready_ = false;
    ball_kin_.invalidate_sums();
    body_terms_ready_ = false;
    neighbours_.invalidate();
  }
  // Detect contacts and compute forces at the current state with no motion (Δt = 0 increments).
  void update_forces();

  CycleState cycle_state() const;
  // Put back a saved CycleState, with the contact rows and ball columns it was saved with: the per-ball
  // row lists are rebuilt from the current rows (no detection, no merge). Throws RunError if the
  // state does not fit the balls.
  void restore_cycle_state(CycleState s);

  ContactGeometry geometry(std::size_t c) const;
  // Contact between balls with user ids, or between a ball and a wall (index); -1 if none.
  long find_ball_ball(std::int64_t id1, std::int64_t id2) const;
  long find_ball_wall(std::int64_t ball_id, std::size_t wall) const;
  // Candidate pairs that matched no assignment rule at the last detection.
  std::size_t unassigned_pairs() const { return neighbours_.unassigned_pairs(); }

 private:
  // One cycle; `last`: the last of a cycle() call (its contact results are written).
  void step_once(bool last);
  void step_body(bool last);  // step_once's work (step_once syncs the columns if it throws)
  void rebuild(double reach);
  void build_row_lists();  // the neighbour list's row lists, and the force pass's per-row state
  void rebuild_if_needed();
  void force_pass(double dt);
  // The law of motion on the records, with each ball's travel since the
  // neighbour list (and since the live rows) measured as it moves; write_columns: the BallStore's
  // columns too.
  void advance_records(double dt, const double* inertial_mass, const double* inertial_inertia, bool write_columns);
  // The columns from the records, if the records are ahead of them.
  void sync_ball_columns() { ball_kin_.sync_columns(balls); }
  // From now on the columns hold the balls' state (synced first): before anything that may read or
  // write them (a controller, a rebuild, the start of a cycle() call).
  void drop_records() {
    ball_kin_.drop(balls);
    skin_known_ = false;
  }
  // What a row gives its two bodies (zero when the row is not an active contact).
  struct RowShare {
    Vec3 force;    // on piece 1: −F_c [N] (piece 2 gets F_c = −force)
    Vec3 moment;   // on piece 1: −(R_1 + g/2) n̂_c × F_c [N m]
    Vec3 moment2;  // on piece 2 (or, for a wall row, on its ball): −(R_2 + g/2) n̂_c × F_c [N m]
    // What the row adds to the stiffness sums (when the time step needs them): k̂_n + k̂_s, k̂_s
    // [N/m] (zero when not an active contact) and the gap [m] (add_stiffness).
    double k_tran = 0.0, k_shear = 0.0, gap = 0.0;
    bool ok = true;  // false on a non-finite force
    // Zero the forces and moments, and the stiffness terms when they are read, field by field:
    // `force = moment = Vec3{}` reloads the moment just stored and stalls store forwarding.
    void clear(bool stiffness) {
      force = Vec3{};
      moment = Vec3{};
      moment2 = Vec3{};
      if (stiffness) {
        k_tran = 0.0;
        k_shear = 0.0;
        gap = 0.0;
      }
    }
  };
  // A ball-ball row whose second ball lies beyond the range of the thread that ran it: its share of
  // that ball, added after the parallel pass (see force_pass).
  struct CrossShare {
    std::uint32_t b;
    Vec3 force, moment;
    double k_tran, k_shear, gap;
  };
  // The force-displacement law of one row (any model and kind). Writes the row's columns; the
  // returned share holds what both bodies get.
  RowShare force_row(std::size_t c, double dt);
  // A row's result, from either law path (row by row or batched).
  struct RowOutcome {
    Vec3 normal;                  // n̂_c
    double gap = 0.0;             // g_c [m]
    // [m] the radii of the moments' arms R + g/2 (contact_moments): of the pair loop's ball and of the
    // body that collects the second share (a wall row's: its ball's, as the wall's arm is 0)
    double r1 = 0.0, r2 = 0.0;
    Vec3 force;                   // F_c [N] (zero if inactive)
    Vec3 shear;                   // shear force carried to the next step [N]
    double normal_force = 0.0, moisture_force = 0.0, trial_shear = 0.0;  // [N]
    double k_tran = 0.0, k_shear = 0.0;  // [N/m], written only when the time step needs them
    Vec3 moment;                  // contact moment M_c on piece 2 [N m] (rrlinear; zero for other models)
    bool wall_row = false;        // (for M_c's share: a wall row's second share is its ball's)
    Moisture moisture = Moisture::Dry;
    bool active = false;
  };
  // Write a row's result into its columns, or delete the contact if it is inactive beyond proximity
  // (spec §2.5); and the pair loop's share into `share`. reported: also the columns that only
  // reports read (see cycle()).
  void store_row(std::size_t c, const RowOutcome& out, bool want_stiffness, bool reported, RowShare& share);
  // The inputs of a batch's lanes (ball-ball rows of force_block), from their rows and the records of
  // their two balls, when the batch runs.
  void fill_lanes(ContactBatch& batch, bool hill) const;
  void fill_ball_lanes(ContactBatch& batch, bool hill) const;  // what the lanes read of their balls
  void fill_row_lanes(ContactBatch& batch, bool hill) const;   // and of their rows
  // A batch lane's results as a row outcome (wall_row: a ball-wall lane of wall_block).
  RowOutcome lane_outcome(const ContactBatch& batch, std::size_t lane, bool wall_row) const;
  // store_row for a lane that the lanes marked kQuick (the contact stays, its force is finite):
  // the same columns, straight from the lanes. The shares come from the lanes too (kMax.., kMbx..).
  void store_kept_lane(std::size_t c, const ContactBatch& batch, std::size_t lane, bool want_stiffness, bool reported,
                       bool history = true);
  // What one thread reuses from block to block.
  struct BlockScratch {
    ContactBatch hill, linear;
  };
  // The rows of balls a0..a1-1 (ball-ball), summed into both balls (see force_pass for the order);
  // a second ball at or beyond range_end (outside this thread's range) gets its share in `crossing`.
  // bad_row: the lowest row with a non-finite force; batched: + the rows that went through a batch.
  void force_block(std::size_t a0, std::size_t a1, std::size_t range_end, double dt, BlockScratch& scratch,
                   std::vector<CrossShare>& crossing, std::size_t& bad_row, std::int64_t& batched);
  // Before the force pass's threads start: the ball records, the hill parameter sets, the live rows.
  void prepare_pass();
  // Thread t's part of the force pass (force_pass): its blocks, its crossing list (crossing_done[t]
  // once final; late_share: a share came after), the crossing shares into its balls, its wall rows.
  void run_range(std::size_t t, double dt, BlockScratch& scratch, std::atomic<bool>* crossing_done,
                 std::atomic<bool>& late_share, std::size_t& bad_row, std::int64_t& batched);
  // The lowest ball of balls first..last-1 with a ball-ball row into a later range (last: none).
  std::size_t crossing_floor(std::size_t first, std::size_t last) const;
  // RunError for the row with a non-finite force.
  [[noreturn]] void throw_bad_row(std::size_t bad_row) const;
  // The wall rows k0..k1 (of NeighbourList::wall_rows): existing linear contacts that touch their
  // wall through a linear batch (the wall's geometry given), the rest row by row (force_row). Each
  // row's results go to its columns and share_moment_; collect_forces() sums them in row order, so
  // the batches need no order.
  void wall_block(std::size_t k0, std::size_t k1, double dt, BlockScratch& scratch, std::size_t& bad_row,
                  std::int64_t& batched);
  // The walls' sums (the balls' sums were ended by the pass's threads: force_pass).
  void collect_forces();
  // The shares of `list` into balls first..last-1, in list order; the wall rows k0..k1 into their
  // balls, in row order (both with their stiffness terms when those are summed).
  void add_crossing(const std::vector<CrossShare>& list, std::size_t first, std::size_t last);
  void add_wall_rows(std::size_t k0, std::size_t k1);
  void compute_mapping(ContactStore& store, std::size_t c) const;
  // Row c becomes a contact (created by proximity) with its rule's properties.
  void create_contact(std::size_t c, const Vec3& normal);
  // Σ over ball i's active contacts: k_tran = Σ(k̂_n + k̂_s) [N/m], k_rot = Σ k̂_s |x_c − x|² [N m].
  void ball_stiffness(std::size_t i, double& k_tran, double& k_rot) const;
  // Row c's terms of those sums for a ball of the given radius [m] (if the row is an active contact).
  void add_row_stiffness(std::size_t c, double radius, double& k_tran, double& k_rot) const;
  double skin() const;

  bool forces_ready_ = false;
  bool write_results_ = true;  // this force pass writes the reported columns (step_once)
  std::int64_t batched_rows_ = 0;
  NeighbourList neighbours_;  // the rows, their per-ball lists, when to rebuild (engine/neighbour_list.hpp)
  // The force sum, in one order for any thread count (so any thread count gives the same bits): a
  // ball's ball-ball rows in descending row order, then its wall rows in row order. The pair loop
  // runs over the balls a of a thread's range from its last ball down, through a's ball-ball rows
  // (NeighbourList::first_rows: keys are sorted by kind, then a, then b > a) from the last down,
  // and adds each row's share to a and to b: b's own rows came before (b > a), and every row (x, b)
  // with x < a comes after. A row whose b lies beyond the thread's range leaves b's share in
  // crossing_, added in descending row order once the thread's own rows are done (by b's thread):
  // those rows (x below the range of b's thread) come last in b's order. Then the wall rows, from
  // F_c and share_moment_.
  std::vector<Vec3> share_moment_;           // [N m] moment of wall row r on its ball
  std::vector<std::vector<CrossShare>> crossing_;  // per thread of the last force pass
  // Per range of the split, its lowest ball with a ball-ball row into a later range: below it the
  // range's thread adds no crossing share (force_pass). Made once per split and row lists.
  std::vector<std::size_t> crossing_floor_;
  static constexpr std::size_t kFloorUnknown = ~std::size_t{0};
  // Per ball, Σ(k̂_n + k̂_s) [N/m] and Σ k̂_s |x_c − x|² [N m] of the last force pass (in the order of
  // the forces), valid while stiffness_ready_.
  std::vector<double> ball_k_tran_, ball_k_rot_;
  bool stiffness_ready_ = false;
  // Per ball, what the pair loop reads (BallKin), the law of motion on it, and the force sums
  // (engine/ball_records.hpp).
  BallRecords ball_kin_;
  // Within one cycle() call nothing but a controller changes the radii, and a controller drops the
  // records: skin_ holds until drop_records().
  bool skin_known_ = false;
  double skin_ = 0.0;  // [m] skin() while skin_known_
  WorkSplit split_;  // the threads' ranges of balls in the force pass
  bool body_terms_ready_ = false;            // ball_kin_[i].terms are up to date (see force_pass)
  // The hill parameters the batched pass reads, by set: row c's are hill_sets_[row_hill_set_[c]], the
  // distinct parameters of the rows and the rules (a few: the rules', and what make_wet and stages
  // gave): a 4-byte index per row instead of the 24-byte parameters, for the pair loop's memory
  // traffic. Made from contacts.hill_params (which stays the record) whenever the mappings
  // are (refresh_param_sets: at a rebuild, refresh_mappings(), a restore); create_contact() sets its
  // row's, and flags the sets stale if its rule's parameters are not the set made for the rule.
  std::vector<HillParams> hill_sets_;
  std::vector<std::uint32_t> row_hill_set_;   // per row
  std::vector<std::uint32_t> rule_hill_set_;  // per assignment rule
  bool hill_sets_stale_ = true;  // (set by create_contact from the pass's threads: std::atomic_ref)
  void refresh_param_sets();
  std::vector<double> scaled_mass_, scaled_inertia_;  // density scaling [kg], [kg m²]
  // The rows the force pass visits, and their records (engine/live_rows.hpp).
  LiveRows live_;
  void refresh_live_rows();
  std::int64_t steps_ahead_ = 0;  // steps of the current cycle() call after this one
};

}  // namespace hilldem
