// Servo control of walls (control/servo.hpp) and the servo-controlled genesis of a small specimen.
#include <gtest/gtest.h>

#include <cmath>

#include "hilldem/control/servo.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/engine/simulation.hpp"
#include "hilldem/labtests/genesis.hpp"
#include "mini_specimen.hpp"

namespace hilldem {
namespace {

// One fixed ball (R 5 mm) under a plane platen with a linear contact (E* 500 MPa).
Simulation ball_under_platen(double gap) {
  Simulation sim;
  BallInit b;
  b.id = 1;
  b.radius = 5e-3;
  b.density = 2650;
  b.fixity = kFixAll;
  sim.balls.add(b);
  Wall w;
  w.name = "platen";
  w.shape = WallShape::Plane;
  w.point = Vec3{0, 0, 5e-3 + gap};
  w.normal = Vec3{0, 0, -1};
  sim.walls.add(w);
  ModelRule r;
  r.kind = ContactKind::BallWall;
  r.model = ModelKind::Linear;
  r.linear = LinearParams{500e6, 1.0, 0.0};
  sim.table.rules.push_back(r);
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-6;
  return sim;
}

constexpr double kArea = 1e-4;  // [m²] the stress is the platen force over this area

TEST(Servo, OverStressedWallMovesAwayUnderStressedMovesIn) {
  Simulation sim = ball_under_platen(-10e-6);  // 10 µm overlap: k_n 3.93e6 N/m, about 39 N
  sim.update_forces();
  Servo servo(Servo::Mode::Axial, {0}, Vec3{0, 0, 1}, ServoSettings{0.1e6, 0.5, 1.0}, [](const Simulation&) { return kArea; });
  EXPECT_NEAR(servo.stress(sim), sim.walls.walls[0].normal_force / kArea, 1e-9);
  EXPECT_GT(servo.stress(sim), 0.1e6);
  servo.control(sim, 1e-6);
  EXPECT_GT(servo.speed(), 0.0);  // away from the ball (outward = +z)
  EXPECT_GT(sim.walls.walls[0].velocity.z, 0.0);
  servo.settings.target_stress = 1e6;  // 100 N wanted: move in
  servo.control(sim, 1e-6);
  EXPECT_LT(sim.walls.walls[0].velocity.z, 0.0);
}

TEST(Servo, SpeedIsCappedAndAWallWithNoContactClosesInAtTheCap) {
  Simulation sim = ball_under_platen(1e-3);  // 1 mm gap: no contact, no stiffness
  sim.update_forces();
  Servo servo(Servo::Mode::Axial, {0}, Vec3{0, 0, 1}, ServoSettings{1e6, 0.5, 0.25}, [](const Simulation&) { return kArea; });
  servo.control(sim, 1e-6);
  EXPECT_DOUBLE_EQ(servo.speed(), -0.25);
  EXPECT_DOUBLE_EQ(sim.walls.walls[0].velocity.z, -0.25);
}

TEST(Servo, ConvergesToTheTargetStress) {
  Simulation sim = ball_under_platen(0.2e-3);
  auto servo = std::make_shared<Servo>(Servo::Mode::Axial, std::vector<std::size_t>{0}, Vec3{0, 0, 1},
                                       ServoSettings{1e6, 0.5, 0.5}, [](const Simulation&) { return kArea; });
  sim.controllers.push_back([servo](Simulation& m, double dt) { servo->control(m, dt); });
  sim.cycle(2000);
  EXPECT_NEAR(servo->stress(sim), 1e6, 1e-6 * 1e6);
  EXPECT_NEAR(sim.walls.walls[0].normal_force, 100.0, 1e-4);
  EXPECT_NEAR(servo->speed(), 0.0, 1e-6);
  // The stiffness-based gain corrects a fraction α_s of the error per step: no overshoot.
  servo->settings.target_stress = 2e6;
  double worst = 0.0;
  sim.observers.push_back([&](const Simulation& m) { worst = std::max(worst, m.walls.walls[0].normal_force); });
  sim.cycle(200);
  EXPECT_LE(worst, 200.0 * (1 + 1e-9));
  EXPECT_NEAR(sim.walls.walls[0].normal_force, 200.0, 1e-3);
}

TEST(Servo, RadialModeDrivesACylinderRadius) {
  // A fixed ball touching the inside of a cylinder of radius 20 mm at x = 15 mm (5 µm overlap).
  Simulation sim;
  BallInit b;
  b.id = 1;
  b.radius = 5e-3;
  b.density = 2650;
  b.fixity = kFixAll;
  b.position = Vec3{15.005e-3, 0, 0};
  sim.balls.add(b);
  Wall w;
  w.name = "lateral";
  w.shape = WallShape::Cylinder;
  w.axis = 2;
  w.radius = 20e-3;
  sim.walls.add(w);
  ModelRule r;
  r.kind = ContactKind::BallWall;
  r.linear = LinearParams{500e6, 1.0, 0.0};
  sim.table.rules.push_back(r);
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-6;
  auto servo = std::make_shared<Servo>(Servo::Mode::Radial, std::vector<std::size_t>{0}, Vec3{}, ServoSettings{5e4, 0.5, 0.5},
                                       [](const Simulation&) { return kArea; });
  sim.controllers.push_back([servo](Simulation& m, double dt) { servo->control(m, dt); });
  sim.cycle(1);
  EXPECT_GT(sim.walls.walls[0].radial_velocity, 0.0);  // 5 µm overlap is about 39 N > 5 N: expand
  sim.cycle(2000);
  EXPECT_NEAR(sim.walls.walls[0].normal_force, 5.0, 1e-4);
  EXPECT_NEAR(sim.walls.walls[0].radius, 20e-3 + 5e-6 - 5.0 / (std::numbers::pi * 5e-3 * 500e6), 1e-9);
}

TEST(Genesis, ServoPackingOfASmallSpecimenReachesThePressure) {
  GenesisSpec spec = testing::mini_spec();  // in a smaller vessel (34 mm x 48 mm): about 110 grains
  spec.vessel_radius = 0.2 * 0.085;
  spec.vessel_height = 0.2 * 0.240;
  const Specimen s = pack_specimen(spec, nullptr);
  const SpecimenState st = measure(s);
  const double p = spec.packing.equilibrium.pressure;
  EXPECT_GT(st.grains, 80u);
  EXPECT_LT(st.grains, 150u);
  EXPECT_NEAR(st.radial_stress, p, 0.01 * p);
  EXPECT_NEAR(st.bottom_stress, p, 0.01 * p);
  EXPECT_NEAR(st.top_stress, p, 0.01 * p);
  EXPECT_LE(st.ratio, spec.packing.equilibrium.ratio);
  // Walls at rest after packing; the vessel contracted from the cloud.
  for (const Wall& w : s.sim.walls.walls) {
    EXPECT_EQ(norm(w.velocity), 0.0);
    EXPECT_EQ(w.radial_velocity, 0.0);
  }
  EXPECT_LT(st.radius, spec.vessel_radius);
  EXPECT_LT(st.height, spec.vessel_height);
  EXPECT_LT(st.porosity, 0.5);  // from the cloud's 0.58
  EXPECT_GT(st.porosity, 0.3);
  EXPECT_GT(st.coordination, 3.0);
  ASSERT_EQ(s.phases.size(), 2u);
  EXPECT_EQ(s.phases[0].name, "cloud");
  EXPECT_EQ(s.phases[1].name, "packing");
  EXPECT_NEAR(s.phases[0].state.porosity, 0.58, 0.02);
  EXPECT_GT(s.phases[1].steps, 1000);
}

TEST(Genesis, SameSeedSameSpecimen) {
  Specimen a = make_cloud(testing::mini_spec());
  Specimen b = make_cloud(testing::mini_spec());
  GenesisSpec other = testing::mini_spec();
  other.packing.seed = 43;
  Specimen c = make_cloud(other);
  EXPECT_EQ(a.sim.balls.position, b.sim.balls.position);
  EXPECT_EQ(a.sim.balls.radius, b.sim.balls.radius);
  EXPECT_NE(a.sim.balls.radius, c.sim.balls.radius);
  // The packing is deterministic too: the first few thousand servo cycles agree bit for bit.
  EquilibriumSettings e = testing::mini_spec().packing.equilibrium;
  e.max_steps = 3000;
  for (Specimen* s : {&a, &b}) {
    relax_cloud(*s, testing::mini_spec().packing, nullptr);
    EXPECT_THROW(servo_equilibrium(*s, e, "packing", nullptr), RunError);  // not converged yet
  }
  EXPECT_EQ(a.sim.balls.position, b.sim.balls.position);
  EXPECT_EQ(measure(a).porosity, measure(b).porosity);
}

TEST(Genesis, BadSettingsAreRefused) {
  GenesisSpec g = testing::mini_spec();
  g.packing.equilibrium.pressure = -1;
  EXPECT_THROW(validate(g), InputError);
  g = testing::mini_spec();
  g.vessel_radius = 3e-3;  // 8 mm grains do not fit
  EXPECT_THROW(validate(g), InputError);
  g = testing::mini_spec();
  g.packing.cloud_porosity = 1.0;
  EXPECT_THROW(validate(g), InputError);
}

}  // namespace
}  // namespace hilldem
