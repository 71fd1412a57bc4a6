// Clumps in the engine (issue 32): pebbles as balls through the one force pass, summed into their
// clumps, moved by the rigid-body law of motion; checkpoints and thread counts.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "../physics/sim_builders.hpp"
#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/state_io.hpp"

namespace hilldem {
namespace {

using testing::granite;
using testing::hill_rule;
using testing::linear_wall_rule;

constexpr double kR = 5e-3;  // [m]

// A floor plane at z = 0 under gravity and local damping α, with the hill model (μ 0.4, damping
// constant γ) between grains and the linear model on the wall.
Simulation floor_scene(double alpha, double gamma) {
  Simulation sim;
  Wall floor;
  floor.name = "floor";
  sim.walls.add(floor);
  sim.table.rules.push_back(hill_rule(0.4, gamma));
  sim.table.rules.push_back(linear_wall_rule(29e6, 0.4));
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = alpha;
  return sim;
}

// Two balls on the floor; auto Δt.
Simulation two_ball_floor() {
  Simulation sim = floor_scene(0.3, 0.07);
  sim.balls.add(granite(1, {0, 0, 5.1e-3}, kR));
  sim.balls.add(granite(2, {10.3e-3, 0.4e-3, 5.2e-3}, kR, {0, 0.05, 0}));
  sim.settings.timestep_max = 1e-6;  // (the automatic Δt before the first contact)
  return sim;
}

const Vec3 kDropAt{5.3e-3, 0.2e-3, 5.2e-3 + 8.72e-3}, kDropV{0.05, -0.02, -0.4}, kDropSpin{10, 60, -5};

ClumpInit init_at(std::int64_t first_id, const Vec3& x, const Vec3& v = {}, const Vec3& w = {}) {
  ClumpInit c;
  c.first_ball_id = first_id;
  c.position = x;
  c.velocity = v;
  c.spin = w;
  c.young_mod = testing::kGraniteE;
  c.pois_ratio = testing::kGraniteNu;
  return c;
}

// The ball columns that are state (not the pebble's fixity, which marks it as moved by its clump).
void expect_same_balls(const Simulation& a, const Simulation& b, const std::string& when) {
  ASSERT_EQ(a.balls.size(), b.balls.size());
  for (std::size_t i = 0; i < a.balls.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(a.balls.position[i][d], b.balls.position[i][d]) << when << " ball " << i << " x" << d;
      EXPECT_EQ(a.balls.velocity[i][d], b.balls.velocity[i][d]) << when << " ball " << i << " v" << d;
      EXPECT_EQ(a.balls.spin[i][d], b.balls.spin[i][d]) << when << " ball " << i << " w" << d;
      EXPECT_EQ(a.balls.contact_force[i][d], b.balls.contact_force[i][d]) << when << " ball " << i << " F" << d;
      EXPECT_EQ(a.balls.contact_moment[i][d], b.balls.contact_moment[i][d]) << when << " ball " << i << " M" << d;
    }
}

// A one-pebble clump is the ball it replaces, bit for bit, in the engine: the same scene once with a
// third ball dropped onto the two (with spin), once with a one-pebble clump of the ball's mass and
// inertia in its place (the ball's row, last), through contacts with balls and the floor, gravity and
// damping, under the automatic time step.
TEST(ClumpEngine, OnePebbleClumpIsBitwiseTheBall) {
  Simulation with_ball = two_ball_floor();
  with_ball.balls.add(granite(3, kDropAt, kR, kDropV));
  with_ball.balls.spin[2] = kDropSpin;

  Simulation with_clump = two_ball_floor();
  Pebbles p;
  p.position = {{0, 0, 0}};
  p.radius = {kR};
  ClumpTemplate t = make_template(p, testing::kGraniteDensity);
  t.mass = with_ball.balls.mass[2];  // the ball's own rounding of (4/3)πR³ρ and (2/5)mR²
  t.principal_inertia = {with_ball.balls.inertia[2], with_ball.balls.inertia[2], with_ball.balls.inertia[2]};
  with_clump.clumps.add(with_clump.balls, t, init_at(3, kDropAt, kDropV, kDropSpin));
  with_clump.invalidate_forces();
  ASSERT_EQ(with_clump.balls.size(), 3u);

  int contacts_seen = 0;
  for (int round = 0; round < 8; ++round) {
    with_ball.cycle(50);
    with_clump.cycle(50);
    ASSERT_EQ(with_ball.time, with_clump.time) << "step " << with_ball.steps;
    expect_same_balls(with_ball, with_clump, "step " + std::to_string(with_ball.steps));
    if (with_ball.find_ball_ball(1, 3) >= 0 || with_ball.find_ball_ball(2, 3) >= 0) ++contacts_seen;
  }
  EXPECT_GE(contacts_seen, 2) << "the dropped ball must touch the others";
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(with_clump.clumps.state.position[0][d], with_ball.balls.position[2][d]);
    EXPECT_EQ(with_clump.clumps.state.spin[0][d], with_ball.balls.spin[2][d]);
  }
}

// An elongated clump of three equal pebbles (radius 2.5 mm, 11 mm long).
ClumpTemplate rod() {
  Pebbles p;
  p.position = {{-3e-3, 0, 0}, {0, 0, 0}, {3e-3, 0, 0}};
  p.radius = {2.5e-3, 2.5e-3, 2.5e-3};
  return make_template(p, testing::kGraniteDensity, 64);
}

Simulation rod_on_floor(double damping) {
  Simulation sim = floor_scene(damping, 0.2);
  ClumpInit c = init_at(1, {0, 0, 6e-3});
  c.orientation = normalized(Quat{1.0, 0.1, 0.15, 0.05});  // tilted: it lands on one end first
  sim.clumps.add(sim.balls, rod(), c);
  sim.invalidate_forces();
  return sim;
}

// A clump dropped onto a plane comes to rest, lying on its pebbles: its energy decays, the
// unbalanced-force ratio falls to 1e-6, the floor carries its weight, and it lies flat on its end
// pebbles (a tilted rod's lowest points; its axis horizontal, its centre one radius up).
TEST(ClumpEngine, DroppedClumpComesToRestOnThePlane) {
  Simulation sim = rod_on_floor(0.7);
  const double m = sim.clumps.state.mass[0];
  auto energy = [&] {
    const ClumpState& s = sim.clumps.state;
    return 0.5 * m * norm2(s.velocity[0]) + rotational_energy(s, 0) + m * 9.81 * s.position[0].z;
  };
  const double e0 = energy();
  const std::int64_t used = sim.solve(1e-6, 400000);
  ASSERT_GT(used, 0) << "not at rest after 400000 steps, ratio " << sim.mean_unbalanced_ratio();
  EXPECT_LT(energy(), e0);
  EXPECT_LT(sim.mean_unbalanced_ratio(), 1e-6);
  EXPECT_NEAR(-sim.walls.walls[0].force.z, m * 9.81, 1e-4 * m * 9.81);
  EXPECT_GE(sim.find_ball_wall(1, 0), 0) << "end pebble 1 touches the floor";
  EXPECT_GE(sim.find_ball_wall(3, 0), 0) << "end pebble 3 touches the floor";
  EXPECT_NEAR(sim.clumps.state.position[0].z, 2.5e-3, 0.02e-3) << "lying flat, one pebble radius up";
  const Vec3 axis = rotate(sim.clumps.state.orientation[0], Vec3{1, 0, 0});
  EXPECT_LT(std::abs(axis.z), 1e-3) << "its long axis horizontal";
}

// Two clumps collide, with no damping, gravity or walls: linear and angular momentum (about the
// origin) are conserved through the contact, to rounding.
TEST(ClumpEngine, CollidingClumpsConserveMomentum) {
  Simulation sim;
  ModelRule r = testing::hill_rule(0.4, 0.0);
  sim.table.rules.push_back(r);
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 2e-7;
  ClumpInit a = init_at(1, {-6e-3, 0.5e-3, 0}, {0.5, 0, 0}, {0, 0, 20});
  a.orientation = normalized(Quat{1, 0.2, 0.1, 0.3});
  ClumpInit b = init_at(10, {6e-3, -0.8e-3, 0.3e-3}, {-0.4, 0.05, 0}, {5, -10, 0});
  b.orientation = normalized(Quat{0.3, 1, -0.2, 0.1});
  sim.clumps.add(sim.balls, rod(), a);
  sim.clumps.add(sim.balls, rod(), b);
  sim.invalidate_forces();
  auto momentum = [&](Vec3& p, Vec3& l) {
    const ClumpState& s = sim.clumps.state;
    p = l = Vec3{};
    for (std::size_t i = 0; i < 2; ++i) {
      p += s.velocity[i] * s.mass[i];
      l += cross(s.position[i], s.velocity[i] * s.mass[i]) + angular_momentum(s, i);
    }
  };
  Vec3 p0, l0, p1, l1;
  // (Velocities at half steps: the momenta are compared at the same phase, before and after.)
  momentum(p0, l0);
  std::int64_t touching = 0;
  for (int k = 0; k < 200; ++k) {
    sim.cycle(100);
    touching += sim.contact_count() > 0;
  }
  momentum(p1, l1);
  ASSERT_GT(touching, 0) << "the clumps must collide";
  EXPECT_EQ(sim.contact_count(), 0u) << "and part again";
  const double ps = sim.clumps.state.mass[0] * 0.5, ls = ps * 6e-3;
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(p1[d], p0[d], 1e-12 * ps) << d;
    EXPECT_NEAR(l1[d], l0[d], 1e-12 * ls) << d;
  }
  // Something was exchanged: the first clump's velocity changed.
  EXPECT_GT(std::abs(sim.clumps.state.velocity[0].x - 0.5), 0.1);
}

// A bed of clumps and balls in a box: falls and collides (used by the restart and thread tests).
Simulation clump_bed() {
  Simulation sim = floor_scene(0.5, 0.1);
  sim.settings.auto_timestep = false;  // (the automatic Δt before the first contact is timestep_max)
  sim.settings.timestep = 4e-6;
  std::int64_t id = 1;
  // Three layers of four, standing: rods upright (tilted a little, each its own way) and balls,
  // 0.8 mm apart side by side and 1 mm above each other, falling at 0.3 m/s: they land and tip over
  // onto their neighbours.
  for (int k = 0; k < 12; ++k) {
    const Vec3 x{(k % 2) * 5.8e-3, ((k / 2) % 2) * 5.8e-3, 5.6e-3 + (k / 4) * 12e-3};
    const Vec3 v{0, 0, -0.3};
    if (k % 4 == 3) {
      sim.balls.add(granite(id++, x, 2.5e-3, v));
      continue;
    }
    ClumpInit c = init_at(id, x, v, {k * 3.0, -2.0 * k, 1.0});
    c.orientation = normalized(Quat{0.7071, 0.02 * (k % 3) - 0.02, -0.7071, 0.015 * k - 0.08});
    sim.clumps.add(sim.balls, rod(), c);
    id += 3;
  }
  sim.invalidate_forces();
  return sim;
}

// Restart is bitwise with clumps: a checkpoint mid-run, read back and cycled on, ends bitwise where
// the uninterrupted run does (clump state included: state_bytes compares every clump column).
// Cycles in calls of 100; the most pebble-pebble and pebble-ball contacts at the end of one.
std::size_t cycle_bed(Simulation& sim, int calls) {
  std::size_t most = 0;
  for (int k = 0; k < calls; ++k) {
    sim.cycle(100);
    std::size_t pairs = 0;
    for (std::size_t c = 0; c < sim.contacts.size(); ++c)
      pairs += sim.contacts.exists[c] && sim.contacts.key[c].kind == ContactKind::BallBall;
    most = std::max(most, pairs);
  }
  return most;
}

TEST(ClumpEngine, RestartIsBitwise) {
  Simulation whole = clump_bed();
  const std::size_t most = cycle_bed(whole, 80);
  Simulation first = clump_bed();
  cycle_bed(first, 37);
  CheckpointWriter w;
  write_simulation(w, first);
  const CheckpointReader r = CheckpointReader::from_bytes(w.bytes(), "mem");
  ASSERT_TRUE(r.has("sim.clumps"));
  Simulation resumed;
  read_simulation(r, resumed);
  ASSERT_EQ(resumed.clumps.size(), first.clumps.size());
  EXPECT_EQ(state_bytes(resumed), state_bytes(first));
  cycle_bed(resumed, 43);
  EXPECT_GE(most, 3u) << "the bed's grains must touch";
  EXPECT_EQ(state_difference(resumed, whole), "");
  EXPECT_EQ(state_digest(resumed), state_digest(whole));
}

// A checkpoint without clumps has no clump section (it is as before clumps existed).
TEST(ClumpEngine, CheckpointWithoutClumpsHasNoClumpSection) {
  Simulation sim = two_ball_floor();
  sim.cycle(10);
  CheckpointWriter w;
  write_simulation(w, sim);
  EXPECT_FALSE(CheckpointReader::from_bytes(w.bytes(), "mem").has("sim.clumps"));
}

// The same bits for one and two threads with clumps.
TEST(ClumpEngine, ThreadCountIndependent) {
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  Simulation one = clump_bed();
  const std::size_t most = cycle_bed(one, 70);
  omp_set_num_threads(2);
  Simulation two = clump_bed();
  two.thread_shares = {0.3, 0.7};  // an uneven split of the work
  cycle_bed(two, 70);
  omp_set_num_threads(threads);
  EXPECT_GE(most, 3u) << "the bed's grains must touch";
  EXPECT_EQ(state_difference(one, two), "");
}

// No neighbour rows between pebbles of one clump; the time step knows the clump.
TEST(ClumpEngine, NoRowsWithinAClumpAndTheTimeStepSeesTheClump) {
  Simulation sim = rod_on_floor(0.0);
  sim.update_forces();
  for (const ContactKey& k : sim.contacts.key) EXPECT_NE(k.kind, ContactKind::BallBall);
  sim.clumps.state.position[0].z = 2.9e-3;  // pressed into the floor
  sim.invalidate_forces();
  sim.update_forces();
  const double dt = sim.estimate_timestep();
  ASSERT_GT(dt, 0.0);
  // The clump's translational bound alone: √(m / Σ k_tran) of its floor contacts, times the safety.
  double k_tran = 0.0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.active[c]) k_tran += sim.contacts.k_tran[c];
  ASSERT_GT(k_tran, 0.0);
  EXPECT_LE(dt, 0.8 * std::sqrt(sim.clumps.state.mass[0] / k_tran) * (1 + 1e-12));
}

}  // namespace
}  // namespace hilldem
