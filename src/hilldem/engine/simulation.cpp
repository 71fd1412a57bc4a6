#include "hilldem/engine/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/core/error.hpp"

namespace hilldem {

void Simulation::cycle(std::int64_t n) {
  for (std::int64_t k = 0; k < n; ++k) step_once();
}

std::int64_t Simulation::solve(double ratio, std::int64_t max_steps) {
  // At least one cycle: forces may be stale (make_wet changes them only on the next cycle, §2.7).
  for (std::int64_t k = 1; k <= max_steps; ++k) {
    step_once();
    if (mean_unbalanced_ratio() <= ratio) return k;
  }
  return -1;
}

void Simulation::update_forces() {
  detect(settings.proximity);
  force_pass(0.0);
  forces_ready_ = true;
}

double Simulation::next_timestep() const {
  if (!settings.auto_timestep) return settings.timestep;
  const double dt = estimate_timestep();
  if (dt > 0.0) return std::min(dt, settings.timestep_max);
  return last_dt > 0.0 ? last_dt : settings.timestep_max;
}

void Simulation::step_once() {
  if (!forces_ready_) update_forces();
  const double dt = next_timestep();
  advance_balls(balls, MotionSettings{settings.gravity, settings.local_damping}, dt);  // spec §1.2 steps 1-2
  for (Wall& w : walls.walls) advance_wall(w, dt);
  detect(settings.proximity);                                                           // step 3
  force_pass(dt);                                                                       // step 4
  time += dt;
  ++steps;
  last_dt = dt;
  for (const auto& obs : observers) obs(*this);
}

ContactGeometry Simulation::geometry(std::size_t c) const {
  const ContactKey& k = contacts.key[c];
  const Vec3& x1 = balls.position[k.a];
  const double r1 = balls.radius[k.a];
  ContactGeometry g;
  if (k.kind == ContactKind::BallBall) {
    const Vec3 d = balls.position[k.b] - x1;
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

std::uint64_t Simulation::piece2_groups(const ContactKey& k) const {
  return k.kind == ContactKind::BallBall ? balls.groups[k.b] : walls.walls[k.b].groups;
}

void Simulation::compute_mapping(ContactStore& store, std::size_t c) const {
  const ContactKey& k = store.key[c];
  if (store.model[c] == ModelKind::Linear) {
    const double r2 = k.kind == ContactKind::BallBall ? balls.radius[k.b] : 0.0;
    store.linear_map[c] = linear_mapping(store.linear_params[c], balls.radius[k.a], r2);
  } else {
    const std::size_t a = k.a, b = k.b;  // hill contacts are ball-ball only (checked by the table)
    store.hill_map[c] = hill_mapping(store.hill_params[c],
                                        HillBodies{balls.radius[a], balls.radius[b], balls.young_mod[a],
                                                   balls.young_mod[b], balls.pois_ratio[a], balls.pois_ratio[b],
                                                   balls.mass[a], balls.mass[b]});
  }
}

void Simulation::refresh_mappings() {
  for (std::size_t c = 0; c < contacts.size(); ++c) compute_mapping(contacts, c);
}

void Simulation::detect(double proximity) {
  // Candidate keys, sorted: ball-ball pairs from the cell grid, ball-wall pairs by direct test.
  std::vector<ContactKey> candidates;
  for (const auto& [i, j] : find_ball_pairs(balls.position, balls.radius, proximity))
    candidates.push_back({i, ContactKind::BallBall, j});
  for (std::uint32_t w = 0; w < walls.size(); ++w)
    for (std::uint32_t i = 0; i < balls.size(); ++i) {
      const auto touch = wall_touch(walls.walls[w], balls.position[i], balls.radius[i]);
      if (touch && touch->gap <= proximity) candidates.push_back({i, ContactKind::BallWall, w});
    }
  std::sort(candidates.begin(), candidates.end());

  // Merge with the existing contacts (also sorted): history survives re-detection. A contact that is
  // no longer a candidate is kept only while it must be (a wet hill contact, spec §2.5).
  ContactStore next;
  unassigned_pairs_ = 0;
  std::size_t o = 0;
  auto keep_old_if_needed = [&](std::size_t i) {
    if (contacts.model[i] == ModelKind::Hill && contacts.moisture[i] == Moisture::Wet) next.append_row(contacts, i);
  };
  for (const ContactKey& key : candidates) {
    while (o < contacts.size() && contacts.key[o] < key) keep_old_if_needed(o++);
    if (o < contacts.size() && contacts.key[o] == key) {
      next.append_row(contacts, o++);
      continue;
    }
    const int r = table.match(key.kind, balls.groups[key.a], piece2_groups(key));
    if (r < 0) {
      ++unassigned_pairs_;
      continue;
    }
    const ModelRule& rule = table.rules[r];
    const Vec3 n0 = key.kind == ContactKind::BallBall
                        ? unit_or_zero(balls.position[key.b] - balls.position[key.a])
                        : wall_touch(walls.walls[key.b], balls.position[key.a], balls.radius[key.a])->normal;
    next.append_new(key, r, rule.model, rule.linear, rule.hill, n0);
    compute_mapping(next, next.size() - 1);
  }
  while (o < contacts.size()) keep_old_if_needed(o++);
  contacts = std::move(next);
}

void Simulation::force_pass(double dt) {
  std::fill(balls.contact_force.begin(), balls.contact_force.end(), Vec3{});
  std::fill(balls.contact_moment.begin(), balls.contact_moment.end(), Vec3{});
  for (Wall& w : walls.walls) w.force = w.moment = Vec3{};

  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const ContactKey& key = contacts.key[c];
    const ContactGeometry g = geometry(c);
    const std::size_t a = key.a;
    const bool ball2 = key.kind == ContactKind::BallBall;

    // Relative velocity of the material points at x_c (spec §1.2) and the mean spin about n̂_c.
    const Vec3 v1 = balls.velocity[a] + cross(balls.spin[a], g.point - balls.position[a]);
    Vec3 v2, spin2;
    if (ball2) {
      v2 = balls.velocity[key.b] + cross(balls.spin[key.b], g.point - balls.position[key.b]);
      spin2 = balls.spin[key.b];
    } else {
      v2 = wall_point_velocity(walls.walls[key.b], g.point);
      spin2 = walls.walls[key.b].spin;
    }
    const double mean_spin_n = 0.5 * dot(balls.spin[a] + spin2, g.normal);
    const Vec3 n_old = contacts.normal[c];
    const ContactKinematics kin{g.normal, g.gap, v2 - v1, dt};

    Vec3 force, shear;
    double fn = 0.0, fm = 0.0, trial = 0.0;
    bool active = false;
    if (contacts.model[c] == ModelKind::Linear) {
      const LinearState prev{carry_into_plane(contacts.shear_state[c], n_old, g.normal, mean_spin_n, dt)};
      const LinearResult r = linear_force(contacts.linear_params[c], contacts.linear_map[c], kin, prev);
      contacts.shear_state[c] = r.state.shear_force;
      force = r.force, shear = r.shear_force, fn = r.normal_force, trial = r.trial_shear, active = r.active;
    } else {
      const HillState prev{carry_into_plane(contacts.shear_state[c], n_old, g.normal, mean_spin_n, dt),
                           contacts.moisture[c]};
      const HillResult r = hill_force(contacts.hill_params[c], contacts.hill_map[c], kin, prev);
      contacts.shear_state[c] = r.state.shear_hm;
      contacts.moisture[c] = r.state.moisture;
      force = r.force, shear = r.shear_force, fn = r.surface_normal, fm = r.moisture_force;
      trial = r.trial_shear, active = r.active;
    }
    // Accumulated shear displacement (reported, not used by the laws): carried like the force.
    contacts.shear_disp[c] = active ? carry_into_plane(contacts.shear_disp[c], n_old, g.normal, mean_spin_n, dt) +
                                          kin.shear_rate() * dt
                                    : Vec3{};
    contacts.normal[c] = g.normal;
    contacts.gap[c] = g.gap;
    contacts.point[c] = g.point;
    contacts.force[c] = force;
    contacts.normal_force[c] = fn;
    contacts.moisture_force[c] = fm;
    contacts.shear_force[c] = shear;
    contacts.trial_shear[c] = trial;
    contacts.active[c] = active;
    if (!active) continue;

    // Force on piece 2 is F_c, on piece 1 it is −F_c (spec conventions); moments about each centre.
    balls.contact_force[a] -= force;
    balls.contact_moment[a] -= cross(g.point - balls.position[a], force);
    if (ball2) {
      balls.contact_force[key.b] += force;
      balls.contact_moment[key.b] += cross(g.point - balls.position[key.b], force);
    } else {
      Wall& w = walls.walls[key.b];
      w.force += force;
      w.moment += cross(g.point - w.rotation_center, force);
    }
    if (!std::isfinite(force.x + force.y + force.z)) {
      std::ostringstream msg;
      msg << "non-finite contact force at step " << steps + 1 << " between ball " << balls.id[a] << " and "
          << (ball2 ? "ball " + std::to_string(balls.id[key.b]) : "wall '" + walls.walls[key.b].name + "'")
          << " (gap " << g.gap << " m): the run is unstable; reduce the time step";
      throw RunError(msg.str());
    }
  }
}

double Simulation::estimate_timestep() const {
  // Per-body sums of the contact-returned stiffnesses (spec §4): k_tran = Σ(k̂_n + k̂_s),
  // k_rot = Σ k̂_s |x_c − x|². Δt_crit = min(√(m/k_tran), √(I/k_rot)).
  std::vector<double> k_tran(balls.size(), 0.0), k_rot(balls.size(), 0.0);
  bool any = false;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const ContactGeometry g = geometry(c);
    if (!g.valid) continue;
    StiffnessEstimate s;
    if (contacts.model[c] == ModelKind::Linear) {
      if (g.gap > 0.0) continue;  // inactive
      s = {contacts.linear_map[c].kn, contacts.linear_map[c].ks};
    } else {
      if (!hill_active(contacts.moisture[c], g.gap)) continue;
      s = hill_timestep_stiffness(contacts.hill_params[c], contacts.hill_map[c], g.gap);
    }
    any = true;
    const ContactKey& k = contacts.key[c];
    auto add = [&](std::size_t i) {
      k_tran[i] += s.kn + s.ks;
      k_rot[i] += s.ks * norm2(g.point - balls.position[i]);
    };
    add(k.a);
    if (k.kind == ContactKind::BallBall) add(k.b);
  }
  if (!any) return 0.0;
  double crit = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (k_tran[i] > 0.0) crit = std::min(crit, std::sqrt(balls.mass[i] / k_tran[i]));
    if (k_rot[i] > 0.0) crit = std::min(crit, std::sqrt(balls.inertia[i] / k_rot[i]));
  }
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
      contact += std::sqrt(fn * fn + norm2(contacts.shear_force[c])) + std::abs(contacts.moisture_force[c]);
      ++active;
    }
  unbalanced /= static_cast<double>(free_balls);
  if (active == 0 || contact == 0.0) return unbalanced > 0.0 ? 1.0 : 0.0;
  return unbalanced / (contact / static_cast<double>(active));
}

std::size_t Simulation::make_wet(double suction, double gap) {
  detect(std::max(gap, settings.proximity));  // step 1: contacts for every pair within the gap
  std::size_t wet = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.model[c] != ModelKind::Hill) continue;
    if (geometry(c).gap <= gap) {  // steps 2-3: suction, then make_wet(g_m)
      contacts.hill_params[c].suction = suction;
      contacts.moisture[c] = Moisture::Wet;
    }
    if (contacts.moisture[c] == Moisture::Wet) ++wet;
  }
  return wet;
}

std::size_t Simulation::make_dry() {
  std::size_t was_wet = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.model[c] != ModelKind::Hill) continue;
    if (contacts.moisture[c] == Moisture::Wet) ++was_wet;
    contacts.moisture[c] = Moisture::Dry;
  }
  return was_wet;
}

long Simulation::find_ball_ball(std::int64_t id1, std::int64_t id2) const {
  long a = balls.find(id1), b = balls.find(id2);
  if (a < 0 || b < 0) return -1;
  if (a > b) std::swap(a, b);
  return contacts.find({static_cast<std::uint32_t>(a), ContactKind::BallBall, static_cast<std::uint32_t>(b)});
}

long Simulation::find_ball_wall(std::int64_t ball_id, std::size_t wall) const {
  const long a = balls.find(ball_id);
  if (a < 0) return -1;
  return contacts.find({static_cast<std::uint32_t>(a), ContactKind::BallWall, static_cast<std::uint32_t>(wall)});
}

}  // namespace hilldem
