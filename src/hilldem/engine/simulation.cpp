#include "hilldem/engine/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <numeric>

#include "hilldem/core/error.hpp"
#include "hilldem/engine/contact_mapping.hpp"
#include "hilldem/engine/model_dispatch.hpp"
#include "hilldem/engine/thread_budget.hpp"
#include "hilldem/motion/ball_step.hpp"
#include "hilldem/motion/law_of_motion.hpp"
#include "hilldem/motion/rigid_body.hpp"

namespace hilldem {


void Simulation::cycle(std::int64_t n) { cycle(n, {}); }

std::int64_t Simulation::cycle(std::int64_t n, const std::function<bool()>& stop) {
  // drive() with a plan that sets nothing: stop() asked before each cycle's law of motion.
  return drive(n, [&stop](double) { return stop && stop(); });
}

std::int64_t Simulation::drive(std::int64_t n, const std::function<bool(double)>& plan) {
  drop_records();  // the caller may have changed the columns since the last call
  for (std::int64_t k = 0; k < n; ++k) {
    const bool interrupted = interrupt && interrupt();
    steps_ahead_ = n - 1 - k;  // (at most: plan may end the call sooner)
    const bool last = step_once(k + 1 == n || interrupted, &plan);
    if (interrupted) throw_interrupted();
    if (last) {
      steps_ahead_ = 0;
      return k + 1;
    }
  }
  steps_ahead_ = 0;
  return n;
}

std::int64_t Simulation::solve(double ratio, std::int64_t max_steps) {
  // At least one cycle: forces may be stale (make_wet changes them only on the next cycle, §2.7).
  drop_records();
  for (std::int64_t k = 1; k <= max_steps; ++k) {
    const bool interrupted = interrupt && interrupt();
    step_once(true);  // the ratio reads the contact results
    if (mean_unbalanced_ratio() <= ratio) return k;
    if (interrupted) throw_interrupted();
  }
  return -1;
}

void Simulation::throw_interrupted() const {
  char t[32];
  std::snprintf(t, sizeof t, "%.6g", time);
  throw Interrupted("stopped on request after step " + std::to_string(steps) + " (time " + t + " s)");
}

void Simulation::update_forces() {
  drop_records();
  if (!clumps.empty()) {
    clumps.check(balls);
    clumps.place_pebbles(balls);  // (bitwise what they hold when the clumps placed them last)
  }
  rebuild_if_needed();
  write_results_ = true;
  force_pass(0.0);
  forces_ready_ = true;
}

double Simulation::next_timestep() const {
  if (!settings.auto_timestep) return settings.timestep;
  const double dt = estimate_timestep();
  if (dt > 0.0) return std::min(dt, settings.timestep_max);
  return last_dt > 0.0 ? last_dt : settings.timestep_max;
}

double Simulation::skin() const {
  if (settings.skin > 0.0) return settings.skin;
  if (skin_known_) return skin_;  // (a serial sum over the radii: kept while the radii cannot change)
  if (balls.size() == 0) return 0.0;
  const double sum = std::accumulate(balls.radius.begin(), balls.radius.end(), 0.0);
  return 0.1 * 2.0 * sum / static_cast<double>(balls.size());
}

bool Simulation::step_once(bool last, const std::function<bool(double)>* plan) {
  try {
    return step_body(last, plan);
  } catch (...) {
    sync_ball_columns();  // the state where the run stopped, for whoever catches this
    if (live_.records_ready()) live_.sync_records(contacts);
    throw;
  }
}

bool Simulation::step_body(bool last, const std::function<bool(double)>* plan) {
  apply_thread_budget();  // when several simulations share the cores (engine/thread_budget.hpp)
  if (!forces_ready_) update_forces();
  const double dt = next_timestep();
  if (plan && (*plan)(dt)) last = true;  // (it sets walls only: the records stay)
  // The reported results of ball-ball contacts, and the balls' columns, only when someone may read
  // them (see cycle()).
  const bool watched = last || !observers.empty() || !controllers.empty();
  write_results_ = watched;
  if (!controllers.empty()) drop_records();  // they may set the columns' velocities
  for (const auto& control : controllers) control(*this, dt);  // servos set wall velocities
  const double* m_scaled = nullptr;
  const double* i_scaled = nullptr;
  if (settings.density_scaling) {
    stiffness_.scaled_masses(balls, contacts, neighbours_, dt / settings.timestep_safety, scaled_mass_, scaled_inertia_);
    m_scaled = scaled_mass_.data();
    i_scaled = scaled_inertia_.data();
  }
  // §1.2 steps 1-2
  if (!clumps.empty()) {
    if (m_scaled) throw RunError("density scaling does not apply to clumps (docs/clumps.md): switch it off");
    advance_with_clumps(dt);
  } else if (ball_kin_.current() && ball_kin_.size() == balls.size()) {
    advance_records(dt, m_scaled, i_scaled, watched);
  } else {
    drop_records();
    advance_balls(balls, MotionSettings{settings.gravity, settings.local_damping}, dt, m_scaled, i_scaled,
                  ball_kin_.contact_sums(balls.size()));
  }
  for (Wall& w : walls.walls) {
    neighbours_.add_wall_motion(w, dt);
    advance_wall(w, dt);
  }
  if (domain) {  // the ghosts' motion is their owners' (the law of motion here had only part of their forces)
    drop_records();
    domain->after_motion(*this);
  }
  rebuild_if_needed();  // step 3
  force_pass(dt);       // steps 3-4
  time += dt;
  ++steps;
  last_dt = dt;
  for (const auto& obs : observers) obs(*this);
  return last;
}

void Simulation::advance_with_clumps(double dt) {
  // On the columns, so that the travel since the neighbour list and the live rows is measured
  // exactly (rebuild_if_needed): a pebble's motion is its clump's turn, not its own V Δt.
  if (settings.box.any())
    throw RunError("clumps in a periodic box are not supported (docs/clumps.md): a pebble's image would part from its clump");
  drop_records();
  const motion::ContactSums* sums = ball_kin_.contact_sums(balls.size());
  advance_balls(balls, MotionSettings{settings.gravity, settings.local_damping}, dt, nullptr, nullptr, sums);
  clumps.advance(balls, sums, RigidMotionSettings{settings.gravity, settings.local_damping}, dt);
}

ContactGeometry Simulation::geometry(std::size_t c) const {
  // (Between steps the columns hold the positions; within an unwatched step the records.)
  auto position = [&](std::size_t i) -> const Vec3& { return ball_kin_.columns_stale() ? ball_kin_[i].position : balls.position[i]; };
  const ContactKey& k = contacts.key[c];
  const bool pair = k.kind == ContactKind::BallBall;
  return contact_geometry(contacts, c, position(k.a), balls.radius[k.a], pair ? position(k.b) : Vec3{},
                          pair ? balls.radius[k.b] : 0.0, walls, settings.box);
}

void Simulation::refresh_mappings() {
  body_terms_ready_ = false;
  for (std::size_t c = 0; c < contacts.size(); ++c) compute_mapping(balls, contacts, c);
  refresh_timestep_stiffness();
}

void Simulation::refresh_timestep_stiffness() {
  // The contacts' forces stay those of the last cycle (spec §2.7: F^m changes on the next cycle),
  // but the time step of that cycle queries every contact active now with its present properties
  // (spec §4), so each existing row's activity, gap and stiffness columns are its model's answer now.
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (!contacts.exists[c]) continue;
    const ContactGeometry g = geometry(c);
    const TimestepStiffness k = g.valid ? timestep_stiffness(contacts, c, g.gap) : TimestepStiffness{};
    contacts.active[c] = k.active;
    if (g.valid) contacts.gap[c] = g.gap;
    contacts.k_tran[c] = k.k_tran;
    contacts.k_shear[c] = k.k_shear;
  }
  stiffness_.ready = false;  // the sums from the rows (StiffnessSums::of_ball)
}

void Simulation::advance_records(double dt, const double* inertial_mass, const double* inertial_inertia,
                                 bool write_columns) {
  // The travel since the live rows is measured ball by ball (the check's expression), or bounded
  // without it while the bound, grown by four steps like the last, stays within the slack; that
  // since the neighbour list only bounded (NeighbourList::travel_bound, no reference position read),
  // exactly by rebuild_if_needed when the bound reaches half the skin.
  const std::size_t n = balls.size();
  const bool live_list = live_.has_positions(n);
  const bool bounded = live_list && live_.bound_holds();
  const bool live = live_list && !bounded;
  const BallRecords::Motion moved =
      ball_kin_.advance(balls, settings.gravity, settings.local_damping, dt, inertial_mass, inertial_inertia,
                        write_columns, split_.shares(), live, live_.positions());
  // No ball moved farther than |V|max Δt this step, but for the rounding of x + V Δt (below
  // 2.3e-16 |x| a step) and of |V|: a margin of 1e-9 of the first and 1e-15 |x|max [m]. A NaN stays.
  const double growth = std::sqrt(moved.max_v2) * dt * (1.0 + 1e-9) + 1e-15 * std::sqrt(moved.max_x2);
  neighbours_.grow_travel_bound(growth);
  live_.after_motion(live_list, live, bounded, moved.worst_live, growth);
}

bool Simulation::rebuild_due() {
  const bool measured = neighbours_.take_motion_bound();  // by advance_records, this step
  if (!neighbours_.stale(balls.size())) {
    if (ball_kin_.current() && !skin_known_) {  // (the radii stay until the records are dropped)
      skin_ = skin();
      skin_known_ = true;
    }
    const double half = 0.5 * skin();
    // A pair outside the list was farther than `skin` beyond proximity at the rebuild. The record
    // motion's bound first: the exact travel is at most the bound, so a bound within the limit gives
    // the exact check's answer without a pass over the positions (a NaN bound fails, and goes on).
    if (measured && neighbours_.holds(neighbours_.travel_bound(), half)) return false;
    // The largest travel since the rebuild, exactly, and since the live rows were made, while they are.
    const bool live = live_.has_positions(balls.size());
    const auto [worst, worst_live] =
        ball_kin_.largest_travel2(balls, neighbours_.position_at_build().data(), live, live_.positions());
    live_.measured(live, worst_live);
    const double ball_travel = std::sqrt(worst);
    neighbours_.set_travel_bound(ball_travel);  // (exact now: the record motion grows it from here)
    if (neighbours_.holds(ball_travel, half)) return false;
  }
  return true;
}

void Simulation::rebuild_if_needed() {
  bool due = rebuild_due();
  if (domain) due = domain->rebuild_anywhere(due);  // (every rank rebuilds at the same step)
  if (!due) return;
  drop_records();  // the rebuild reads the columns, and wraps the positions into a periodic box
  if (domain) {
    if (live_.records_ready()) live_.sync_records(contacts);  // (the rows travel with their history)
    domain->before_rebuild(*this);
  }
  rebuild(settings.proximity);
}

void Simulation::rebuild(double proximity) {
  if (live_.records_ready()) live_.sync_records(contacts);  // (the rows are made anew, their history by key)
  const double reach = proximity + skin();
  neighbours_.rebuild(contacts, balls, walls, table, settings.box, reach, steps,
                      [this](ContactStore& store, std::size_t c) { compute_mapping(balls, store, c); },
                      clumps.clump_of_balls(balls.size()));
  build_row_lists();
  neighbours_.built(balls.position);
  body_terms_ready_ = false;
}

void Simulation::build_row_lists() {
  neighbours_.build_row_lists(contacts, balls.size());
  // What the force pass keeps per row or per ball of these rows, made again.
  pass_.rows_changed(contacts.size());
  live_.invalidate();
  stiffness_.reset(balls.size());
}

CycleState Simulation::cycle_state() const {
  const NeighbourList& list = neighbours_;
  return {forces_ready_,         list.rebuild_needed(),    list.rebuilds(), list.unassigned_pairs(),
          list.position_at_build(), list.wall_travel()};
}

void Simulation::restore_cycle_state(CycleState s) {
  if (!s.position_at_build.empty() && s.position_at_build.size() != balls.size())
    throw RunError("cycle state for " + std::to_string(s.position_at_build.size()) + " balls, the simulation has " +
                   std::to_string(balls.size()));
  for (const ContactKey& k : contacts.key)
    if (k.a >= balls.size() || (k.kind == ContactKind::BallBall && k.b >= balls.size()) ||
        (k.kind == ContactKind::BallWall && k.b >= walls.size()))
      throw RunError("cycle state: a contact row refers to a body that does not exist");
  // The force pass finds a ball's rows by position in the sorted list (NeighbourList::first_rows).
  for (std::size_t c = 1; c < contacts.size(); ++c)
    if (!(contacts.key[c - 1] < contacts.key[c])) throw RunError("cycle state: contact rows are not sorted by key");
  if (!clumps.empty()) clumps.check(balls);
  forces_ready_ = s.forces_ready;
  ball_kin_.forget_sums();  // the restored columns hold the sums the next step moves with
  const bool rebuild_needed = s.rebuild_needed || s.position_at_build.empty();  // (before the move below)
  neighbours_.restore(rebuild_needed, s.rebuilds, static_cast<std::size_t>(s.unassigned_pairs),
                      std::move(s.position_at_build), s.wall_travel);
  if (!rebuild_needed && !s.rows_complete)
    neighbours_.restore_rows(contacts, balls, walls, table, settings.box, settings.proximity + skin(),
                             [this](ContactStore& store, std::size_t c) { compute_mapping(balls, store, c); },
                             clumps.clump_of_balls(balls.size()));
  body_terms_ready_ = false;
  build_row_lists();
}


void Simulation::refresh_live_rows() {
  live_.refresh(contacts, ball_kin_.data(), neighbours_.first_rows().data(), balls.size(), settings.proximity,
                settings.box, skin());
}

void Simulation::force_pass(double dt) {
  ball_kin_.begin_sums(balls.size());  // (not current until the pass has added every share)
  prepare_pass();
  body_terms_ready_ = true;
  live_.count_pass();
  const PassWorld world{&balls, &walls,     &contacts, &table,      &settings,  &neighbours_,
                        &ball_kin_, &live_, &split_,   &hill_sets_, &stiffness_};
  pass_.run(world, PassOptions{dt, write_results_, steps, &thread_shares, balls_per_block});
  if (domain) domain->after_forces(*this);
}

void Simulation::prepare_pass() {
  // The ball records, the hill parameter sets and the live rows (and their records) the pass reads.
  const std::size_t rows = contacts.size();
  const std::size_t n = balls.size();
  const bool terms_ready = body_terms_ready_ && ball_kin_.size() == n;
  if (!terms_ready || hill_sets_.stale(rows)) {
    if (live_.records_ready()) live_.sync_records(contacts);  // (the records hold the rows' sets)
    hill_sets_.refresh(contacts, table);
  }
  if (ball_kin_.size() != n) drop_records();
  // What the pair loop reads of each ball, in one record (two cache lines): the position, velocity
  // and spin from the columns unless the records hold them already (advance_records, or an earlier
  // pass in this step); the hill terms (four divisions per ball) only when the properties may have
  // changed: at a rebuild, refresh_mappings() or a restore, the moments at which the row-by-row
  // path's mappings are computed too (real masses, §2.4). (Within a cycle() call nothing but a
  // controller changes a radius, and a controller drops the records.)
  if (!ball_kin_.current() || !terms_ready) ball_kin_.fill(balls, !ball_kin_.current(), !terms_ready);
  // The live rows, made again when a ball may have moved more than the slack since they were
  // (rebuild_if_needed measured it), or the rows, their models or the proximity may have changed. (A
  // contact made since, in any pass, was a live row: the others were too far apart to touch.) Not
  // while each contact's shear displacement is tracked: every row then goes through force_row.
  live_.set_visited(!settings.track_shear_displacement);
  if (!terms_ready || !live_.made_for(rows, settings.proximity)) live_.invalidate();
  if (live_.visited() && !live_.current()) refresh_live_rows();
  live_.end_pass_measure();
  // The live rows through their records on the steps nobody looks at, made when at least
  // kRecordSteps more steps follow in this cycle() call: making them and writing them back costs
  // about half a step, which the faster steps win back in about eight (docs/performance.md).
  constexpr std::int64_t kRecordSteps = 8;
  const bool records = live_.visited() && !write_results_;
  if (live_.records_ready() && !records) live_.sync_records(contacts);
  if (records && !live_.records_ready() && steps_ahead_ >= kRecordSteps)
    live_.build_records(contacts, hill_sets_.row_sets(), n);
  live_.count_record_pass();
}


double Simulation::estimate_timestep() const {
  // Per-body sums of the contact-returned stiffnesses (spec §4; hill Eqs. 19-21, linear k_n, k_s),
  // stored by the last force pass.
  double crit = stiffness_.critical_timestep(balls, contacts, neighbours_);
  if (!clumps.empty()) {
    std::vector<double> k_tran(clumps.ball.size()), k_rot(clumps.ball.size());
    for (std::size_t k = 0; k < k_tran.size(); ++k)
      stiffness_.of_ball(clumps.ball[k], balls, contacts, neighbours_, k_tran[k], k_rot[k]);
    crit = std::min(crit, std::sqrt(clumps.critical_timestep2(k_tran, k_rot)));
  }
  if (domain) crit = domain->min_over_ranks(crit);  // (+inf where a rank has no contact)
  return std::isfinite(crit) ? settings.timestep_safety * crit : 0.0;
}

std::size_t Simulation::make_wet(double suction, double gap) {
  rebuild(std::max(gap, settings.proximity));  // step 1: every pair within the gap has a row
  neighbours_.invalidate();                     // back to the normal reach at the next cycle
  std::size_t wet = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.model[c] != ModelKind::Hill) continue;
    const ContactGeometry g = geometry(c);
    if (g.gap <= gap) {  // steps 2-3: a contact (new ones start here), suction, then make_wet(g_m)
      if (!contacts.exists[c]) create_contact(table, balls, hill_sets_, contacts, c, g.normal);
      contacts.hill_params[c].suction = suction;
      contacts.moisture[c] = Moisture::Wet;
    }
    if (contacts.exists[c] && contacts.moisture[c] == Moisture::Wet) ++wet;
  }
  refresh_timestep_stiffness();
  return wet;
}

std::size_t Simulation::make_dry() {
  std::size_t was_wet = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.model[c] != ModelKind::Hill || !contacts.exists[c]) continue;
    if (contacts.moisture[c] == Moisture::Wet) ++was_wet;
    contacts.moisture[c] = Moisture::Dry;
  }
  refresh_timestep_stiffness();
  return was_wet;
}

long Simulation::find_ball_ball(std::int64_t id1, std::int64_t id2) const {
  long a = balls.find(id1), b = balls.find(id2);
  if (a < 0 || b < 0) return -1;
  if (a > b) std::swap(a, b);
  const long c = contacts.find({static_cast<std::uint32_t>(a), ContactKind::BallBall, static_cast<std::uint32_t>(b)});
  return c >= 0 && contacts.exists[c] ? c : -1;
}

long Simulation::find_ball_wall(std::int64_t ball_id, std::size_t wall) const {
  const long a = balls.find(ball_id);
  if (a < 0) return -1;
  const long c = contacts.find({static_cast<std::uint32_t>(a), ContactKind::BallWall, static_cast<std::uint32_t>(wall)});
  return c >= 0 && contacts.exists[c] ? c : -1;
}

void Simulation::sort_balls_spatially() {
  if (contact_count() > 0) throw RunError("sort_balls_spatially: only before any contact exists");
  if (balls.size() < 2) return;
  const std::vector<std::uint32_t> order = spatial_order(balls);
  balls.permute(order);
  clumps.balls_permuted(order);
  contacts.clear();
  invalidate_forces();
}

}  // namespace hilldem
