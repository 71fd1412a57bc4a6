// Within one cycle() call the law of motion moves the force pass's ball records; the first step of a
// call moves the BallStore's columns. Long calls against calls of one step each: the same law
// (motion/ball_step.hpp) and the same travel, so the same bits; and the columns hold the balls'
// state whenever anyone outside the cycle can look: after every cycle() call, in every observer and
// controller, after a run that threw.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "hilldem/bench/bed_bench.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/packing_import.hpp"
#include "sim_builders.hpp"

namespace hilldem {
namespace {
using testing::granite_row;
using testing::random_box;

// Every ball's position, velocity and spin, bit for bit.
struct State {
  std::vector<Vec3> position, velocity, spin;
  std::int64_t rebuilds = 0;
  std::size_t contacts = 0;
};
State state(const Simulation& sim) {
  return {sim.balls.position, sim.balls.velocity, sim.balls.spin, sim.rebuilds(), sim.contact_count()};
}
bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }
void expect_same(const State& a, const State& b) {
  EXPECT_EQ(a.rebuilds, b.rebuilds);
  EXPECT_EQ(a.contacts, b.contacts);
  ASSERT_EQ(a.position.size(), b.position.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.position.size(); ++i)
    differ += !same_bits(a.position[i], b.position[i]) || !same_bits(a.velocity[i], b.velocity[i]) ||
              !same_bits(a.spin[i], b.spin[i]);
  EXPECT_EQ(differ, 0u) << "balls whose state differs";
}

// A box of 600 grains thrown about under gravity, with local damping, walls (linear rows through
// wall_block and force_row), a few balls fixed in some directions, wet half way.
Simulation busy_box() {
  Simulation sim = random_box(600, 33);
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.3;
  for (std::size_t i = 0; i < sim.balls.size(); i += 37) sim.balls.fixity[i] = static_cast<FixityMask>(i % 64);
  return sim;
}

// n steps in one cycle() call (records: the records carry the state from step to step), or in n calls
// of one step (each moves the columns).
void advance(Simulation& sim, bool records, std::int64_t n) {
  if (records) {
    sim.cycle(n);
  } else {
    for (std::int64_t k = 0; k < n; ++k) sim.cycle(1);
  }
}

// Long cycle() calls (the records carry the state from step to step), dry then wet, in a walled box
// and in a periodic one (rebuilds wrap the positions), and with density scaling.
TEST(Motion, RecordsOrColumnsGiveTheSameBits) {
  auto walled = [](bool records) {
    Simulation sim = busy_box();
    advance(sim, records, 400);
    sim.make_wet(20e3, 0.5e-3);
    advance(sim, records, 400);
    return state(sim);
  };
  const State a = walled(true), b = walled(false);
  EXPECT_GT(a.rebuilds, 2);
  EXPECT_GT(a.contacts, 100u);
  expect_same(a, b);

  auto periodic = [](bool records) {
    Simulation sim = random_box(400, 8, /*walls=*/false);
    sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = sim.settings.box.periodic[2] = true;
    sim.settings.box.hi = {0.04, 0.04, 0.04};
    for (std::size_t i = 0; i < sim.balls.size(); ++i) {
      sim.balls.velocity[i] *= 10.0;                    // [m/s]
      sim.balls.position[i] += Vec3{0.02, 0.013, 0.0};  // [m] the boundaries cut the cloud
    }
    advance(sim, records, 600);
    return state(sim);
  };
  const State p = periodic(true), q = periodic(false);
  EXPECT_GT(p.rebuilds, 2);
  expect_same(p, q);

  auto scaled = [](bool records) {
    Simulation sim = busy_box();
    sim.settings.auto_timestep = false;
    sim.settings.timestep = 4e-6;  // [s]
    sim.settings.density_scaling = true;
    advance(sim, records, 500);
    return state(sim);
  };
  expect_same(scaled(true), scaled(false));

  // Applied loads on a few balls (the motion then reads them: motion::step_ball<true>).
  auto loaded = [](bool records) {
    Simulation sim = busy_box();
    for (std::size_t i = 3; i < sim.balls.size(); i += 50) {
      sim.balls.applied_force[i] = {0.0, 0.0, 0.02};  // [N]
      sim.balls.applied_moment[i] = {1e-5, 0.0, 0.0};  // [N m]
    }
    advance(sim, records, 300);
    return state(sim);
  };
  expect_same(loaded(true), loaded(false));
}

// What the caller writes into the columns between cycle() calls counts, and so does what a
// controller writes there before the motion of its step; observers see the step's state.
TEST(Motion, ColumnsAreTheStateWheneverSomeoneLooks) {
  auto run = [](bool records, std::vector<Vec3>* seen) {
    Simulation sim = busy_box();
    advance(sim, records, 150);
    sim.balls.velocity[5] = {0.3, -0.2, 0.1};  // [m/s] by hand, between two calls
    sim.balls.position[6] += Vec3{0.0, 0.0, 1e-4};  // [m]
    sim.invalidate_neighbours();
    advance(sim, records, 150);
    for (double& r : sim.balls.radius) r *= 0.7;  // [m] a new mean radius: a new skin (and new rebuilds)
    sim.refresh_mappings();
    sim.invalidate_neighbours();
    advance(sim, records, 150);
    // (Held at 0.1 m/s upwards against gravity: the step's motion must start from it.)
    sim.controllers.push_back([](Simulation& s, double) { s.balls.velocity[7] = {0.0, 0.0, 0.1}; });  // [m/s]
    sim.observers.push_back([seen](const Simulation& s) { seen->push_back(s.balls.position[8]); });
    advance(sim, records, 100);
    sim.controllers.clear();
    advance(sim, records, 100);  // (the observer still looks)
    return state(sim);
  };
  std::vector<Vec3> seen_records, seen_columns;
  const State a = run(true, &seen_records), b = run(false, &seen_columns);
  expect_same(a, b);
  ASSERT_EQ(seen_records.size(), 200u);
  ASSERT_EQ(seen_columns.size(), 200u);
  for (std::size_t k = 0; k < seen_records.size(); ++k) EXPECT_TRUE(same_bits(seen_records[k], seen_columns[k])) << k;
  // Each step's own position, not the last one's (the ball moves).
  EXPECT_FALSE(same_bits(seen_records.front(), seen_records.back()));
}

// `steps` cycles of `sim` in one call (records) or one at a time, to the RunError it must end in: the
// error's message and the balls' state.
std::pair<std::string, State> failing_run(Simulation sim, bool records, std::int64_t steps) {
  std::string message;
  try {
    advance(sim, records, steps);
  } catch (const RunError& e) {
    message = e.what();
  }
  return {message, state(sim)};
}

// Steps nobody watches leave the columns behind the records; a run that fails in one of them still
// leaves its state in the columns (the state where it stopped, as the column motion does), whether
// the travel check throws or the force pass does.
TEST(Motion, ColumnsHoldTheStateAfterARunFails) {
  Simulation blows_up = busy_box();
  blows_up.settings.auto_timestep = false;
  blows_up.settings.timestep = 2e-4;  // [s] far beyond the critical step
  const auto [message_records, records] = failing_run(blows_up, true, 100000);
  const auto [message_columns, columns] = failing_run(blows_up, false, 100000);
  EXPECT_NE(message_records.find("non-finite position"), std::string::npos) << message_records;
  EXPECT_EQ(message_records, message_columns);
  expect_same(records, columns);

  // A ball with a NaN applied moment spins NaN from the first step, and its contact, made some steps
  // later, has no finite force.
  Simulation spins = granite_row({0.1e-3});  // [m]
  spins.balls.velocity[0] = {1.0, 0.0, 0.0};  // [m/s] towards ball 2: they touch after ≈ 100 steps
  spins.balls.applied_moment[0] = {0.0, 0.0, std::nan("")};
  const auto [spin_message_records, spin_records] = failing_run(spins, true, 1000);
  const auto [spin_message_columns, spin_columns] = failing_run(spins, false, 1000);
  EXPECT_NE(spin_message_records.find("non-finite contact force"), std::string::npos) << spin_message_records;
  EXPECT_EQ(spin_message_records, spin_message_columns);
  expect_same(spin_records, spin_columns);
}

// The BallStore's contact_force column against the rows' forces: −F_c into piece 1 and F_c into a
// ball that is piece 2, summed in another order (so within rounding). The force pass adds them up in
// its own line per ball and writes the column on every pass someone may read it after.
double worst_force_sum_error(const Simulation& sim) {
  std::vector<Vec3> sum(sim.balls.size());
  std::vector<double> scale(sim.balls.size(), 0.0);
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) {
    const ContactKey& k = sim.contacts.key[c];
    const Vec3& f = sim.contacts.force[c];
    sum[k.a] -= f;
    scale[k.a] += norm(f);
    if (k.kind == ContactKind::BallBall) {
      sum[k.b] += f;
      scale[k.b] += norm(f);
    }
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < sum.size(); ++i)
    worst = std::max(worst, norm(sim.balls.contact_force[i] - sum[i]) / std::max(scale[i], 1e-300));
  return worst;
}

// The settled bed of `hilldem bench` (11,200 grains, ≈ 4.7 contacts each, a floor, periodic in x and
// y; with more than one thread, rows whose second ball lies in another thread's range).
TEST(Motion, ForceColumnsAreTheRowsSumsWheneverSomeoneLooks) {
  const Packing bed = read_packing(HILLDEM_SOURCE_DIR "/bench/bed_settled.data", PackingFormat::Lammps);
  for (const bool records : {true, false}) {
    Simulation sim = make_bed(bed);
    advance(sim, records, 200);  // (records: only the last step watched)
    EXPECT_LT(worst_force_sum_error(sim), 1e-12) << records;
    EXPECT_GT(sim.contact_count(), 20000u);
    // An observer sees each step's sums (every step watched).
    double worst = 0.0;
    sim.observers.push_back([&worst](const Simulation& s) { worst = std::max(worst, worst_force_sum_error(s)); });
    sim.cycle(20);
    EXPECT_LT(worst, 1e-12) << records;
  }
}

// Each thread ends its own balls' force sums: the crossing shares from the ranges below, as soon as
// each is final, then its balls' floor rows. One, two and three threads: the same bits in the balls,
// and in the floor's sums after each call.
TEST(Motion, ThreadsEndTheirOwnSumsWithTheSameBits) {
  const Packing bed = read_packing(HILLDEM_SOURCE_DIR "/bench/bed_settled.data", PackingFormat::Lammps);
  struct Run {
    State state;
    std::vector<Wall> floor;
  };
  auto run = [&bed](int threads) {
    omp_set_num_threads(threads);
    Simulation sim = make_bed(bed);
    sim.settings.local_damping = 0.0;  // (the balls keep moving)
    std::vector<Wall> floor;
    for (int k = 0; k < 3; ++k) {
      sim.cycle(40);
      floor.push_back(sim.walls.walls[0]);
    }
    omp_set_num_threads(omp_get_num_procs());
    return Run{state(sim), floor};
  };
  const Run one = run(1);
  EXPECT_GT(one.floor[2].active_contacts, 100u);
  for (const int threads : {2, 3}) {
    const Run other = run(threads);
    expect_same(one.state, other.state);
    for (std::size_t k = 0; k < one.floor.size(); ++k) {
      const Wall &a = one.floor[k], &b = other.floor[k];
      EXPECT_TRUE(same_bits(a.force, b.force) && same_bits(a.moment, b.moment)) << threads << k;
      EXPECT_EQ(std::memcmp(&a.normal_force, &b.normal_force, sizeof(double)), 0) << threads << k;
      EXPECT_EQ(std::memcmp(&a.normal_stiffness, &b.normal_stiffness, sizeof(double)), 0) << threads << k;
      EXPECT_EQ(a.active_contacts, b.active_contacts) << threads << k;
    }
  }
}

}  // namespace
}  // namespace hilldem
