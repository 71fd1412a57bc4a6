// Engine behaviour: make_wet creates contacts, wet contacts persist at positive gaps, the cycle's
// order and integrator, fixity, the automatic time step, Appendix A through the engine, determinism.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "hilldem/io/runner.hpp"
#include "hilldem/io/scenario.hpp"
#include "hilldem/io/state_io.hpp"
#include "sim_builders.hpp"

namespace hilldem {
namespace {

using namespace hilldem::testing;

// Three balls in a row with gaps 1 mm and 3 mm; no contacts exist before make_wet.
Simulation three_in_a_row() { return granite_row({1e-3, 3e-3}); }

TEST(MakeWet, CreatesContactsWithinTheGapOnly) {
  Simulation sim = three_in_a_row();
  sim.update_forces();
  EXPECT_EQ(sim.contact_count(), 0u);
  EXPECT_EQ(sim.make_wet(200e3, 2e-3), 1u);
  ASSERT_EQ(sim.contact_count(), 1u);
  EXPECT_GE(sim.find_ball_ball(1, 2), 0);
  EXPECT_LT(sim.find_ball_ball(2, 3), 0);
  const long c = sim.find_ball_ball(1, 2);
  EXPECT_EQ(sim.contacts.moisture[c], Moisture::Wet);
  EXPECT_DOUBLE_EQ(sim.contacts.hill_params[c].suction, 200e3);
  // Wider gap: both pairs.
  EXPECT_EQ(sim.make_wet(100e3, 3.5e-3), 2u);
}

TEST(MakeWet, WetContactSurvivesPositiveGapAndPullsTheGrains) {
  Simulation sim = three_in_a_row();
  sim.make_wet(200e3, 2e-3);
  sim.cycle(10);
  const long c = sim.find_ball_ball(1, 2);
  ASSERT_GE(c, 0);
  EXPECT_TRUE(sim.contacts.active[c]);
  EXPECT_LT(sim.contacts.moisture_force[c], 0.0);
  EXPECT_GT(sim.balls.velocity[0].x, 0.0);  // ball 1 pulled towards ball 2
  EXPECT_LT(sim.balls.velocity[1].x, 0.0);
}

TEST(MakeDry, DriedOpenContactIsDeleted) {
  Simulation sim = three_in_a_row();
  sim.make_wet(200e3, 2e-3);
  sim.cycle(1);
  EXPECT_EQ(sim.make_dry(), 1u);
  sim.cycle(1);
  EXPECT_EQ(sim.contact_count(), 0u);
}

// Spec §4: velocities at half steps; a free ball under gravity follows the central-difference
// recurrence exactly: v_n = n g Δt, z_n = z_0 + g Δt² n(n+1)/2.
TEST(LawOfMotion, FreeFallMatchesCentralDifference) {
  Simulation sim;
  sim.balls.add(granite(1, {0, 0, 1.0}, 5e-3));
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-3;
  sim.cycle(100);
  EXPECT_NEAR(sim.balls.velocity[0].z, -9.81 * 100 * 1e-3, 1e-12);
  EXPECT_NEAR(sim.balls.position[0].z, 1.0 - 9.81 * 1e-6 * 100 * 101 / 2, 1e-12);
  EXPECT_NEAR(sim.time, 0.1, 1e-12);
}

TEST(LawOfMotion, FixedComponentsKeepTheirVelocity) {
  Simulation sim;
  BallInit b = granite(1, {0, 0, 0}, 5e-3, {0.1, 0, 0});
  b.fixity = 0b000101;  // x and z fixed
  sim.balls.add(b);
  sim.settings.gravity = {0, -9.81, -9.81};
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-3;
  sim.cycle(10);
  EXPECT_DOUBLE_EQ(sim.balls.velocity[0].x, 0.1);
  EXPECT_DOUBLE_EQ(sim.balls.velocity[0].z, 0.0);
  EXPECT_NEAR(sim.balls.velocity[0].y, -9.81e-2, 1e-12);
  EXPECT_NEAR(sim.balls.position[0].x, 1e-3, 1e-15);
}

// Spec §4 for every one of the 64 fixity masks at once, with local damping (α 0.7), gravity and
// applied loads of random signs: each free component follows ΔV = (F − α|F| sign V)/m Δt from its own
// velocity (spin: the moment and I), each fixed one keeps its value bit for bit, and x += V Δt.
TEST(LawOfMotion, EveryFixityMaskWithDamping) {
  Simulation sim;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random3 = [&](double scale) { return Vec3{scale * u(rng), scale * u(rng), scale * u(rng)}; };
  for (int mask = 0; mask < 64; ++mask) {
    BallInit b = granite(mask + 1, {0.02 * mask, 0, 0}, 5e-3, random3(0.1));
    b.fixity = static_cast<FixityMask>(mask);
    b.spin = random3(10.0);
    if (mask % 5 == 0) b.velocity.y = 0.0;  // sign 0: no damping of that component
    sim.balls.add(b);
    sim.balls.applied_force.back() = random3(0.05);    // [N]
    sim.balls.applied_moment.back() = random3(1e-4);   // [N m]
  }
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.7;
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-4;
  const BallStore before = sim.balls;
  sim.cycle(1);
  const double dt = 1e-4, alpha = 0.7;
  auto sign = [](double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); };
  for (std::size_t i = 0; i < 64; ++i)
    for (int d = 0; d < 3; ++d) {
      const double f = before.applied_force[i][d] + (d == 2 ? -9.81 * before.mass[i] : 0.0);
      const double m = before.applied_moment[i][d];
      const double v0 = before.velocity[i][d], w0 = before.spin[i][d];
      const double v = sim.balls.velocity[i][d], w = sim.balls.spin[i][d];
      if (before.fixity[i] & (1u << d)) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(v), std::bit_cast<std::uint64_t>(v0)) << i << " " << d;
      } else {
        EXPECT_DOUBLE_EQ(v, v0 + (f - alpha * std::abs(f) * sign(v0)) / before.mass[i] * dt) << i << " " << d;
      }
      if (before.fixity[i] & (1u << (d + 3))) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(w), std::bit_cast<std::uint64_t>(w0)) << i << " " << d;
      } else {
        EXPECT_DOUBLE_EQ(w, w0 + (m - alpha * std::abs(m) * sign(w0)) / before.inertia[i] * dt) << i << " " << d;
      }
      EXPECT_DOUBLE_EQ(sim.balls.position[i][d], before.position[i][d] + v * dt) << i << " " << d;
    }
}

// Local damping with α = 0.7 brings a ball resting on a plane to equilibrium.
TEST(LawOfMotion, LocalDampingSettlesABallOnAPlane) {
  Simulation sim;
  sim.balls.add(granite(1, {0, 0, 5e-3}, 5e-3));
  Wall floor;
  floor.name = "floor";
  sim.walls.add(floor);
  sim.table.rules.push_back(linear_wall_rule(29e6, 0.4));
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.7;
  ASSERT_GT(sim.solve(1e-8, 100000), 0);
  EXPECT_NEAR(-sim.walls.walls[0].force.z, sim.balls.mass[0] * 9.81, 1e-7);
}

// Spec §4 and Eqs. 19-21: the automatic Δt of the two-grain hill contact at δ = 0.1 mm.
TEST(TimeStep, AutomaticEstimateMatchesTheFormula) {
  Simulation sim;
  sim.balls.add(granite(1, {0, 0, 0}, 7.5e-3));
  sim.balls.add(granite(2, {0, 0, 12.4e-3}, 5e-3));
  sim.table.rules.push_back(hill_rule(0.4, 0.07));
  sim.update_forces();
  const HillMapping& m = sim.contacts.hill_map[0];
  const double f = std::sqrt(1.0 + 0.035 * 0.035) - 0.035;
  const double kn = 1.5 * m.kn * std::sqrt(1e-4) / (f * f), ks = m.ks * std::sqrt(1e-4) / (f * f);
  const double arm2 = std::pow(5e-3 - 0.5e-4, 2);  // top ball: contact point 4.95 mm from its centre
  double crit = 1e9;
  for (int i = 0; i < 2; ++i) {
    const double arm = i == 0 ? std::pow(7.5e-3 - 0.5e-4, 2) : arm2;
    crit = std::min({crit, std::sqrt(sim.balls.mass[i] / (kn + ks)), std::sqrt(sim.balls.inertia[i] / (ks * arm))});
  }
  EXPECT_NEAR(sim.estimate_timestep(), 0.8 * crit, 1e-9 * crit);
}

// Spec §4 after make_wet: the first cycle's Δt queries the new wet contact (Eq. 19 at
// δ_o = 2e-4 R_o, since the grains are apart), not the dry state of the cycle before.
TEST(TimeStep, FirstCycleAfterMakeWetUsesTheWetContact) {
  Simulation sim = granite_row({1e-3});  // two free granite grains, R = 5 mm, 1 mm apart
  sim.settings.auto_timestep = true;
  sim.update_forces();                   // no contact: nothing bounds Δt yet
  ASSERT_EQ(sim.make_wet(20e3, 3e-3), 1u);
  const HillMapping& m = sim.contacts.hill_map[0];
  const double root = std::sqrt(2e-4 * m.r_o);
  const double kn = 1.5 * m.kn * root, ks = m.ks * root;  // no dashpot: F(ξ) = 1
  const double arm2 = std::pow(5e-3 + 0.5e-3, 2);          // contact point in the middle of the gap
  const double crit = std::min(std::sqrt(sim.balls.mass[0] / (kn + ks)), std::sqrt(sim.balls.inertia[0] / (ks * arm2)));
  sim.cycle(1);
  EXPECT_LT(sim.last_dt, sim.settings.timestep_max);
  EXPECT_NEAR(sim.last_dt, 0.8 * crit, 1e-9 * crit);
}

// Spec §4 after new contact properties (set_contacts): raising γ_h from 0 to 0.07 on an existing
// contact shortens the next Δt by F(ξ) (Eq. 20) at once, as if the contact had been made with it.
TEST(TimeStep, NewPropertiesChangeTheNextTimeStep) {
  auto pair = [](double damp) {
    Simulation sim;
    sim.balls.add(granite(1, {0, 0, 0}, 7.5e-3));
    sim.balls.add(granite(2, {0, 0, 12.4e-3}, 5e-3));
    sim.table.rules.push_back(hill_rule(0.4, damp));
    sim.update_forces();
    return sim;
  };
  Simulation changed = pair(0.0);
  const double before = changed.estimate_timestep();
  changed.contacts.hill_params[0].damp_con = 0.07;
  changed.refresh_mappings();
  const Simulation made = pair(0.07);
  const double f = std::sqrt(1.0 + 0.035 * 0.035) - 0.035;
  EXPECT_NEAR(changed.estimate_timestep(), f * before, 1e-12 * before);
  // (to the rounding of the gap, which the force pass takes by another sequence of operations)
  EXPECT_NEAR(changed.estimate_timestep(), made.estimate_timestep(), 1e-12 * before);
}

// Appendix A (spec §2.10) through the engine: after shearing, doubling the overlap with no further
// shear motion leaves the shear force unchanged (incremental update).
TEST(AppendixA, DoublingOverlapKeepsShearForce) {
  Scenario sc = load_scenario(R"(
[simulation]
timestep = 1e-6
[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[ball]]
id = 1
position = [0, 0, 0]
radius = 7.5e-3
material = "granite"
fix = ["all"]
[[ball]]
id = 2
position = [0, 0, 12.5e-3]
radius = 5e-3
material = "granite"
fix = ["all"]
[[contact_model]]
between = "ball-ball"
model = "hill"
fric_coef = 1000.0
[[stage]]
type = "translate"
ball = 2
by = [0, 0, -1e-4]
steps = 50
[[stage]]
type = "rotate"
ball = 2
by = [0, 0.02, 0]
steps = 50
[[stage]]
type = "probe"
label = "A"
quantity = "contact.shear_force"
balls = [1, 2]
[[stage]]
type = "translate"
ball = 2
by = [0, 0, -1e-4]
steps = 50
[[stage]]
type = "probe"
label = "B"
quantity = "contact.shear_force"
balls = [1, 2]
[[stage]]
type = "probe"
label = "overlap"
quantity = "contact.overlap"
balls = [1, 2]
)", "appendix_a.toml");
  RunOptions opt;
  opt.quiet = true;
  opt.write_files = false;
  std::ostringstream log;
  const RunResult r = run_scenario(sc, opt, log);
  EXPECT_NEAR(r.find("A")->value, 1478.272, 1e-3);
  EXPECT_NEAR(r.find("B")->value, 1478.272, 1e-3);  // the absolute update would give 2090.6 N
  EXPECT_NEAR(r.find("overlap")->value, 2e-4, 1e-12);
}

// Same input, same result, bit for bit.
TEST(Determinism, TwoRunsAreBitwiseIdentical) {
  auto run = [] {
    Simulation sim = random_box(200, 3);
    sim.settings.gravity = {0, 0, -9.81};
    sim.settings.local_damping = 0.7;
    sim.make_wet(20e3, 1e-3);
    sim.cycle(300);
    return sim.balls.position;
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i]) << "ball " << i;
}

// 200 balls in a box under gravity, damped, with wet contacts: a state whose every cycle counts.
Simulation wet_damped_box() {
  Simulation sim = random_box(200, 3);
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.7;
  sim.make_wet(20e3, 1e-3);
  return sim;
}

// cycle(n, stop): once stop() says so, the coming cycle is the last; the state is bitwise cycle(k)'s,
// contact results included, and cycling on continues as an uninterrupted run.
TEST(Cycle, StoppedByTheHookIsTheStateOfThatManyCycles) {
  Simulation hooked = wet_damped_box(), plain = wet_damped_box();
  int asked = 0;
  const std::int64_t ran = hooked.cycle(1000, [&] { return ++asked == 37; });
  EXPECT_EQ(ran, 37);
  EXPECT_EQ(hooked.steps, 37);
  plain.cycle(37);
  EXPECT_EQ(state_digest(hooked), state_digest(plain));
  EXPECT_EQ(state_difference(hooked, plain), "");
  EXPECT_EQ(hooked.cycle(25, [] { return false; }), 25);
  plain.cycle(25);
  EXPECT_EQ(state_difference(hooked, plain), "");
}

// Simulation::interrupt: once it answers true, that cycle is the last and the call throws Interrupted
// naming the step; the state is bitwise that many cycles', in cycle() and in solve().
TEST(Cycle, InterruptEndsTheCallAfterThatCycleWithInterrupted) {
  Simulation hooked = wet_damped_box(), plain = wet_damped_box();
  int asked = 0;
  hooked.interrupt = [&] { return ++asked == 37; };
  try {
    hooked.cycle(1000);
    ADD_FAILURE() << "cycle() did not throw Interrupted";
  } catch (const Interrupted& e) {
    EXPECT_NE(std::string(e.what()).find("after step 37 "), std::string::npos) << e.what();
  }
  EXPECT_EQ(hooked.steps, 37);
  plain.cycle(37);
  EXPECT_EQ(state_difference(hooked, plain), "");
  // solve(): the cycle asked about runs, and the call throws unless the ratio is met by it.
  asked = 0;
  hooked.interrupt = [&] { return ++asked == 5; };
  EXPECT_THROW(hooked.solve(1e-12, 1000), Interrupted);
  EXPECT_EQ(hooked.steps, 42);
  plain.solve(1e-12, 5);
  EXPECT_EQ(state_difference(hooked, plain), "");
  // Copied with the simulation, and an answer of false changes nothing.
  hooked.interrupt = [] { return false; };
  Simulation copy = hooked;
  EXPECT_EQ(copy.cycle(25, {}), 25);
  plain.cycle(25);
  EXPECT_EQ(state_difference(copy, plain), "");
}

}  // namespace
}  // namespace hilldem
