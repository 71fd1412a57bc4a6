// A ball rolling on a plane with the rolling-resistance linear model (docs/spec/rrlinear.md): it
// stops within the distance the rolling resistance predicts. Energy of a rolling sphere
// ½ m v² + ½ (2/5 m R²) ω² = 0.7 m v0², taken by M* = μ_r R m g over the rotation d/R:
// d = 0.7 v0² / (μ_r g). Without rolling resistance it keeps rolling.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim_builders.hpp"

namespace hilldem {
namespace {

// A 5 mm granite ball resting on a floor (its weight's overlap), rolling at v0 [m/s] along x
// (ω_y = v0/R: no slip at the contact).
Simulation rolling_ball(double rolling_fric, double v0) {
  Simulation sim;
  const double r = 5e-3, g = 9.81;
  ModelRule floor;
  floor.name = "floor";
  floor.kind = ContactKind::BallWall;
  floor.model = ModelKind::RrLinear;
  floor.linear = {1e9, 1.0, 0.5, rolling_fric};  // E* [Pa], κ*, μ, μ_r
  sim.table.rules.push_back(floor);
  const double mass = 4.0 / 3.0 * std::numbers::pi * r * r * r * testing::kGraniteDensity;
  const double kn = std::numbers::pi * r * 1e9;  // [N/m] ball-wall: π R E* (spec §3)
  BallInit b = testing::granite(1, {0, 0, r - mass * g / kn}, r, {v0, 0, 0});
  b.spin = {0, v0 / r, 0};
  sim.balls.add(b);
  Wall w;
  w.name = "floor";
  w.shape = WallShape::Plane;
  w.point = {0, 0, 0};
  w.normal = {0, 0, 1};
  sim.walls.add(w);
  sim.settings.gravity = {0, 0, -g};
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 2e-6;  // [s] (√(m/k_n) ≈ 9.4e-6 s)
  return sim;
}

TEST(RollingResistance, BallStopsWithinThePredictedDistance) {
  const double mu_r = 0.05, v0 = 0.1, g = 9.81;
  const double predicted = 0.7 * v0 * v0 / (mu_r * g);  // 14.27 mm
  Simulation sim = rolling_ball(mu_r, v0);
  double stopped_at = -1.0;
  for (int k = 0; k < 400 && stopped_at < 0.0; ++k) {  // up to 0.8 s (it stops after ≈ 0.29 s)
    sim.cycle(1000);
    if (sim.balls.velocity[0].x <= 1e-4 * v0) stopped_at = sim.balls.position[0].x;
  }
  ASSERT_GT(stopped_at, 0.0) << "the ball did not stop";
  EXPECT_NEAR(stopped_at, predicted, 0.005 * predicted);  // (measured: 14.2713 mm against 14.2712)
  EXPECT_EQ(sim.contact_count(), 1u);
  // At rest: it does not set off again.
  sim.cycle(50000);
  EXPECT_NEAR(sim.balls.position[0].x, stopped_at, 1e-3 * predicted);
  EXPECT_LT(std::abs(sim.balls.spin[0].y), 1e-3 * v0 / 5e-3);
}

TEST(RollingResistance, WithoutItTheBallKeepsRolling) {
  Simulation sim = rolling_ball(0.0, 0.1);
  sim.cycle(150000);  // 0.3 s: past where μ_r = 0.05 stops it
  EXPECT_NEAR(sim.balls.velocity[0].x, 0.1, 1e-3);
  EXPECT_NEAR(sim.balls.position[0].x, 0.1 * 0.3, 1e-3 * 0.03);
}

}  // namespace
}  // namespace hilldem
