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
#include "hilldem/engine/clump_bodies.hpp"
#include "hilldem/engine/equilibrium.hpp"
#include "hilldem/engine/force_pass.hpp"
#include "hilldem/engine/hill_param_sets.hpp"
#include "hilldem/engine/live_rows.hpp"
#include "hilldem/engine/neighbour_list.hpp"
#include "hilldem/engine/simulation_settings.hpp"
#include "hilldem/engine/stiffness_sums.hpp"
#include "hilldem/engine/work_split.hpp"
#include "hilldem/models/model_table.hpp"
#include "hilldem/motion/ball_step.hpp"
#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

class Simulation;

// One rank's part of a domain decomposition (parallel/domain.hpp, docs/mpi.md): the Simulation then
// holds the balls this rank owns and the ghost copies of its neighbours' balls near them, in the
// relative order of the whole run, and calls these at the points of the cycle where ranks
// must agree. Null (the default): the Simulation is the whole run.
class DomainHooks {
 public:
  virtual ~DomainHooks() = default;
  // After the law of motion (the columns hold the state): the ghosts get their owners' motion.
  virtual void after_motion(Simulation& sim) = 0;
  // Whether any rank's balls call for a rebuild, given this rank's answer (the same on every rank).
  virtual bool rebuild_anywhere(bool here) = 0;
  // Before a rebuild (columns and rows current): balls move to their new owners with their rows,
  // and the ghosts are made again. May replace every ball and row of `sim`.
  virtual void before_rebuild(Simulation& sim) = 0;
  // After the force pass: the walls' sums made the whole run's (each rank's pass counted its ghosts'
  // wall rows too), the same on every rank.
  virtual void after_forces(Simulation& sim) = 0;
  // The smallest of every rank's x (exact in any order): the whole run's critical time step [s] from
  // each rank's (spec §4; a ghost's, from part of its rows, is never below its owner's).
  virtual double min_over_ranks(double x) = 0;
};

class Simulation {
 public:
  BallStore balls;
  WallStore walls;
  ContactStore contacts;
  ModelTable table;
  GroupNames groups;
  SimulationSettings settings;
  // Clumps (docs/clumps.md): rigid bodies whose pebbles are rows of `balls`, moved by their clump.
  // After adding clumps (ClumpBodies::add), call invalidate_forces().
  ClumpBodies clumps;

  double time = 0.0;        // [s]
  std::int64_t steps = 0;   // cycles done
  double last_dt = 0.0;     // [s] Δt of the last cycle

  // Called after every cycle (histories, progress).
  std::vector<std::function<void(const Simulation&)>> observers;
  // Called at the start of every cycle with its Δt [s], before the law of motion, with the forces
  // at t: servos and other controllers set wall or ball velocities here. While any is registered
  // every cycle writes its results (a controller may read them); servos that read and set only walls
  // run in the plan of drive() instead, as the lab tests' do.
  std::vector<std::function<void(Simulation&, double)>> controllers;
  // The domain decomposition this Simulation is one rank's part of, or null (see DomainHooks).
  DomainHooks* domain = nullptr;

  // Run n cycles. The contacts' reported results (ContactStore gap, force, normal_force,
  // moisture_force, trial_shear, active) are those of the last cycle when it returns, and of every
  // cycle for the observers and controllers while any is registered; between those, the batched
  // ball-ball contacts skip writing them (memory traffic: on the 100,800-sphere bench, whose cycles
  // nobody watches). The history and everything the next cycle uses are written on every cycle, and
  // the balls' force sums do not read these columns, so results do not depend on it (test
  // ContactResults.WrittenOnTheLastCycleAndForObservers).
  void cycle(std::int64_t n);
  // The same, asking stop() before each cycle: once it returns true, that cycle is the last one
  // (its results written, as at the end of cycle(k)). Returns the cycles run, k ≤ n; the state is
  // bitwise that of cycle(k), so a caller can answer an interruption (the Python module: Ctrl-C)
  // without cutting a long run into many calls, each of which rebuilds the cycle's records.
  std::int64_t cycle(std::int64_t n, const std::function<bool()>& stop);
  // Up to n cycles for a driver that decides between cycles on what the walls and the clock say:
  // the lab tests' servo loops (PFC's servo FISH functions). Before each cycle's law of motion,
  // with the forces at t, plan(dt) is called with that cycle's Δt [s]: it may set the walls'
  // velocities (as a controller does) and read the walls (position, force sums), time and steps,
  // nothing else (the balls' columns and the contacts' reported results are those of the last
  // cycle that wrote them); it returns true when this cycle must be the call's last, the one whose
  // results are written as at the end of cycle(k). The cycles in between run as within cycle(n),
  // unwatched, unless observers or controllers are registered. Returns the cycles run. A driver
  // that needs the specimen's contacts after some cycle plans that cycle as the last: the
  // same bits as cycle(1) after each, at the cost of the cycles that write everything
  // (docs/lab-tests.md, "Where the time goes").
  std::int64_t drive(std::int64_t n, const std::function<bool(double dt)>& plan);
  // Cycle (at least once) until the mean unbalanced-force ratio is ≤ ratio; returns the cycles
  // used, or -1 if max_steps passed first. (Every cycle's contact results are written.)
  std::int64_t solve(double ratio, std::int64_t max_steps);
  // When set, asked before every cycle of cycle() and solve(): once it answers true, that cycle is
  // the last (its results written, as at the end of cycle(k)) and the call throws Interrupted. For
  // drivers that run many calls of their own (the lab tests): their CLI commands set it to answer
  // SIGINT, SIGTERM and SIGHUP, so a test stops between two cycles with a message. Copied with the
  // Simulation; not part of its state (checkpoints, digests).
  std::function<bool()> interrupt;

  // Δt the next cycle will use [s].
  double next_timestep() const;
  // f·Δt_crit from the contact stiffnesses (spec §4, hill Eqs. 19-21), or 0 if no contact reports one.
  double estimate_timestep() const;
  // PFC's mechanical ratio-average [-]: mean unbalanced-force magnitude over free bodies (balls and
  // clumps) / mean applied-force magnitude over the same bodies (their contacts' |F_c| and weight).
  double mean_unbalanced_ratio() const {
    return hilldem::mean_unbalanced_ratio(balls, contacts, settings.gravity, clumps.empty() ? nullptr : &clumps);
  }

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
  std::int64_t batched_rows() const { return pass_.batched_rows(); }

  // Recompute every contact's mapping, and the per-ball terms and parameter sets the batched hill
  // law reads, after properties of bodies or contacts changed (radius, density, E, ν, a contact's
  // μ, γ_h, ψ: the cycle does not watch them), and the stiffnesses the next Δt is estimated from.
  void refresh_mappings();
  // Rebuild the neighbour list before the next force evaluation (after bodies were added or moved
  // by hand, or the table changed).
  void invalidate_neighbours() { neighbours_.invalidate(); }
  // The skin [m]: settings.skin, or (0 there) a tenth of the mean diameter.
  double skin() const;
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
  // row lists are rebuilt from the current rows (no detection; with rows_complete false, the
  // neighbour rows that are not contacts made again as the last rebuild made them). Throws RunError
  // if the state does not fit the balls.
  void restore_cycle_state(CycleState s);

  ContactGeometry geometry(std::size_t c) const;
  // Contact between balls with user ids, or between a ball and a wall (index); -1 if none.
  long find_ball_ball(std::int64_t id1, std::int64_t id2) const;
  long find_ball_wall(std::int64_t ball_id, std::size_t wall) const;
  // Candidate pairs that matched no assignment rule at the last detection.
  std::size_t unassigned_pairs() const { return neighbours_.unassigned_pairs(); }

 private:
  [[noreturn]] void throw_interrupted() const;
  // One cycle; `last`: the last of a cycle() call (its contact results are written).
  // One cycle; `plan` (drive()) may make it the last. Returns whether it was.
  bool step_once(bool last, const std::function<bool(double)>* plan = nullptr);
  bool step_body(bool last, const std::function<bool(double)>* plan);  // step_once's work (step_once syncs the columns if it throws)
  // §1.2 steps 1-2 with clumps: the balls on the columns, then the clumps, which place their pebbles.
  void advance_with_clumps(double dt);
  void rebuild(double reach);
  void build_row_lists();  // the neighbour list's row lists, and the force pass's per-row state
  void rebuild_if_needed();
  bool rebuild_due();  // whether this Simulation's balls or walls call for a rebuild
  // Each existing row's activity and time-step stiffness now (after make_wet, make_dry, new
  // properties), for the next cycle's Δt.
  void refresh_timestep_stiffness();
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
  // Before the force pass: the ball records, the hill parameter sets, the live rows (and records).
  void prepare_pass();

  bool forces_ready_ = false;
  bool write_results_ = true;  // this force pass writes the reported columns (step_once)
  NeighbourList neighbours_;  // the rows, their per-ball lists, when to rebuild (engine/neighbour_list.hpp)
  // Per ball, what the pair loop reads (BallKin), the law of motion on it, and the force sums
  // (engine/ball_records.hpp).
  BallRecords ball_kin_;
  // Within one cycle() call nothing but a controller changes the radii, and a controller drops the
  // records: skin_ holds until drop_records().
  bool skin_known_ = false;
  double skin_ = 0.0;  // [m] skin() while skin_known_
  WorkSplit split_;  // the threads' ranges of balls in the force pass
  bool body_terms_ready_ = false;  // ball_kin_[i].terms are up to date (see prepare_pass)
  HillParamSets hill_sets_;        // the hill parameters the batched pass reads, by set
  StiffnessSums stiffness_;        // per ball, the stiffness sums of the last force pass
  std::vector<double> scaled_mass_, scaled_inertia_;  // density scaling [kg], [kg m²]
  // The rows the force pass visits, and their records (engine/live_rows.hpp).
  LiveRows live_;
  void refresh_live_rows();
  ForcePass pass_;  // §1.2 step 4 (engine/force_pass.hpp)
  std::int64_t steps_ahead_ = 0;  // steps of the current cycle() call after this one
};

}  // namespace hilldem
