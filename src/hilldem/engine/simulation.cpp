#include "hilldem/engine/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>

#include "hilldem/core/error.hpp"
#include "hilldem/engine/contact_mapping.hpp"
#include "hilldem/engine/model_dispatch.hpp"
#include "hilldem/engine/thread_budget.hpp"
#include "hilldem/motion/ball_step.hpp"

namespace hilldem {


void Simulation::cycle(std::int64_t n) {
  drop_records();  // the caller may have changed the columns since the last call
  for (std::int64_t k = 0; k < n; ++k) {
    steps_ahead_ = n - 1 - k;  // (whether the live records pay: force_pass)
    step_once(k + 1 == n);
  }
  steps_ahead_ = 0;
}

std::int64_t Simulation::solve(double ratio, std::int64_t max_steps) {
  // At least one cycle: forces may be stale (make_wet changes them only on the next cycle, §2.7).
  drop_records();
  for (std::int64_t k = 1; k <= max_steps; ++k) {
    step_once(true);  // the ratio reads the contact results
    if (mean_unbalanced_ratio() <= ratio) return k;
  }
  return -1;
}

void Simulation::update_forces() {
  drop_records();
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

void Simulation::step_once(bool last) {
  try {
    step_body(last);
  } catch (...) {
    sync_ball_columns();  // the state where the run stopped, for whoever catches this
    if (live_.records_ready()) live_.sync_records(contacts);
    throw;
  }
}

void Simulation::step_body(bool last) {
  // The reported results of ball-ball contacts, and the balls' columns, only when someone may read
  // them (see cycle()).
  const bool watched = last || !observers.empty() || !controllers.empty();
  write_results_ = watched;
  apply_thread_budget();  // when several simulations share the cores (engine/thread_budget.hpp)
  if (!forces_ready_) update_forces();
  const double dt = next_timestep();
  if (!controllers.empty()) drop_records();  // they may set the columns' velocities
  for (const auto& control : controllers) control(*this, dt);  // servos set wall velocities
  const double* m_scaled = nullptr;
  const double* i_scaled = nullptr;
  if (settings.density_scaling) {
    const std::size_t n = balls.size();
    scaled_mass_.resize(n);
    scaled_inertia_.resize(n);
    const double want = dt / settings.timestep_safety;  // Δt/f
#pragma omp parallel for schedule(static) if (n > kParallelMin)
    for (std::size_t i = 0; i < n; ++i) {
      double k_tran, k_rot;
      stiffness_.of_ball(i, balls, contacts, neighbours_, k_tran, k_rot);
      scaled_mass_[i] = std::max(balls.mass[i], k_tran * want * want);
      scaled_inertia_[i] = std::max(balls.inertia[i], k_rot * want * want);
    }
    m_scaled = scaled_mass_.data();
    i_scaled = scaled_inertia_.data();
  }
  // §1.2 steps 1-2
  if (ball_kin_.current() && ball_kin_.size() == balls.size()) {
    advance_records(dt, m_scaled, i_scaled, watched);
  } else {
    drop_records();
    advance_balls(balls, MotionSettings{settings.gravity, settings.local_damping}, dt, m_scaled, i_scaled,
                  ball_kin_.contact_sums(balls.size()));
  }
  for (Wall& w : walls.walls) {
    // Bound on how far any point of the wall moved (for the neighbour-list check).
    double reach = 0.0;
    if (w.shape == WallShape::Facet)
      for (const Vec3& v : w.vertex) reach = std::max(reach, norm(v - w.rotation_center));
    else if (w.shape == WallShape::Plane && norm2(w.spin) > 0.0)
      reach = std::numeric_limits<double>::infinity();
    if (norm2(w.spin) > 0.0) neighbours_.add_wall_travel(norm(w.spin) * dt * reach);
    neighbours_.add_wall_travel((norm(w.velocity) + std::abs(w.radial_velocity)) * dt);
    advance_wall(w, dt);
  }
  rebuild_if_needed();  // step 3
  force_pass(dt);       // steps 3-4
  time += dt;
  ++steps;
  last_dt = dt;
  for (const auto& obs : observers) obs(*this);
}

ContactGeometry Simulation::geometry(std::size_t c) const {
  const ContactKey& k = contacts.key[c];
  // (Between steps the columns hold the positions; within an unwatched step the records.)
  auto position = [&](std::size_t i) -> const Vec3& { return ball_kin_.columns_stale() ? ball_kin_[i].position : balls.position[i]; };
  const Vec3& x1 = position(k.a);
  const double r1 = balls.radius[k.a];
  ContactGeometry g;
  if (k.kind == ContactKind::BallBall) {
    Vec3 x2 = position(k.b);
    if (contacts.image[c] != kNoImage) x2 += image_shift(contacts.image[c], settings.box);
    const Vec3 d = x2 - x1;
    const double dist = norm(d);
    g.normal = dist > 0.0 ? d / dist : contacts.normal[c];  // coincident centres: keep the old normal
    g.gap = dist - r1 - balls.radius[k.b];
  } else {
    const auto touch = wall_touch(walls.walls[k.b], x1, r1);
    if (!touch) {
      g.valid = false;
      g.normal = contacts.normal[c];
      g.gap = std::numeric_limits<double>::infinity();
      g.point = x1;
      return g;
    }
    g.normal = touch->normal;
    g.gap = touch->gap;
  }
  g.point = x1 + g.normal * (r1 + 0.5 * g.gap);  // centre of the gap/overlap (spec §1.1)
  return g;
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

void Simulation::rebuild_if_needed() {
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
    if (measured && neighbours_.holds(neighbours_.travel_bound(), half)) return;
    // The largest squared travel since the rebuild [m²], exactly; a NaN wins (not std::max, which
    // would drop it). Parallel: the maximum does not depend on the order, and a NaN asks for a
    // rebuild, which ends the run (NeighbourList::rebuild). And the largest since the live rows were
    // made, while they are. (The positions from the records when the columns lag behind them.)
    const std::size_t n = balls.size();
    const bool from_records = ball_kin_.columns_stale();
    const bool live = live_.has_positions(n);
    const Vec3* at_live = live_.positions();
    const Vec3* at_build = neighbours_.position_at_build().data();
    double worst = 0.0, worst_live = 0.0;
#pragma omp parallel if (n > kParallelMin)
    {
      double mine = 0.0, mine_live = 0.0;
#pragma omp for schedule(static) nowait
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3& x = from_records ? ball_kin_[i].position : balls.position[i];
        const double d2 = norm2(x - at_build[i]);
        if (!(d2 <= mine)) mine = d2;
        if (live) {
          const double l2 = norm2(x - at_live[i]);
          if (!(l2 <= mine_live)) mine_live = l2;
        }
      }
#pragma omp critical(hilldem_rebuild_check)
      {
        if (!(mine <= worst)) worst = mine;
        if (!(mine_live <= worst_live)) worst_live = mine_live;
      }
    }
    live_.measured(live, worst_live);
    const double ball_travel = std::sqrt(worst);
    neighbours_.set_travel_bound(ball_travel);  // (exact now: the record motion grows it from here)
    if (neighbours_.holds(ball_travel, half)) return;
  }
  drop_records();  // the rebuild reads the columns, and wraps the positions into a periodic box
  rebuild(settings.proximity);
}

void Simulation::rebuild(double proximity) {
  if (live_.records_ready()) live_.sync_records(contacts);  // (the rows are made anew, their history by key)
  const double reach = proximity + skin();
  neighbours_.rebuild(contacts, balls, walls, table, settings.box, reach, steps,
                      [this](ContactStore& store, std::size_t c) { compute_mapping(balls, store, c); });
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
  forces_ready_ = s.forces_ready;
  ball_kin_.forget_sums();  // the restored columns hold the sums the next step moves with
  const bool rebuild_needed = s.rebuild_needed || s.position_at_build.empty();  // (before the move below)
  neighbours_.restore(rebuild_needed, s.rebuilds, static_cast<std::size_t>(s.unassigned_pairs),
                      std::move(s.position_at_build), s.wall_travel);
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
  const double crit = stiffness_.critical_timestep(balls, contacts, neighbours_);
  return std::isfinite(crit) ? settings.timestep_safety * crit : 0.0;
}

double Simulation::mean_unbalanced_ratio() const {
  // PFC's mechanical ratio-average (spec lab-tests §3.4): the mean over free bodies of the
  // unbalanced-force magnitude over the mean over the same bodies of the applied-force magnitude,
  // that is the sum over a body's active contacts of |F_c| plus its weight m |g|. A contact's force
  // counts as |F^s_n n̂ + F_s| + |F^m|, the magnitudes of its parts: a wet contact in equilibrium
  // carries a Hertz force and an equal and opposite moisture force, and its net force is zero.
  const std::size_t n = balls.size();
  std::vector<double> applied(n, 0.0);
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (!contacts.active[c]) continue;
    const double fn = contacts.normal_force[c];
    const double f = std::sqrt(fn * fn + norm2(contacts.shear_force(c))) + std::abs(contacts.moisture_force[c]);
    const ContactKey& k = contacts.key[c];
    applied[k.a] += f;
    if (k.kind == ContactKind::BallBall) applied[k.b] += f;
  }
  const double g = norm(settings.gravity);
  double unbalanced = 0.0, applied_sum = 0.0;
  std::size_t free_balls = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const FixityMask fix = balls.fixity[i];
    if ((fix & kFixVel) == kFixVel) continue;
    Vec3 f = unbalanced_force(balls, i, settings.gravity);
    for (int d = 0; d < 3; ++d)
      if (fix & (1u << d)) f[d] = 0.0;
    unbalanced += norm(f);
    applied_sum += applied[i] + balls.mass[i] * g;
    ++free_balls;
  }
  if (free_balls == 0) return 0.0;
  if (applied_sum == 0.0) return unbalanced > 0.0 ? 1.0 : 0.0;
  return unbalanced / applied_sum;  // the two means share the divisor free_balls
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
  const std::size_t n = balls.size();
  if (n < 2) return;
  // Order by cell of a grid one mean diameter wide (z, then y, then x).
  Vec3 lo = balls.position[0], hi = lo;
  for (const Vec3& x : balls.position)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
  const double cell = std::max(2.0 * std::accumulate(balls.radius.begin(), balls.radius.end(), 0.0) / n, 1e-12);
  auto cell_index = [&](const Vec3& x) {
    const auto c = [&](int d) { return static_cast<std::uint64_t>((x[d] - lo[d]) / cell); };
    const std::uint64_t nx = c(0) + 1;
    const std::uint64_t ny = static_cast<std::uint64_t>((hi.y - lo.y) / cell) + 1;
    const std::uint64_t mx = static_cast<std::uint64_t>((hi.x - lo.x) / cell) + 1;
    return (c(2) * ny + c(1)) * mx + (nx - 1);
  };
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t p, std::uint32_t q) {
    return cell_index(balls.position[p]) < cell_index(balls.position[q]);
  });
  balls.permute(order);
  contacts.clear();
  invalidate_forces();
}

}  // namespace hilldem
