#include "hilldem/engine/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <thread>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/engine/contact_batch.hpp"
#include "hilldem/engine/thread_budget.hpp"
#include "hilldem/models/lanes.hpp"
#include "hilldem/models/rrlinear.hpp"
#include "hilldem/motion/ball_step.hpp"

namespace hilldem {

namespace {
// A row's terms of a ball's stiffness sums: k_tran += k̂_n + k̂_s, k_rot += k̂_s |x_c − x|² with
// |x_c − x| = R + g/2 (the contact point is on the normal). One expression for the force pass and
// for add_row_stiffness, so that both round (and contract into multiply-adds) alike.
HILLDEM_INLINE void add_stiffness(double k_tran_row, double k_shear, double radius, double gap, double& k_tran,
                                  double& k_rot) {
  const double arm = radius + 0.5 * gap;
  k_tran += k_tran_row;
  k_rot += k_shear * arm * arm;
}

// Hill parameters by their bits (refresh_param_sets: a set holds exactly its rows' parameters).
std::array<std::uint64_t, 3> param_bits(const HillParams& p) {
  return {std::bit_cast<std::uint64_t>(p.fric_coef), std::bit_cast<std::uint64_t>(p.damp_con),
          std::bit_cast<std::uint64_t>(p.suction)};
}
bool same_bits(const HillParams& x, const HillParams& y) { return param_bits(x) == param_bits(y); }
}  // namespace

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
      ball_stiffness(i, k_tran, k_rot);
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

void Simulation::compute_mapping(ContactStore& store, std::size_t c) const {
  const ContactKey& k = store.key[c];
  switch (store.model[c]) {
    case ModelKind::Linear:
    case ModelKind::RrLinear: {  // (the linear springs; R̄ of rrlinear is taken in force_row)
      const double r2 = k.kind == ContactKind::BallBall ? balls.radius[k.b] : 0.0;
      store.linear_map[c] = linear_mapping(store.linear_params[c], balls.radius[k.a], r2);
      break;
    }
    case ModelKind::Hill: {
      const std::size_t a = k.a, b = k.b;  // hill contacts are ball-ball only (checked by the table)
      store.hill_map[c] = hill_mapping(store.hill_params[c],
                                       HillBodies{balls.radius[a], balls.radius[b], balls.young_mod[a],
                                                  balls.young_mod[b], balls.pois_ratio[a], balls.pois_ratio[b],
                                                  balls.mass[a], balls.mass[b]});
      break;
    }
  }
}

void Simulation::create_contact(std::size_t c, const Vec3& normal) {
  // A new contact takes its properties from its assignment rule, as a row new to the neighbour list
  // does: what an earlier contact of the same pair was given (make_wet's suction, a set_contact
  // stage) is gone with it, and the result does not depend on when the list was rebuilt.
  const ModelRule& rule = table.rules[static_cast<std::size_t>(contacts.rule[c])];
  if (contacts.model[c] == ModelKind::Hill) {
    contacts.hill_params[c] = rule.hill;
    // The row's parameter set: its rule's, if that set still holds the rule's parameters (the table
    // may have changed since the sets were made); else all sets are made again before the next pass
    // reads them (this row goes through force_row in this one).
    const auto r = static_cast<std::size_t>(contacts.rule[c]);
    if (c < row_hill_set_.size() && r < rule_hill_set_.size() && same_bits(hill_sets_[rule_hill_set_[r]], rule.hill))
      row_hill_set_[c] = rule_hill_set_[r];
    else
      std::atomic_ref<bool>(hill_sets_stale_).store(true, std::memory_order_relaxed);
  } else {
    contacts.linear_params[c] = rule.linear;
  }
  compute_mapping(contacts, c);
  contacts.create(c, normal);
}

void Simulation::refresh_param_sets() {
  if (live_.records_ready()) live_.sync_records(contacts);  // (the records hold the rows' sets)
  // The distinct parameters, told apart by their bits, so that each row's set holds exactly its
  // parameters. Rows mostly share their neighbour's set: one comparison, and a map lookup only when
  // the parameters change along the rows.
  std::map<std::array<std::uint64_t, 3>, std::uint32_t> index;
  hill_sets_.clear();
  auto intern = [&](const HillParams& p) {
    const auto [it, added] = index.try_emplace(param_bits(p), static_cast<std::uint32_t>(hill_sets_.size()));
    if (added) hill_sets_.push_back(p);
    return it->second;
  };
  rule_hill_set_.resize(table.rules.size());
  for (std::size_t r = 0; r < table.rules.size(); ++r) rule_hill_set_[r] = intern(table.rules[r].hill);
  const std::size_t rows = contacts.size();
  row_hill_set_.assign(rows, 0);
  if (hill_sets_.empty()) hill_sets_.push_back(HillParams{});  // (no rules: every row's index is valid)
  std::uint32_t last = 0;
  for (std::size_t c = 0; c < rows; ++c) {
    if (contacts.model[c] != ModelKind::Hill) continue;
    const HillParams& p = contacts.hill_params[c];
    if (!same_bits(hill_sets_[last], p)) last = intern(p);
    row_hill_set_[c] = last;
  }
  hill_sets_stale_ = false;
}

void Simulation::refresh_mappings() {
  body_terms_ready_ = false;
  for (std::size_t c = 0; c < contacts.size(); ++c) compute_mapping(contacts, c);
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
                      [this](ContactStore& store, std::size_t c) { compute_mapping(store, c); });
  build_row_lists();
  neighbours_.built(balls.position);
  body_terms_ready_ = false;
}

void Simulation::build_row_lists() {
  neighbours_.build_row_lists(contacts, balls.size());
  // What the force pass keeps per row or per ball of these rows, made again.
  crossing_floor_.clear();
  share_moment_.assign(contacts.size(), Vec3{});
  live_.invalidate();
  ball_k_tran_.assign(balls.size(), 0.0);
  ball_k_rot_.assign(balls.size(), 0.0);
  stiffness_ready_ = false;
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

// One row, any model and kind (the general path).
Simulation::RowShare Simulation::force_row(std::size_t c, double dt) {
  const double proximity = settings.proximity;
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  const PeriodicBox& box = settings.box;
  // The balls' state from their records (current in the force pass; the columns may lag behind).
  const BallKin* rec = ball_kin_.data();
  const double* rad = balls.radius.data();
  const ContactKey key = contacts.key[c];
  const std::size_t a = key.a;
  const bool ball2 = key.kind == ContactKind::BallBall;
  const Vec3 x1 = rec[a].position;
  const double r1 = rad[a];

  // Geometry (spec §1.1). Neighbour pairs that are not contacts are rejected before any sqrt.
  using lanes::v3;
  Vec3 normal;
  double gap;
  if (ball2) {
    Vec3 x2 = rec[key.b].position;
    if (contacts.image[c] != kNoImage) x2 += image_shift(contacts.image[c], box);
    const Vec3 d = x2 - x1;
    if (!contacts.exists[c]) {
      const double reach = r1 + rad[key.b] + proximity;
      if (norm2(d) > reach * reach) return {};  // a neighbour pair, not a contact
    }
    const PairGeometry<double> g = ball_pair_geometry(v3(d), r1, rad[key.b], v3(contacts.normal[c]));
    normal = lanes::vec3(g.normal);
    gap = g.gap;
  } else {
    const auto touch = wall_touch(walls.walls[key.b], x1, r1);
    if (!touch && !contacts.exists[c]) return {};
    normal = touch ? touch->normal : contacts.normal[c];
    gap = touch ? touch->gap : std::numeric_limits<double>::infinity();
    if (!contacts.exists[c] && gap > proximity) return {};
  }
  if (!contacts.exists[c]) create_contact(c, normal);  // created by proximity

  // Relative velocity of the material points at x_c (spec §1.2); a wall is body 2 with the arm 0
  // (r2 = −g/2) and its surface velocity at x_c = x1 + (R1 + g/2) n̂.
  RowOutcome out;
  out.normal = normal;
  out.gap = gap;
  out.r1 = r1;
  out.r2 = ball2 ? rad[key.b] : r1;  // (a wall row's second share is its ball's: wall_block)
  const double r2 = ball2 ? rad[key.b] : -0.5 * gap;
  Vec3 v2, spin2;
  if (ball2) {
    v2 = rec[key.b].velocity;
    spin2 = rec[key.b].spin;
  } else {
    v2 = wall_point_velocity(walls.walls[key.b], x1 + normal * (r1 + 0.5 * gap));
    spin2 = walls.walls[key.b].spin;
  }
  const Vec3 rel = lanes::vec3(contact_velocity(v3(normal), gap, r1, r2, v3(rec[a].velocity), v3(rec[a].spin),
                                                v3(v2), v3(spin2)));
  const ContactKinematics kin{normal, gap, rel, dt};
  const double mean_spin = 0.5 * dot(rec[a].spin + spin2, normal);  // ½(ω1 + ω2)·n̂ [rad/s] (§1.3)
  const Vec3 carried = carry_into_plane(contacts.shear_state[c], contacts.normal[c], normal, mean_spin, dt);
  out.moisture = contacts.moisture[c];
  StiffnessEstimate stiff;
  // (Exhaustive: a model without a case here does not compile, -Werror=switch.)
  switch (contacts.model[c]) {
    case ModelKind::Hill: {
      const HillResult r = hill_force(contacts.hill_params[c], contacts.hill_map[c], kin, HillState{carried, out.moisture});
      out.shear = r.state.shear_hm;
      out.moisture = r.state.moisture;
      out.force = r.force, out.normal_force = r.surface_normal, out.moisture_force = r.moisture_force;
      out.trial_shear = r.trial_shear, out.active = r.active;
      if (out.active && want_stiffness) stiff = hill_timestep_stiffness(contacts.hill_params[c], contacts.hill_map[c], gap);
      break;
    }
    case ModelKind::Linear: {
      const LinearResult r = linear_force(contacts.linear_params[c], contacts.linear_map[c], kin, LinearState{carried});
      out.shear = r.state.shear_force;
      out.force = r.force, out.normal_force = r.normal_force, out.trial_shear = r.trial_shear, out.active = r.active;
      if (out.active) stiff = {contacts.linear_map[c].kn, contacts.linear_map[c].ks};
      break;
    }
    case ModelKind::RrLinear: {
      const Vec3 moment = carry_into_plane(contacts.moment_state[c], contacts.normal[c], normal, mean_spin, dt);
      const RrLinearResult r =
          rrlinear_force(contacts.linear_params[c], contacts.linear_map[c], kin, RrLinearState{carried, moment},
                         spin2 - rec[a].spin, rrlinear_radius(r1, ball2 ? rad[key.b] : 0.0));
      out.shear = r.linear.state.shear_force;
      out.force = r.linear.force, out.normal_force = r.linear.normal_force, out.trial_shear = r.linear.trial_shear;
      out.active = r.linear.active;
      out.moment = r.moment;
      out.wall_row = !ball2;
      if (out.active) stiff = {contacts.linear_map[c].kn, contacts.linear_map[c].ks};
      break;
    }
  }
  out.k_tran = stiff.kn + stiff.ks;
  out.k_shear = stiff.ks;
  if (!out.active) out.force = Vec3{};
  // Accumulated shear displacement (reported, not used by the laws): rotated with the plane (and
  // cleared again by store_row if the contact is deleted).
  if (settings.track_shear_displacement)
    contacts.shear_disp[c] =
        out.active ? lanes::vec3(rotate_with_plane(v3(contacts.shear_disp[c]), v3(contacts.normal[c]), v3(normal), mean_spin, dt)) +
                         kin.shear_rate() * dt
                   : Vec3{};
  RowShare share;
  store_row(c, out, want_stiffness, true, share);
  return share;
}

// A batch lane's results as a row outcome (store_row's input). A wall row's moment on its ball
// takes the ball's arm (the lane's second arm is the wall's, exactly 0: wall_block); a linear lane
// never ruptures, so its moisture state stays as it was.
HILLDEM_INLINE Simulation::RowOutcome Simulation::lane_outcome(const ContactBatch& batch, std::size_t lane,
                                                              bool wall_row) const {
  using F = ContactBatch;
  RowOutcome out;
  out.normal = batch.get3(F::kNx, lane);
  out.gap = batch.col(F::kGap)[lane];
  out.r1 = batch.col(F::kR1)[lane];
  out.r2 = wall_row ? out.r1 : batch.col(F::kR2)[lane];
  out.force = batch.get3(F::kFx, lane);
  out.shear = batch.get3(F::kShx, lane);
  out.normal_force = batch.col(F::kFn)[lane];
  out.moisture_force = batch.col(F::kFm)[lane];
  out.trial_shear = batch.col(F::kTrial)[lane];
  out.k_tran = batch.col(F::kKtran)[lane];
  out.k_shear = batch.col(F::kKshear)[lane];
  out.moisture = batch.col(F::kRuptured)[lane] != 0.0 ? Moisture::Ruptured : contacts.moisture[batch.row(lane)];
  out.active = batch.col(F::kActive)[lane] != 0.0;
  return out;
}

HILLDEM_INLINE void Simulation::store_row(std::size_t c, const RowOutcome& out, bool want_stiffness, bool reported,
                                         RowShare& share) {
  // Deleted when inactive beyond the proximity distance (a wet contact stays active: spec §2.5).
  if (!out.active && out.gap > settings.proximity) {
    contacts.remove(c);  // (moisture back to dry)
    contacts.gap[c] = out.gap;
    contacts.normal[c] = out.normal;
    share.clear(want_stiffness);
    share.ok = true;
    return;
  }
  // Force on piece 2 is F_c, on piece 1 −F_c (spec conventions). The contact point lies on the normal
  // at R + g/2 from either centre, so the moment on either ball is −(R + g/2) n̂ × F_c.
  // (The share is written where it belongs, field by field: a share built on the stack and copied
  // reloads fields just stored, which stalls store forwarding.)
  const ContactMoments<double> m =
      contact_moments(lanes::v3(out.normal), out.gap, out.r1, out.r2, lanes::v3(out.force));
  share.force = -out.force;
  // The contact moment M_c (rrlinear) on piece 2, −M_c on piece 1; a wall row's second share is its
  // ball's (piece 1).
  share.moment = lanes::vec3(m.on1) - out.moment;
  share.moment2 = out.wall_row ? lanes::vec3(m.on2) - out.moment : lanes::vec3(m.on2) + out.moment;
  share.ok = std::isfinite(out.force.x + out.force.y + out.force.z);
  if (want_stiffness) {  // what add_row_stiffness reads (zero when inactive)
    share.k_tran = out.k_tran;
    share.k_shear = out.k_shear;
    share.gap = out.gap;
  }
  // Only the columns the cycle needs (memory traffic): F_s = F_c − (F_n + F^m) n̂ is derived. The
  // history always; F_c and the columns only reports read when `reported` (wall rows, which
  // collect_forces reads from F_c, always are); gap and the active flag also when the stiffness
  // sums read them (and the gap when the force is not finite: the run's error message names it).
  contacts.shear_state[c] = out.shear;
  contacts.normal[c] = out.normal;
  contacts.moment_state[c] = out.moment;
  if (reported) contacts.force[c] = out.force;
  if (reported || want_stiffness || !share.ok) contacts.gap[c] = out.gap;
  if (reported) {
    contacts.normal_force[c] = out.normal_force;
    contacts.moisture_force[c] = out.moisture_force;
    contacts.trial_shear[c] = out.trial_shear;
  }
  if (want_stiffness) {  // only the time-step estimate and density scaling read them
    contacts.k_tran[c] = out.k_tran;
    contacts.k_shear[c] = out.k_shear;
  }
  // Byte-sized columns last: a char store may alias anything, so the compiler reloads every
  // column pointer after one.
  contacts.moisture[c] = out.moisture;
  if (reported || want_stiffness) contacts.active[c] = out.active;
}

HILLDEM_INLINE void Simulation::store_kept_lane(std::size_t c, const ContactBatch& batch, std::size_t lane,
                                               bool want_stiffness, bool reported, bool history) {
  // The columns of store_row for a contact that stays (written in the same cases), straight from the
  // lanes: no RowOutcome and RowShare copied, no moments computed one lane at a time, no keys read
  // again.
  using F = ContactBatch;
  if (history) {
    contacts.shear_state[c] = batch.get3(F::kShx, lane);
    contacts.normal[c] = batch.get3(F::kNx, lane);
  }
  if (reported) {
    contacts.force[c] = batch.get3(F::kFx, lane);
    contacts.normal_force[c] = batch.col(F::kFn)[lane];
    contacts.moisture_force[c] = batch.col(F::kFm)[lane];
    contacts.trial_shear[c] = batch.col(F::kTrial)[lane];
  }
  if (reported || want_stiffness) contacts.gap[c] = batch.col(F::kGap)[lane];
  if (want_stiffness) {
    contacts.k_tran[c] = batch.col(F::kKtran)[lane];
    contacts.k_shear[c] = batch.col(F::kKshear)[lane];
  }
  // Byte-sized columns last (store_row); the moisture changes only when the bridge ruptured.
  if (batch.col(F::kRuptured)[lane] != 0.0) contacts.moisture[c] = Moisture::Ruptured;
  if (reported || want_stiffness) contacts.active[c] = batch.col(F::kActive)[lane] != 0.0;
}

namespace {
// x2 − x1 of a ball-ball row [m] from the balls' records, ball 2 shifted by the row's periodic image
// (x2 + shift first, as force_row and geometry() do).
template <class Kin>
HILLDEM_INLINE Vec3 separation(const Kin& ka, const Kin& kb, ImageCode image, const PeriodicBox& box) {
  Vec3 x2 = kb.position;
  if (image != kNoImage) x2 += image_shift(image, box);
  return x2 - ka.position;
}
// Whether a ball-ball pair is within reach (gap ≤ proximity [m]): a neighbour pair becomes a contact
// there (as force_row). Not beyond it, so that a non-finite separation goes to force_row, which
// reports it.
template <class Kin>
HILLDEM_INLINE bool pair_within_reach(const Kin& ka, const Kin& kb, ImageCode image, const PeriodicBox& box,
                                      double proximity) {
  const double reach = ka.radius + kb.radius + proximity;
  return !(norm2(separation(ka, kb, image, box)) > reach * reach);
}
}  // namespace

#if defined(__AVX512F__)
using lanes::transpose8;
using lanes::widen8;
#endif

HILLDEM_INLINE void Simulation::fill_ball_lanes(ContactBatch& batch, bool hill) const {
  // Each lane's inputs: from the records of its two balls x2 − x1 (x2 with its periodic image), the
  // radii, velocities and spins, and for the hill law the sums of the two balls' terms; from its row
  // the last normal and shear force and the parameters. The ball values copied lane by lane are 28
  // loads and 28 stores a lane, and a core stores about one value a cycle to different lines; with
  // AVX-512 the records of eight lanes are loaded whole and transposed in registers, and each field
  // is stored once for the eight lanes (docs/performance.md). The arithmetic is the same (x2 − x1 and
  // the sums, lane by lane), so the bits are those of the lane-by-lane copy.
  using F = ContactBatch;
  const BallKin* kin = ball_kin_.data();
  const std::size_t n = batch.size();
  std::size_t lane = 0;
#if defined(__AVX512F__)
  {
    static_assert(sizeof(BallKin) == 128 && alignof(BallKin) == 64);
    static_assert(offsetof(BallKin, position) == 0 && offsetof(BallKin, radius) == 24 &&
                  offsetof(BallKin, velocity) == 32 && offsetof(BallKin, spin) == 56 && offsetof(BallKin, terms) == 80);
    for (; lane < n; lane += 8) {
      // (A last group of fewer than eight lanes repeats its last lane; the batch has room for 64.)
      const double* pa[8];
      const double* pb[8];
      __m512d ra[8], rb[8], a0[8], a1[8], b0[8], b1[8];
      for (std::size_t k = 0; k < 8; ++k) {
        const std::size_t l = std::min(lane + k, n - 1);
        pa[k] = reinterpret_cast<const double*>(kin + batch.ball1(l));
        pb[k] = reinterpret_cast<const double*>(kin + batch.ball2(l));
        ra[k] = _mm512_load_pd(pa[k]);
        rb[k] = _mm512_load_pd(pb[k]);
      }
      transpose8(ra, a0);  // position, radius, velocity, spin.x
      transpose8(rb, b0);
      for (std::size_t k = 0; k < 8; ++k) {
        ra[k] = _mm512_load_pd(pa[k] + 8);
        rb[k] = _mm512_load_pd(pb[k] + 8);
      }
      transpose8(ra, a1);  // spin.y, spin.z, the four terms, padding
      transpose8(rb, b1);
      _mm512_store_pd(batch.col(F::kDx) + lane, _mm512_sub_pd(b0[0], a0[0]));
      _mm512_store_pd(batch.col(F::kDy) + lane, _mm512_sub_pd(b0[1], a0[1]));
      _mm512_store_pd(batch.col(F::kDz) + lane, _mm512_sub_pd(b0[2], a0[2]));
      _mm512_store_pd(batch.col(F::kR1) + lane, a0[3]);
      _mm512_store_pd(batch.col(F::kR2) + lane, b0[3]);
      _mm512_store_pd(batch.col(F::kVax) + lane, a0[4]);
      _mm512_store_pd(batch.col(F::kVay) + lane, a0[5]);
      _mm512_store_pd(batch.col(F::kVaz) + lane, a0[6]);
      _mm512_store_pd(batch.col(F::kVbx) + lane, b0[4]);
      _mm512_store_pd(batch.col(F::kVby) + lane, b0[5]);
      _mm512_store_pd(batch.col(F::kVbz) + lane, b0[6]);
      _mm512_store_pd(batch.col(F::kWax) + lane, a0[7]);
      _mm512_store_pd(batch.col(F::kWay) + lane, a1[0]);
      _mm512_store_pd(batch.col(F::kWaz) + lane, a1[1]);
      _mm512_store_pd(batch.col(F::kWbx) + lane, b0[7]);
      _mm512_store_pd(batch.col(F::kWby) + lane, b1[0]);
      _mm512_store_pd(batch.col(F::kWbz) + lane, b1[1]);
      if (hill) {
        _mm512_store_pd(batch.col(F::kIr) + lane, _mm512_add_pd(a1[2], b1[2]));
        _mm512_store_pd(batch.col(F::kIm) + lane, _mm512_add_pd(a1[3], b1[3]));
        _mm512_store_pd(batch.col(F::kCn) + lane, _mm512_add_pd(a1[4], b1[4]));
        _mm512_store_pd(batch.col(F::kCs) + lane, _mm512_add_pd(a1[5], b1[5]));
      }
    }
    // Lanes across a periodic boundary: x2 − x1 again, with the image.
    for (std::size_t l = 0; l < n; ++l)
      if (batch.image(l) != kNoImage)
        batch.put3(F::kDx, l, separation(kin[batch.ball1(l)], kin[batch.ball2(l)], batch.image(l), settings.box));
    lane = n;
  }
#endif
  for (; lane < n; ++lane) {  // lane by lane (no AVX-512)
    const BallKin& ka = kin[batch.ball1(lane)];
    const BallKin& kb = kin[batch.ball2(lane)];
    batch.put3(F::kDx, lane, separation(ka, kb, batch.image(lane), settings.box));
    batch.col(F::kR1)[lane] = ka.radius;
    batch.col(F::kR2)[lane] = kb.radius;
    batch.put3(F::kVax, lane, ka.velocity);
    batch.put3(F::kVbx, lane, kb.velocity);
    batch.put3(F::kWax, lane, ka.spin);
    batch.put3(F::kWbx, lane, kb.spin);
    if (hill) {
      batch.col(F::kIr)[lane] = ka.terms.inv_radius + kb.terms.inv_radius;
      batch.col(F::kIm)[lane] = ka.terms.inv_mass + kb.terms.inv_mass;
      batch.col(F::kCn)[lane] = ka.terms.normal + kb.terms.normal;
      batch.col(F::kCs)[lane] = ka.terms.shear + kb.terms.shear;
    }
  }
}

HILLDEM_INLINE void Simulation::fill_row_lanes(ContactBatch& batch, bool hill) const {
  using F = ContactBatch;
  const std::size_t n = batch.size();
  // The rows' own inputs. A hill lane's history, parameter set and M: from its live record (eight
  // lanes at a time with AVX-512: one aligned line a row), or from the row columns.
  auto put_hill = [&](std::size_t lane, const Vec3& normal, const Vec3& shear, std::uint32_t set, Moisture m) {
    batch.put3(F::kNox, lane, normal);
    batch.put3(F::kSx, lane, shear);
    const HillParams& p = hill_sets_[set];
    batch.col(F::kFric)[lane] = p.fric_coef, batch.col(F::kSuction)[lane] = p.suction;
    batch.col(F::kDamp)[lane] = p.damp_con;
    batch.col(F::kWet)[lane] = m == Moisture::Wet ? 1.0 : 0.0;
  };
  std::size_t lane = 0;
#if defined(__AVX512F__)
  if (hill) {
    // Eight lanes with live records at a time: the records loaded whole and transposed in registers
    // (n̂_c and F^h_s stored once for the eight lanes), the parameters gathered by set, M compared
    // for the eight at once. The same values as put_hill's, so the same bits.
    static_assert(sizeof(LiveRecord) == 64 && alignof(LiveRecord) == 64);
    static_assert(offsetof(LiveRecord, hill_set) == 8 && offsetof(LiveRecord, moisture) == 15 &&
                  offsetof(LiveRecord, normal) == 16 && offsetof(LiveRecord, shear) == 40);
    static_assert(sizeof(HillParams) == 24 && offsetof(HillParams, fric_coef) == 0 &&
                  offsetof(HillParams, damp_con) == 8 && offsetof(HillParams, suction) == 16);
    const __m512i no_slot = _mm512_set1_epi64(ContactBatch::kNoSlot);
    const double* sets = reinterpret_cast<const double*>(hill_sets_.data());
    for (; lane + 8 <= n; lane += 8) {
      if (_mm512_cmp_epi64_mask(widen8(batch.slots() + lane), no_slot, _MM_CMPINT_NE) != 0xFF) break;  // (the rest lane by lane)
      __m512d r[8], c[8];
      for (std::size_t k = 0; k < 8; ++k) r[k] = _mm512_load_pd(reinterpret_cast<const double*>(&live_.records()[batch.slot(lane + k)]));
      transpose8(r, c);  // c[1]: set and flags; c[2..4]: n̂_c; c[5..7]: F^h_s
      const F::Field history[6] = {F::kNox, F::kNoy, F::kNoz, F::kSx, F::kSy, F::kSz};
      for (int f = 0; f < 6; ++f) _mm512_store_pd(batch.col(history[f]) + lane, c[2 + f]);
      const __m512i flags = _mm512_castpd_si512(c[1]);
      const __m512i at = _mm512_mullo_epi64(_mm512_and_si512(flags, _mm512_set1_epi64(0xFFFFFFFF)), _mm512_set1_epi64(3));
      _mm512_store_pd(batch.col(F::kFric) + lane, _mm512_i64gather_pd(at, sets + 0, 8));
      _mm512_store_pd(batch.col(F::kDamp) + lane, _mm512_i64gather_pd(at, sets + 1, 8));
      _mm512_store_pd(batch.col(F::kSuction) + lane, _mm512_i64gather_pd(at, sets + 2, 8));
      const __mmask8 wet = _mm512_cmp_epi64_mask(_mm512_srli_epi64(flags, 56),
                                                 _mm512_set1_epi64(static_cast<int>(Moisture::Wet)), _MM_CMPINT_EQ);
      _mm512_store_pd(batch.col(F::kWet) + lane, _mm512_maskz_mov_pd(wet, _mm512_set1_pd(1.0)));
    }
  }
#endif
  for (; lane < n; ++lane) {
    const std::size_t c = batch.row(lane);
    if (hill) {
      const std::uint32_t slot = batch.slot(lane);
      if (slot != ContactBatch::kNoSlot) {
        const LiveRecord& r = live_.records()[slot];
        put_hill(lane, r.normal, r.shear, r.hill_set, r.moisture);
      } else {
        put_hill(lane, contacts.normal[c], contacts.shear_state[c], row_hill_set_[c], contacts.moisture[c]);
      }
    } else {  // the linear law's history, and its parameters: the row's (LinearMapping, LinearParams)
      batch.put3(F::kNox, lane, contacts.normal[c]);
      batch.put3(F::kSx, lane, contacts.shear_state[c]);
      batch.col(F::kIr)[lane] = contacts.linear_map[c].kn;
      batch.col(F::kIm)[lane] = contacts.linear_map[c].ks;
      batch.col(F::kFric)[lane] = contacts.linear_params[c].fric;
    }
  }
}

void Simulation::fill_lanes(ContactBatch& batch, bool hill) const {
  fill_ball_lanes(batch, hill);
  fill_row_lanes(batch, hill);
}

void Simulation::force_block(std::size_t a0, std::size_t a1, std::size_t range_end, double dt, BlockScratch& scratch,
                             std::vector<CrossShare>& crossing, std::size_t& bad_row, std::int64_t& batched_count) {
  // Rows of balls a0..a1-1 (ball-ball rows, contiguous), from the last ball down and each ball's rows
  // from the last down. Existing hill and linear contacts go through the batches; new contacts and
  // the shear-displacement tracking through force_row(). Each row's share is added to both balls
  // when its result is known, in that descending row order (the order of force_pass): a batch is
  // run before a row of the other batch or of force_row() is added, so the lanes keep the order.
  const double proximity = settings.proximity;
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  const bool reported = write_results_;
  const PeriodicBox& box = settings.box;
  const BallKin* kin = ball_kin_.data();
  const ContactKey* keys = contacts.key.data();
  // Each ball's force and moment sums in one line, each a vector with a +0.0 fourth lane
  // (motion::ContactSums): a row's share into a ball is one vector operation per sum, not three
  // scalar ones. The same additions component by component, so the same bits.
  motion::ContactSums* __restrict sums = ball_kin_.sums();
  // Prefetch distances in rows (the pass runs down the rows; below). The row columns run downwards,
  // and the hardware prefetcher follows descending streams poorly, so the pair loop would wait on
  // the first loads of the history, parameter and flag columns: the history and parameters are asked
  // for 32 rows ahead, the byte columns and the keys 128 rows ahead. Only for more than 2^17 rows:
  // below, the rows sit in the outer caches, and the prefetches' own work (≈ 30 instructions a row)
  // costs more than they hide (the distances and the threshold: docs/performance.md).
  constexpr std::size_t kPrefetchRows = 16;
  constexpr std::size_t kPrefetchColumns = 32;
  constexpr std::size_t kPrefetchFlags = 128;
  constexpr std::size_t kPrefetchBalls = 8;
  constexpr std::size_t kPrefetchRecords = 64;
  const bool far = contacts.size() > (std::size_t{1} << 17);
  const bool live = live_.visited();  // the rows visited: the live rows (force_pass), or all (through force_row)
  const bool records = live && live_.records_ready();  // the live rows through their records
  using F = ContactBatch;
  ContactBatch& hill = scratch.hill;
  ContactBatch& linear = scratch.linear;
  hill.clear();
  linear.clear();
  // A row's shares into its two balls: −F_c and moment1 into ball a, F_c and moment2 into ball b
  // (b beyond this thread's range: into `crossing`, see force_pass), and the stiffness terms.
  auto add_to_balls = [&](std::size_t a, std::size_t b, const Vec3& force, const Vec3& moment1, const Vec3& moment2,
                          double k_tran, double k_shear, double gap) __attribute__((always_inline)) {
    const motion::V4 f = motion::load(force);
    sums[a].force -= f;
    sums[a].moment += motion::load(moment1);
    if (want_stiffness) add_stiffness(k_tran, k_shear, kin[a].radius, gap, ball_k_tran_[a], ball_k_rot_[a]);
    if (b < range_end) {
      sums[b].force += f;
      sums[b].moment += motion::load(moment2);
      if (want_stiffness) add_stiffness(k_tran, k_shear, kin[b].radius, gap, ball_k_tran_[b], ball_k_rot_[b]);
    } else {
      crossing.push_back({static_cast<std::uint32_t>(b), force, moment2, k_tran, k_shear, gap});
    }
  };
  // Whether a ball-ball pair (ball a's record ka, ball b, the row's periodic image) is within reach.
  auto within_reach = [&](const BallKin& ka, std::size_t b, ImageCode image) __attribute__((always_inline)) {
    return pair_within_reach(ka, kin[b], image, box, proximity);
  };
  // Row c's share (share.force is −F_c: x − (−F) is x + F bit for bit).
  auto add_share = [&](std::size_t c, const RowShare& s) __attribute__((always_inline)) {
    if (!s.ok) bad_row = std::min(bad_row, c);
    add_to_balls(keys[c].a, keys[c].b, -s.force, s.moment, s.moment2, s.k_tran, s.k_shear, s.gap);
  };
  // The law of the gathered lanes, and their results into the rows and the balls.
  auto flush = [&](ContactBatch& batch) {
    fill_lanes(batch, &batch == &hill);
    const LaneStep step{dt, want_stiffness, proximity};
    if (&batch == &hill) run_hill_lanes(batch, step);
    else run_linear_lanes(batch, step);
    batched_count += static_cast<std::int64_t>(batch.size());
    const double* quick = batch.col(F::kQuick);
    // One lane's results into its row (or live record) and its balls' sums, in lane order.
    auto scatter_lane = [&](std::size_t lane) __attribute__((always_inline)) {
      const std::size_t c = batch.row(lane);
      const std::uint32_t slot = &batch == &hill ? batch.slot(lane) : ContactBatch::kNoSlot;
      if (quick[lane] == 0.0) {  // deleted, or a non-finite force: the general way
        RowShare share;
        store_row(c, lane_outcome(batch, lane, /*wall_row=*/false), want_stiffness, reported, share);
        add_share(c, share);
        if (slot != ContactBatch::kNoSlot) live_.load_record(slot, contacts, row_hill_set_.data());  // (store_row wrote the columns)
        return;
      }
      // The shares from the lanes; a live record's history into the record.
      if (slot != ContactBatch::kNoSlot) {
        LiveRecord& h = live_.records()[slot];
        h.shear = batch.get3(F::kShx, lane);
        h.normal = batch.get3(F::kNx, lane);
        if (batch.col(F::kRuptured)[lane] != 0.0) h.moisture = Moisture::Ruptured;
        store_kept_lane(c, batch, lane, want_stiffness, reported, false);
      } else {
        store_kept_lane(c, batch, lane, want_stiffness, reported);
      }
      double k_tran = 0.0, k_shear = 0.0, gap = 0.0;
      if (want_stiffness)
        k_tran = batch.col(F::kKtran)[lane], k_shear = batch.col(F::kKshear)[lane], gap = batch.col(F::kGap)[lane];
      add_to_balls(batch.ball1(lane), batch.ball2(lane), batch.get3(F::kFx, lane), batch.get3(F::kMax, lane),
                   batch.get3(F::kMbx, lane), k_tran, k_shear, gap);
    };
    std::size_t lane = 0;
#if defined(__AVX512F__)
    // Eight hill lanes at a time when all eight take the common way with live records and nothing
    // more is asked of them (kept, finite, no rupture, both balls in this thread's range, no reports,
    // no stiffness): their shares transposed in registers into one 64-byte vector per ball, each
    // ball's sums (one line, motion::ContactSums) added to in one operation, and n̂_c and F^h_s
    // stored into each record at once. The same additions in the same lane order (x − F is x + (−F)
    // bit for bit, and a fourth lane +0.0 stays +0.0), so the same bits as scatter_lane.
    if (records && &batch == &hill && !reported && !want_stiffness) {
      const double* ruptured = batch.col(F::kRuptured);
      const __m512d zero = _mm512_setzero_pd();
      const __m512i no_slot = _mm512_set1_epi64(ContactBatch::kNoSlot);
      const __m512i end = _mm512_set1_epi64(static_cast<long long>(range_end));
      for (; lane + 8 <= batch.size(); lane += 8) {
        const __mmask8 simple =
            _mm512_cmp_pd_mask(_mm512_loadu_pd(quick + lane), zero, _CMP_NEQ_UQ) &
            _mm512_cmp_pd_mask(_mm512_loadu_pd(ruptured + lane), zero, _CMP_EQ_OQ) &
            _mm512_cmp_epi64_mask(widen8(batch.slots() + lane), no_slot, _MM_CMPINT_NE) &
            _mm512_cmp_epi64_mask(widen8(batch.balls2() + lane), end, _MM_CMPINT_LT);
        if (simple != 0xFF) {
          for (std::size_t k = 0; k < 8; ++k) scatter_lane(lane + k);
          continue;
        }
        auto col = [&](ContactBatch::Field f) { return _mm512_load_pd(batch.col(f) + lane); };
        const __m512d fx = col(F::kFx), fy = col(F::kFy), fz = col(F::kFz);
        __m512d c[8], share_a[8], share_b[8], history[8];
        // Ball 1: [−F_c, +0.0, moment 1, +0.0]; ball 2: [F_c, +0.0, moment 2, +0.0].
        c[0] = _mm512_sub_pd(zero, fx), c[1] = _mm512_sub_pd(zero, fy), c[2] = _mm512_sub_pd(zero, fz);
        c[3] = zero, c[4] = col(F::kMax), c[5] = col(F::kMay), c[6] = col(F::kMaz), c[7] = zero;
        transpose8(c, share_a);
        c[0] = fx, c[1] = fy, c[2] = fz, c[4] = col(F::kMbx), c[5] = col(F::kMby), c[6] = col(F::kMbz);
        transpose8(c, share_b);
        // The record's doubles 2-7: n̂_c, then F^h_s (LiveRecord).
        c[0] = zero, c[1] = zero, c[2] = col(F::kNx), c[3] = col(F::kNy), c[4] = col(F::kNz);
        c[5] = col(F::kShx), c[6] = col(F::kShy), c[7] = col(F::kShz);
        transpose8(c, history);
        for (std::size_t k = 0; k < 8; ++k) {
          double* a = reinterpret_cast<double*>(sums + batch.ball1(lane + k));
          _mm512_store_pd(a, _mm512_add_pd(_mm512_load_pd(a), share_a[k]));
          double* b = reinterpret_cast<double*>(sums + batch.ball2(lane + k));
          _mm512_store_pd(b, _mm512_add_pd(_mm512_load_pd(b), share_b[k]));
          _mm512_mask_store_pd(reinterpret_cast<double*>(&live_.records()[batch.slot(lane + k)]), 0xFC, history[k]);
        }
      }
    }
#endif
    for (; lane < batch.size(); ++lane) scatter_lane(lane);
    batch.clear();
  };
  for (std::size_t a = a1; a-- > a0;) {
    // Ball a's sums start here: its own rows come first in its order, and rows (x, a) with x < a
    // come later.
    sums[a] = motion::ContactSums{};
    if (want_stiffness) ball_k_tran_[a] = ball_k_rot_[a] = 0.0;
    const BallKin& ka = kin[a];
    if (far && a >= kPrefetchBalls) {
      // The record, force sums and row range of the ball some places down: the pass meets each ball
      // first as the `a` of its rows, a descending stream.
      const std::size_t ahead = a - kPrefetchBalls;
      const char* record = reinterpret_cast<const char*>(kin + ahead);
      __builtin_prefetch(record);
      __builtin_prefetch(record + 64);
      if (records) {
        __builtin_prefetch(sums + ahead);  // (to be read: see the live records' loop below)
      } else {
        __builtin_prefetch(sums + ahead, 1);
      }
      // Its row range: of its live rows, or of all its rows.
      __builtin_prefetch(live ? live_.first() + ahead : neighbours_.first_rows().data() + ahead);
    }
    // Ball a's rows from the last down: k1 − 1 down to k0 of the row sequence row_at, its live rows
    // (live_rows) or all of its rows.
    auto run_rows = [&](std::size_t k1, std::size_t k0, auto row_at) __attribute__((always_inline)) {
      for (std::size_t k = k1; k-- > k0;) {
        const std::size_t c = row_at(k);
        if (far) {  // (nothing asked for ahead when the rows fit in the caches: see above)
          if (k >= kPrefetchRows) {
            // The ball record of a neighbour some rows on, and its force sums: the neighbours in the layer
            // above a ball are a whole layer away in memory, and the hardware prefetcher misses them.
            const std::size_t ahead_ball = keys[row_at(k - kPrefetchRows)].b;
            const char* ahead = reinterpret_cast<const char*>(kin + ahead_ball);
            __builtin_prefetch(ahead);
            __builtin_prefetch(ahead + 64);
            __builtin_prefetch(sums + ahead_ball, 1);
          }
          if (k >= kPrefetchColumns) {  // the history and the parameters
            const std::size_t r = row_at(k - kPrefetchColumns);
            __builtin_prefetch(contacts.normal.data() + r, 1);
            __builtin_prefetch(contacts.shear_state.data() + r, 1);
            __builtin_prefetch(row_hill_set_.data() + r);
          }
          if (k >= kPrefetchFlags) {  // the byte columns, and the keys (12 B) half as far
            const std::size_t r = row_at(k - kPrefetchFlags);
            __builtin_prefetch(contacts.image.data() + r);
            __builtin_prefetch(contacts.exists.data() + r);
            __builtin_prefetch(contacts.model.data() + r);
            __builtin_prefetch(contacts.moisture.data() + r);
            __builtin_prefetch(keys + row_at(k - kPrefetchFlags / 2));
          }
        }
        const std::size_t b = keys[c].b;
        const bool exists = contacts.exists[c];
        if (contacts.model[c] == ModelKind::Hill) {
          // A hill row, contact or neighbour pair, without a branch on which it is: the row always
          // takes the next lane's slot, which becomes a lane only if it is a contact. A live row is
          // mostly a contact (≈ 90 % in the bench bed; the others are neighbour pairs within reach of
          // one, and contacts deleted since the list was made), so the branch on `exists` is mostly
          // not taken, and the balls' records are read only then. Only a pair within reach that is
          // no contact yet (a new one: rare) goes to force_row, in row order.
          if (linear.size() > 0) flush(linear);
          if (hill.full()) flush(hill);
          const ImageCode image = contacts.image[c];
          hill.add_if(exists, static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(a),
                      static_cast<std::uint32_t>(b), image);
          if (!exists && within_reach(ka, b, image)) [[unlikely]] {  // a contact from now on
            if (hill.size() > 0) flush(hill);
            add_share(c, force_row(c, dt));
          }
          continue;
        }
        // A neighbour pair beyond reach gives nothing to either ball.
        if (!exists && !within_reach(ka, b, contacts.image[c])) continue;
        ContactBatch* batch = nullptr;  // the model's batch (exhaustive: -Werror=switch)
        switch (contacts.model[c]) {
          case ModelKind::Hill: batch = &hill; break;
          case ModelKind::Linear: batch = &linear; break;
          case ModelKind::RrLinear: break;  // (row by row: no batch)
        }
        if (!exists || batch == nullptr) {  // a new contact, or a model without a batch: row by row
          if (hill.size() > 0) flush(hill);
          if (linear.size() > 0) flush(linear);
          add_share(c, force_row(c, dt));
          continue;
        }
        ContactBatch& other = batch == &hill ? linear : hill;
        if (other.size() > 0) flush(other);
        if (batch->full()) flush(*batch);
        // The lane's inputs are read when the batch runs (fill_lanes).
        batch->add(static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                   contacts.image[c]);
      }
    };
    if (records) {
      // Ball a's live rows from the last down, through their records: the loop of
      // run_rows for live rows, with the record of each row in place of its nine columns. A row that
      // is no contact (a neighbour pair within reach of one, or a contact deleted since the list)
      // is checked for reach from the record and its second ball's, which the lanes read anyway.
      LiveRecord* rec = live_.records();
      const std::uint32_t* live_first = live_.first();
      for (std::size_t k = live_first[a + 1]; k-- > live_first[a];) {
        if (far) {
          // The neighbour's record and sums, as in run_rows, and the record 64 rows on (one line a
          // row). Asked for to be read, not written (prefetchw), although both lines are written
          // later (docs/performance.md).
          if (k >= kPrefetchRows) {
            const std::size_t ahead_ball = rec[k - kPrefetchRows].b;
            const char* ahead = reinterpret_cast<const char*>(kin + ahead_ball);
            __builtin_prefetch(ahead);
            __builtin_prefetch(ahead + 64);
            __builtin_prefetch(sums + ahead_ball);
          }
          if (k >= kPrefetchRecords) __builtin_prefetch(rec + k - kPrefetchRecords);
        } else if (k >= kPrefetchRecords) {
          // The records alone in the caches' range too: the stream runs down, and the hardware
          // prefetcher follows it poorly.
          __builtin_prefetch(rec + k - kPrefetchRecords);
        }
        const LiveRecord& r = rec[k];
        const std::size_t c = r.row, b = r.b;
        if (r.model == ModelKind::Hill) {
          if (linear.size() > 0) flush(linear);
          if (hill.full()) flush(hill);
          const bool exists = r.exists;
          hill.add_if(exists, static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(a),
                      static_cast<std::uint32_t>(b), r.image, static_cast<std::uint32_t>(k));
          if (!exists && within_reach(ka, b, r.image)) [[unlikely]] {  // a contact again (force_row)
            if (hill.size() > 0) flush(hill);
            add_share(c, force_row(c, dt));
            live_.load_record(k, contacts, row_hill_set_.data());
          }
          continue;
        }
        // Another model keeps its history and flags in the columns: this one row as run_rows takes it.
        run_rows(k + 1, k, [rec](std::size_t j) -> std::size_t { return rec[j].row; });
      }
    } else if (live) {
      const std::uint32_t* rows = live_.rows();
      run_rows(live_.first()[a + 1], live_.first()[a], [rows](std::size_t k) -> std::size_t { return rows[k]; });
    } else {  // every row through force_row (each contact's shear displacement tracked)
      const std::vector<std::uint32_t>& first_rows = neighbours_.first_rows();
      for (std::size_t c = first_rows[a + 1]; c-- > first_rows[a];) add_share(c, force_row(c, dt));
    }
  }
  if (hill.size() > 0) flush(hill);
  if (linear.size() > 0) flush(linear);
}

void Simulation::wall_block(std::size_t k0, std::size_t k1, double dt, BlockScratch& scratch, std::size_t& bad_row,
                            std::int64_t& batched_count) {
  // Existing linear wall contacts through a linear batch: one contact's law at a time is a chain of
  // dependent square roots and divisions (engine/contact_batch.hpp).
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  const bool batched = !settings.track_shear_displacement;
  using F = ContactBatch;
  ContactBatch& batch = scratch.linear;
  batch.clear();
  auto done = [&](std::size_t c, const RowShare& share) {
    share_moment_[c] = share.moment2;
    if (!share.ok) bad_row = std::min(bad_row, c);
  };
  auto flush = [&] {
    run_linear_lanes(batch, LaneStep{dt, want_stiffness, settings.proximity, /*geometry_given=*/true});
    batched_count += static_cast<std::int64_t>(batch.size());
    const double* quick = batch.col(F::kQuick);
    for (std::size_t lane = 0; lane < batch.size(); ++lane) {
      const std::size_t c = batch.row(lane);
      if (quick[lane] == 0.0) {
        RowShare share;
        store_row(c, lane_outcome(batch, lane, /*wall_row=*/true), want_stiffness, true, share);
        done(c, share);
        continue;
      }
      store_kept_lane(c, batch, lane, want_stiffness, true);
      share_moment_[c] = batch.get3(F::kMax, lane);  // the ball's arm (the wall's, kMbx.., is 0)
    }
    batch.clear();
  };
  for (std::size_t k = k0; k < k1; ++k) {
    const std::size_t c = neighbours_.wall_rows()[k];
    if (!batched || !contacts.exists[c] || contacts.model[c] != ModelKind::Linear) {
      done(c, force_row(c, dt));
      continue;
    }
    const std::size_t a = contacts.key[c].a;
    const Wall& w = walls.walls[contacts.key[c].b];
    const Vec3 x1 = ball_kin_[a].position;  // (the records: current in the force pass)
    const double r1 = balls.radius[a];
    const auto touch = wall_touch(w, x1, r1);
    if (!touch) {  // (the contact is deleted: force_row)
      done(c, force_row(c, dt));
      continue;
    }
    if (batch.full()) flush();
    const std::size_t lane = batch.add(static_cast<std::uint32_t>(c));
    const double arm1 = r1 + 0.5 * touch->gap;
    batch.put3(F::kNx, lane, touch->normal);
    batch.col(F::kGap)[lane] = touch->gap;
    batch.col(F::kR1)[lane] = r1;
    batch.col(F::kR2)[lane] = -0.5 * touch->gap;  // the wall's arm R2 + g/2 is then exactly 0
    batch.put3(F::kVax, lane, ball_kin_[a].velocity);
    batch.put3(F::kVbx, lane, wall_point_velocity(w, x1 + touch->normal * arm1));
    batch.put3(F::kWax, lane, ball_kin_[a].spin);
    batch.put3(F::kWbx, lane, w.spin);
    batch.put3(F::kNox, lane, contacts.normal[c]);
    batch.put3(F::kSx, lane, contacts.shear_state[c]);
    batch.col(F::kIr)[lane] = contacts.linear_map[c].kn;
    batch.col(F::kIm)[lane] = contacts.linear_map[c].ks;
    batch.col(F::kFric)[lane] = contacts.linear_params[c].fric;
  }
  if (batch.size() > 0) flush();
}

void Simulation::refresh_live_rows() {
  live_.refresh(contacts, ball_kin_.data(), neighbours_.first_rows().data(), balls.size(), settings.proximity,
                settings.box, skin());
}

void Simulation::force_pass(double dt) {
  const std::size_t rows = contacts.size();
  const std::size_t n = balls.size();
  // Blocks of balls, each with its own rows (ball-ball rows are sorted by their first ball); each
  // row writes only its own columns. Each thread takes a range of balls of equal work (WorkSplit)
  // in blocks of balls_per_block from its start, and runs the blocks from the last down
  // (run_range). Every ball's force is summed in one order whatever the ranges: its ball-ball rows
  // in descending row order, then its wall rows (NeighbourList::first_rows, force_block,
  // collect_forces). So results depend neither on the blocks (ContactBatch::pad_lanes) nor on the
  // thread count. The first failing row is found by a min-reduction, so the outcome does not depend
  // on the thread count.
  ball_kin_.begin_sums(n);  // (not current until collect_forces has added every share)
  std::size_t bad_row = rows;
  std::int64_t batched = 0;
  prepare_pass();
  std::unique_ptr<std::atomic<bool>[]> crossing_done;  // per thread: its crossing list is final
  std::atomic<bool> late_share{false};
#pragma omp parallel reduction(min : bad_row) reduction(+ : batched) if (n > kParallelMin)
  {
    // ≈ 60 kB: on the heap, not the thread's stack. Default-initialised (make_unique would zero it on
    // every pass): every lane value a law or the scatter uses is written before it is read.
    std::unique_ptr<BlockScratch> scratch(new BlockScratch);
#pragma omp single
    {
      const auto threads = static_cast<std::size_t>(omp_get_num_threads());
      const bool live_split = live_.visited() && live_.covers(n);
      const std::uint32_t* row_first = live_split ? live_.first() : neighbours_.first_rows().data();
      const bool resplit =
          split_.prepare(threads, n, rows, thread_shares, row_first, neighbours_.wall_rows_start().data());
      crossing_.resize(threads);
      if (resplit || crossing_floor_.size() != threads) crossing_floor_.assign(threads, kFloorUnknown);
      crossing_done.reset(new std::atomic<bool>[threads]);
      for (std::size_t u = 0; u < threads; ++u) crossing_done[u].store(false, std::memory_order_relaxed);
    }
    run_range(static_cast<std::size_t>(omp_get_thread_num()), dt, *scratch, crossing_done.get(), late_share, bad_row,
              batched);
  }
  if (late_share.load()) throw RunError("internal error: a crossing share after its list was final (force_pass)");
  batched_rows_ = batched;
  body_terms_ready_ = true;
  live_.count_pass();
  if (bad_row < rows) throw_bad_row(bad_row);
  collect_forces();
}

void Simulation::prepare_pass() {
  // The ball records, the hill parameter sets and the live rows (and their records) the pass reads.
  const std::size_t rows = contacts.size();
  const std::size_t n = balls.size();
  const bool terms_ready = body_terms_ready_ && ball_kin_.size() == n;
  if (!terms_ready || hill_sets_stale_ || row_hill_set_.size() != rows) refresh_param_sets();
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
    live_.build_records(contacts, row_hill_set_.data(), n);
  live_.count_record_pass();
}

void Simulation::run_range(std::size_t t, double dt, BlockScratch& scratch, std::atomic<bool>* crossing_done,
                           std::atomic<bool>& late_share, std::size_t& bad_row, std::int64_t& batched) {
  // Thread t's range of balls (force_pass), its crossing shares announced to the threads above as
  // soon as they are final, then the end of its balls' sums.
  const std::size_t block = std::max<std::size_t>(1, balls_per_block);
  const std::size_t first = split_.begin(t), last = split_.end(t);
  std::vector<CrossShare>& crossing = crossing_[t];
  crossing.clear();
  // One thread needs no timing: its share is the whole.
  const bool timed = omp_get_num_threads() > 1;
  const double busy_from = timed ? omp_get_wtime() : 0.0;
  // The lowest ball of the range with a row into a later range (made once per split: the rows do
  // not change until the next). Below it the thread adds no crossing share, and from there its list
  // is final and announced (crossing_done), long before its pass ends: the blocks run from the
  // last down, and the crossing rows are those of its top layer of balls: only its top row_span balls
  // (NeighbourList::row_span) can have one, and the last range has none.
  if (crossing_floor_[t] == kFloorUnknown) crossing_floor_[t] = crossing_floor(first, last);
  const std::size_t floor = crossing_floor_[t];
  bool announced = false;
  std::size_t announced_size = 0;
  auto announce = [&] {
    crossing_done[t].store(true, std::memory_order_release);
    announced = true;
    announced_size = crossing.size();
  };
  if (floor >= last) announce();
  if (last > first)
    for (std::size_t a = first + (last - first - 1) / block * block;; a -= block) {
      force_block(a, std::min(last, a + block), last, dt, scratch, crossing, bad_row, batched);
      if (!announced && a <= floor) announce();
      if (a == first) break;
    }
  if (!announced) announce();
  // (A share added after the list was announced would be a wrong floor: another thread may have read
  // the list already. Never seen; checked, as it costs nothing.)
  if (crossing.size() != announced_size) late_share.store(true, std::memory_order_relaxed);
  // The end of the range's force sums, by the thread itself, in their order (force_pass): the
  // crossing shares into its balls from the ranges below, the last range's first (each list once
  // its thread announced it: no wait in practice), then its balls' wall rows in row order
  // (wall_block: each row's result depends on no other row, nor on the batch it falls into).
  for (std::size_t u = t; u-- > 0;) {
    for (int spin = 0; !crossing_done[u].load(std::memory_order_acquire); ++spin)
      if (spin > 1000) std::this_thread::yield();  // (more threads than cores: let the other run)
    add_crossing(crossing_[u], first, last);
  }
  const std::size_t k0 = neighbours_.wall_rows_start()[first], k1 = neighbours_.wall_rows_start()[last];
  if (k1 > k0) {
    wall_block(k0, k1, dt, scratch, bad_row, batched);
    add_wall_rows(k0, k1);
  }
  if (timed) split_.add_busy(t, omp_get_wtime() - busy_from);  // [s]
}

std::size_t Simulation::crossing_floor(std::size_t first, std::size_t last) const {
  std::size_t floor = last;
  if (last < balls.size()) {
    const std::vector<std::uint32_t>& rows_of = neighbours_.first_rows();
    for (std::size_t a = last - std::min(last - first, neighbours_.row_span()); a < last && floor == last; ++a)
      if (rows_of[a + 1] > rows_of[a] && contacts.key[rows_of[a + 1] - 1].b >= last) floor = a;
  }
  return floor;
}

void Simulation::throw_bad_row(std::size_t bad_row) const {
  // (The gap column is written for a row whose force is not finite: store_row.)
  const ContactKey& key = contacts.key[bad_row];
  std::ostringstream msg;
  msg << "non-finite contact force at step " << steps + 1 << " between ball " << balls.id[key.a] << " and "
      << (key.kind == ContactKind::BallBall ? "ball " + std::to_string(balls.id[key.b])
                                            : "wall '" + walls.walls[key.b].name + "'")
      << " (gap " << contacts.gap[bad_row] << " m): the run is unstable; reduce the time step";
  throw RunError(msg.str());
}

void Simulation::add_crossing(const std::vector<CrossShare>& list, std::size_t first, std::size_t last) {
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  motion::ContactSums* __restrict sums = ball_kin_.sums();
  for (const CrossShare& s : list)
    if (s.b >= first && s.b < last) {
      sums[s.b].force += motion::load(s.force);
      sums[s.b].moment += motion::load(s.moment);
      if (want_stiffness)
        add_stiffness(s.k_tran, s.k_shear, balls.radius[s.b], s.gap, ball_k_tran_[s.b], ball_k_rot_[s.b]);
    }
}

void Simulation::add_wall_rows(std::size_t k0, std::size_t k1) {
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  motion::ContactSums* __restrict sums = ball_kin_.sums();
  for (std::size_t k = k0; k < k1; ++k) {
    const std::uint32_t c = neighbours_.wall_rows()[k];
    const std::size_t a = contacts.key[c].a;
    sums[a].force -= motion::load(contacts.force[c]);
    sums[a].moment += motion::load(share_moment_[c]);
    if (want_stiffness) add_row_stiffness(c, balls.radius[a], ball_k_tran_[a], ball_k_rot_[a]);
  }
}

void Simulation::collect_forces() {
  // The walls' sums, each wall row in row order (the balls' sums were ended by the pass's threads).
  // Rows that are not active contacts hold zero force and moment.
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  for (Wall& w : walls.walls) {
    w.force = w.moment = Vec3{};
    w.normal_force = w.normal_stiffness = 0.0;
    w.active_contacts = 0;
  }
  // Each wall row into its wall's sums, in row order.
  for (std::uint32_t c : neighbours_.wall_rows()) {
    const ContactKey& k = contacts.key[c];
    if (!contacts.active[c]) continue;
    Wall& w = walls.walls[k.b];
    const Vec3 point = ball_kin_[k.a].position + contacts.normal[c] * (balls.radius[k.a] + 0.5 * contacts.gap[c]);
    w.force += contacts.force[c];
    w.moment += cross(point - w.rotation_center, contacts.force[c]) + contacts.moment_state[c];  // (+ M_c: rrlinear)
    w.normal_force += dot(contacts.force[c], contacts.normal[c]);
    w.normal_stiffness += contacts.model[c] == ModelKind::Hill ? contacts.k_tran[c] : contacts.linear_map[c].kn;
    ++w.active_contacts;
  }
  stiffness_ready_ = want_stiffness;
  // The BallStore's columns of the sums on the passes someone may read them after (as the reported
  // contact columns); the law of motion reads the sums themselves.
  ball_kin_.end_sums();
  if (write_results_) ball_kin_.sync_sum_columns(balls);
}

void Simulation::add_row_stiffness(std::size_t c, double radius, double& k_tran, double& k_rot) const {
  if (!contacts.active[c]) return;
  add_stiffness(contacts.k_tran[c], contacts.k_shear[c], radius, contacts.gap[c], k_tran, k_rot);
}

void Simulation::ball_stiffness(std::size_t i, double& k_tran, double& k_rot) const {
  if (stiffness_ready_) {  // summed by the last force pass
    k_tran = ball_k_tran_[i];
    k_rot = ball_k_rot_[i];
    return;
  }
  // The same sums from the rows, in the same order (force_pass: the ball-ball rows in descending
  // row order, its own rows then those where it is piece 2; then its wall rows), so the result does
  // not depend on which way it was computed (a resumed run takes this way first).
  k_tran = k_rot = 0.0;
  const NeighbourList& list = neighbours_;
  const std::vector<std::uint32_t>& first = list.first_rows();
  if (i + 1 >= first.size()) return;  // a ball added since the last rebuild: no contacts yet
  const double radius = balls.radius[i];
  for (std::size_t c = first[i + 1]; c-- > first[i];) add_row_stiffness(c, radius, k_tran, k_rot);
  for (std::uint32_t k = list.late_rows_start()[i + 1]; k-- > list.late_rows_start()[i];)
    add_row_stiffness(list.late_rows()[k], radius, k_tran, k_rot);
  for (std::uint32_t k = list.wall_rows_start()[i]; k < list.wall_rows_start()[i + 1]; ++k)
    add_row_stiffness(list.wall_rows()[k], radius, k_tran, k_rot);
}

double Simulation::estimate_timestep() const {
  // Per-body sums of the contact-returned stiffnesses (spec §4): k_tran = Σ(k̂_n + k̂_s),
  // k_rot = Σ k̂_s |x_c − x|². Δt_crit = min(√(m/k_tran), √(I/k_rot)). The stiffnesses were stored
  // by the last force pass (hill Eqs. 19-21; linear k_n, k_s).
  // The minimum is taken over the squares m/k_tran, I/k_rot [s²] and rooted once: √ is monotonic and
  // correctly rounded, so √(min x) is bit for bit min √x, without two roots per ball.
  const std::size_t n = balls.size();
  double crit2 = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(static) reduction(min : crit2) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    double k_tran, k_rot;
    ball_stiffness(i, k_tran, k_rot);
    if (k_tran > 0.0) crit2 = std::min(crit2, balls.mass[i] / k_tran);
    if (k_rot > 0.0) crit2 = std::min(crit2, balls.inertia[i] / k_rot);
  }
  const double crit = std::sqrt(crit2);
  return std::isfinite(crit) ? settings.timestep_safety * crit : 0.0;
}

double Simulation::mean_unbalanced_ratio() const {
  double unbalanced = 0.0;
  std::size_t free_balls = 0;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const FixityMask fix = balls.fixity[i];
    if ((fix & kFixVel) == kFixVel) continue;
    Vec3 f = unbalanced_force(balls, i, settings.gravity);
    for (int d = 0; d < 3; ++d)
      if (fix & (1u << d)) f[d] = 0.0;
    unbalanced += norm(f);
    ++free_balls;
  }
  if (free_balls == 0) return 0.0;
  double contact = 0.0;
  std::size_t active = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c)
    if (contacts.active[c]) {
      // Magnitudes of the parts, not of their sum: a wet contact in equilibrium carries a Hertz force
      // and an equal and opposite moisture force, and its net force is zero.
      const double fn = contacts.normal_force[c];
      contact += std::sqrt(fn * fn + norm2(contacts.shear_force(c))) + std::abs(contacts.moisture_force[c]);
      ++active;
    }
  unbalanced /= static_cast<double>(free_balls);
  if (active == 0 || contact == 0.0) return unbalanced > 0.0 ? 1.0 : 0.0;
  return unbalanced / (contact / static_cast<double>(active));
}

std::size_t Simulation::make_wet(double suction, double gap) {
  rebuild(std::max(gap, settings.proximity));  // step 1: every pair within the gap has a row
  neighbours_.invalidate();                     // back to the normal reach at the next cycle
  std::size_t wet = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.model[c] != ModelKind::Hill) continue;
    const ContactGeometry g = geometry(c);
    if (g.gap <= gap) {  // steps 2-3: a contact (new ones start here), suction, then make_wet(g_m)
      if (!contacts.exists[c]) create_contact(c, g.normal);
      contacts.hill_params[c].suction = suction;
      contacts.moisture[c] = Moisture::Wet;
    }
    if (contacts.exists[c] && contacts.moisture[c] == Moisture::Wet) ++wet;
  }
  return wet;
}

std::size_t Simulation::make_dry() {
  std::size_t was_wet = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.model[c] != ModelKind::Hill || !contacts.exists[c]) continue;
    if (contacts.moisture[c] == Moisture::Wet) ++was_wet;
    contacts.moisture[c] = Moisture::Dry;
  }
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
