// Physics checks the memo does not cover: Newton's third law for every contact, momentum,
// energy of an undamped Hertz collision, restitution independent of impact speed.
#include <gtest/gtest.h>

#include <cmath>

#include "sim_builders.hpp"

namespace hilldem {
namespace {

using namespace hilldem::testing;

// Σ forces on balls + Σ forces on walls = 0 at every step, and the moments about the origin too.
TEST(NewtonThird, ContactForcesCancelEveryStep) {
  Simulation sim = random_box(150, 7);
  sim.make_wet(20e3, 1e-3);  // wet and dry hill contacts plus linear wall contacts
  double checked = 0;
  sim.observers.push_back([&](const Simulation& s) {
    Vec3 total, moment;
    double scale = 0.0;
    for (std::size_t i = 0; i < s.balls.size(); ++i) {
      total += s.balls.contact_force[i];
      moment += s.balls.contact_moment[i] + cross(s.balls.position[i], s.balls.contact_force[i]);
      scale += norm(s.balls.contact_force[i]);
    }
    for (const Wall& w : s.walls.walls) {
      total += w.force;
      moment += w.moment + cross(w.rotation_center, w.force);
    }
    if (scale == 0.0) return;
    EXPECT_LT(norm(total), 1e-12 * scale);
    EXPECT_LT(norm(moment), 1e-12 * scale * 0.04);
    ++checked;
  });
  sim.cycle(200);
  EXPECT_GT(checked, 100);
  EXPECT_GT(sim.contact_count(), 20u);
}

// No walls, no gravity, no local damping: total linear momentum of free balls is conserved.
TEST(Momentum, ConservedWithoutWalls) {
  Simulation sim = random_box(150, 11, /*walls=*/false);
  auto momentum = [&] {
    Vec3 p;
    for (std::size_t i = 0; i < sim.balls.size(); ++i) p += sim.balls.velocity[i] * sim.balls.mass[i];
    return p;
  };
  double pmag = 0.0;
  for (std::size_t i = 0; i < sim.balls.size(); ++i) pmag += norm(sim.balls.velocity[i]) * sim.balls.mass[i];
  const Vec3 p0 = momentum();
  sim.cycle(300);
  EXPECT_LT(norm(momentum() - p0), 1e-12 * pmag);
}

struct Collision {
  double speed_in, speed_out, energy_in, energy_out;
};

// Head-on collision of two equal granite balls (R = 5 mm) closing at 2v [m/s].
Collision collide(double v, double damp_con) {
  Simulation sim;
  const double r = 5e-3;
  sim.balls.add(granite(1, {0, 0, 0}, r, {v, 0, 0}));
  sim.balls.add(granite(2, {2 * r + 1e-6, 0, 0}, r, {-v, 0, 0}));
  sim.table.rules.push_back(hill_rule(0.4, damp_con));
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 2e-9 / std::pow(v, 0.2) * 5;  // ≈ 1e-8 s: thousands of steps per collision
  auto energy = [&] {
    double e = 0;
    for (std::size_t i = 0; i < 2; ++i) e += 0.5 * sim.balls.mass[i] * norm2(sim.balls.velocity[i]);
    return e;
  };
  const double e0 = energy();
  // Cycle until the balls have separated again.
  for (int k = 0; k < 2'000'000; ++k) {
    sim.cycle(1);
    if (sim.balls.velocity[1].x > 0 && sim.contact_count() == 0) break;
  }
  sim.cycle(10);
  return {v, sim.balls.velocity[1].x, e0, energy()};
}

TEST(HertzCollision, UndampedConservesEnergy) {
  for (double v : {0.1, 1.0}) {
    const Collision c = collide(v, 0.0);
    EXPECT_NEAR(c.energy_out / c.energy_in, 1.0, 1e-4) << "v = " << v;
    EXPECT_NEAR(c.speed_out / c.speed_in, 1.0, 1e-4) << "v = " << v;
  }
}

// Spec §2.9: γ_h = 0.07 gives e = 0.9063, the same for any impact speed.
TEST(HertzCollision, DampedRestitutionIndependentOfSpeed) {
  double lo = 1.0, hi = 0.0;
  for (double v : {0.05, 0.5, 5.0}) {
    const Collision c = collide(v, 0.07);
    const double e = c.speed_out / c.speed_in;
    EXPECT_NEAR(e, 0.9063, 2e-3) << "v = " << v;
    lo = std::min(lo, e);
    hi = std::max(hi, e);
  }
  EXPECT_LT(hi - lo, 2e-3);
}

}  // namespace
}  // namespace hilldem
