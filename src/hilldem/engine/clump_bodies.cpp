#include "hilldem/engine/clump_bodies.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hilldem/core/error.hpp"

namespace hilldem {

std::size_t ClumpBodies::add(BallStore& balls, const ClumpTemplate& t, const ClumpInit& c) {
  const std::size_t first = pebbles.size();
  const std::size_t i = add_clump(state, pebbles, t, c.position, c.velocity, c.orientation, c.spin, c.fixity);
  groups.push_back(c.groups);
  for (std::size_t k = first; k < pebbles.size(); ++k) {
    BallInit b;
    b.id = c.first_ball_id + static_cast<std::int64_t>(k - first);
    b.position = pebble_position(state, pebbles, k);
    b.radius = pebbles.radius[k];
    b.density = t.density;
    b.young_mod = c.young_mod;
    b.pois_ratio = c.pois_ratio;
    b.velocity = pebble_velocity(state, pebbles, k);
    b.spin = c.spin;
    b.fixity = kFixAll;  // moved by its clump (place_pebbles), not by the balls' law of motion
    b.groups = c.groups;
    const std::size_t row = balls.add(b);
    balls.mass[row] = t.mass;  // the clump's: the contact mappings' mass (spec §2.4)
    const Vec3& in = t.principal_inertia;
    balls.inertia[row] = std::min(in.x, std::min(in.y, in.z));
    ball.push_back(static_cast<std::uint32_t>(row));
  }
  return i;
}

std::vector<std::uint32_t> ClumpBodies::clump_of_balls(std::size_t n) const {
  if (empty()) return {};
  std::vector<std::uint32_t> of(n, kNoClump);
  for (std::size_t k = 0; k < ball.size(); ++k)
    if (ball[k] < n) of[ball[k]] = pebbles.clump[k];
  return of;
}

void ClumpBodies::place_pebbles(BallStore& balls) const {
  for (std::size_t k = 0; k < pebbles.size(); ++k) place_pebble(balls, k);
}

void ClumpBodies::place_pebble(BallStore& balls, std::size_t k) const {
  const std::uint32_t b = ball[k];
  balls.position[b] = pebble_position(state, pebbles, k);
  balls.velocity[b] = pebble_velocity(state, pebbles, k);
  balls.spin[b] = state.spin[pebbles.clump[k]];
}

void ClumpBodies::loads(const BallStore& balls, const motion::ContactSums* sums) {
  // Each pebble's load acts at its centre at t, from its clump's state (its ball's column may have
  // been moved on by the balls' law of motion): the force pass's moment on a ball is about its centre.
  const std::size_t n = pebbles.size();
  std::vector<Vec3> point(n), f(n), m(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t b = ball[k];
    point[k] = pebble_position(state, pebbles, k);
    Vec3 fc = balls.contact_force[b], mc = balls.contact_moment[b];
    if (sums) {
      fc = {sums[b].force[0], sums[b].force[1], sums[b].force[2]};
      mc = {sums[b].moment[0], sums[b].moment[1], sums[b].moment[2]};
    }
    f[k] = fc + balls.applied_force[b];
    m[k] = mc + balls.applied_moment[b];
  }
  sum_pebble_loads(state, pebbles, point, f, m, force, torque);
}

void ClumpBodies::advance(BallStore& balls, const motion::ContactSums* sums, const RigidMotionSettings& m,
                          double dt) {
  loads(balls, sums);
  advance_clumps(state, force, torque, m, dt);
  place_pebbles(balls);
}

double ClumpBodies::critical_timestep2(const std::vector<double>& k_tran_of_pebble,
                                       const std::vector<double>& k_rot_of_pebble) const {
  std::vector<double> tran(size(), 0.0), rot(size(), 0.0);
  for (std::size_t k = 0; k < pebbles.size(); ++k) {
    const double p = norm(pebbles.body_position[k]);
    tran[pebbles.clump[k]] += k_tran_of_pebble[k];
    rot[pebbles.clump[k]] += k_rot_of_pebble[k] + k_tran_of_pebble[k] * p * (p + 2.0 * pebbles.radius[k]);
  }
  double crit2 = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < size(); ++j) {
    const Vec3& in = state.principal_inertia[j];
    if (tran[j] > 0.0) crit2 = std::min(crit2, state.mass[j] / tran[j]);
    if (rot[j] > 0.0) crit2 = std::min(crit2, std::min(in.x, std::min(in.y, in.z)) / rot[j]);
  }
  return crit2;
}

void ClumpBodies::balls_permuted(const std::vector<std::uint32_t>& order) {
  std::vector<std::uint32_t> new_row(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) new_row[order[k]] = static_cast<std::uint32_t>(k);
  for (std::uint32_t& b : ball) b = new_row[b];
}

void ClumpBodies::check(const BallStore& balls) const {
  const std::size_t n = pebbles.size();
  if (ball.size() != n || groups.size() != state.size() || pebbles.body_position.size() != n ||
      pebbles.radius.size() != n)
    throw RunError("clumps: the pebble and clump columns have different lengths");
  std::vector<char> taken(balls.size(), 0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t b = ball[k];
    if (pebbles.clump[k] >= state.size())
      throw RunError("clumps: pebble " + std::to_string(k) + " belongs to clump " + std::to_string(pebbles.clump[k]) +
                     ", there are " + std::to_string(state.size()));
    if (b >= balls.size() || taken[b])
      throw RunError("clumps: pebble " + std::to_string(k) + " has no ball of its own (row " + std::to_string(b) + ")");
    taken[b] = 1;
    if (balls.radius[b] != pebbles.radius[k])
      throw RunError("clumps: pebble " + std::to_string(k) + " and its ball " + std::to_string(balls.id[b]) +
                     " have different radii");
  }
}

}  // namespace hilldem
