#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/motion/law_of_motion.hpp"
#include "hilldem/motion/rigid_body.hpp"

using namespace hilldem;

namespace {

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The asymmetric 3-pebble clump scaled to an equal-volume diameter of 10 mm, ρ = 2650 kg/m³.
ClumpTemplate asymmetric_clump() {
  const Pebbles p{{{0.0, 0.0, 0.0}, {0.9e-3, 0.2e-3, 0.0}, {0.1e-3, 0.8e-3, 0.5e-3}}, {0.6e-3, 0.5e-3, 0.4e-3}};
  return make_template(p, 2650.0).scaled(10e-3);
}

struct FreeRun {
  double max_dl = 0.0, max_de = 0.0;  // relative
  int flips = 0;                      // sign changes of ω along the axis started on
};
// Torque-free rotation from ω = Ω (e_axis + ε (1, 1, 1)) in the principal frame, n steps of Δt.
FreeRun free_rotation(const ClumpTemplate& t, int axis, double omega, double eps, double dt, long n) {
  ClumpState s;
  Vec3 wb{eps, eps, eps};
  wb[axis] = 1.0;
  const Quat q0 = from_rotation_vector({0.3, 0.2, -0.5});
  s.add({}, {}, q0, rotate(q0, wb * omega), t.mass, t.principal_inertia);
  const Vec3 l0 = angular_momentum(s, 0);
  const double e0 = rotational_energy(s, 0);
  FreeRun r;
  double prev = s.body_momentum[0][axis];
  for (long k = 0; k < n; ++k) {
    step_clump(s, 0, {}, {}, {}, dt);
    r.max_dl = std::max(r.max_dl, norm(angular_momentum(s, 0) - l0) / norm(l0));
    r.max_de = std::max(r.max_de, std::abs(rotational_energy(s, 0) / e0 - 1.0));
    const double c = s.body_momentum[0][axis];
    if (c * prev < 0.0) ++r.flips;
    prev = c;
  }
  return r;
}

}  // namespace

TEST(RigidBody, OnePebbleClumpMovesBitwiseLikeABall) {
  for (const double alpha : {0.0, 0.7}) {
    BallStore balls;
    BallInit b;
    b.position = {1e-3, 2e-3, -3e-3};
    b.radius = 2.5e-3;
    b.density = 2650.0;
    b.velocity = {0.1, -0.2, 0.05};
    b.spin = {3.0, -1.0, 2.0};
    b.fixity = 0b000100;  // z velocity fixed
    balls.add(b);
    const MotionSettings ms{{0.0, 0.0, -9.81}, alpha};
    const ClumpTemplate t = make_template({{b.position}, {b.radius}}, b.density);
    // the template's mass properties are the ball's (to rounding); the law is compared on the same values
    EXPECT_NEAR(t.mass, balls.mass[0], 1e-15 * t.mass);
    EXPECT_NEAR(t.principal_inertia.y, balls.inertia[0], 1e-13 * balls.inertia[0]);
    ClumpState s;
    const double in = balls.inertia[0];
    s.add(b.position, b.velocity, {}, b.spin, balls.mass[0], {in, in, in}, b.fixity);
    const RigidMotionSettings rs{ms.gravity, alpha};
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1e-3, 1e-3);
    for (int step = 0; step < 500; ++step) {
      const Vec3 f{u(rng), u(rng), u(rng)}, m{u(rng) * 1e-3, u(rng) * 1e-3, u(rng) * 1e-3};
      balls.contact_force[0] = f;
      balls.contact_moment[0] = m;
      advance_balls(balls, ms, 1e-5);
      step_clump(s, 0, f, m, rs, 1e-5);
      ASSERT_TRUE(same_bits(balls.position[0], s.position[0])) << step;
      ASSERT_TRUE(same_bits(balls.velocity[0], s.velocity[0])) << step;
      ASSERT_TRUE(same_bits(balls.spin[0], s.spin[0])) << step;
    }
    EXPECT_EQ(s.velocity[0].z, b.velocity.z);  // fixed
    EXPECT_NE(s.spin[0].x, b.spin.x);
  }
}

TEST(RigidBody, TorqueFreeRotationConservesMomentumAndEnergy) {
  // Near the intermediate axis (the hardest case: the body axes swing the farthest): Ω = 100 rad/s,
  // Δt = 5e-7 s, so Ω Δt = 5e-5 rad, 1e5 steps.
  const ClumpTemplate t = asymmetric_clump();
  const FreeRun r = free_rotation(t, 1, 100.0, 1e-2, 5e-7, 100000);
  EXPECT_LT(r.max_dl, 1e-10);
  EXPECT_LT(r.max_de, 1e-10);
  // second order: over the same 0.2 s (20 rad), twice the step gives four times the energy error
  // (at Ω Δt = 5e-5 the error above is rounding's, not the scheme's)
  const FreeRun r1 = free_rotation(t, 1, 100.0, 1e-2, 1e-5, 20000);
  const FreeRun r2 = free_rotation(t, 1, 100.0, 1e-2, 2e-5, 10000);
  EXPECT_GT(r2.max_de, 3.5 * r1.max_de);
  EXPECT_LT(r2.max_de, 4.5 * r1.max_de);
}

TEST(RigidBody, IntermediateAxisInstability) {
  // Ω Δt = 1e-3 rad, 1e5 steps (100 rad of rotation), started 1e-3 off a principal axis.
  const ClumpTemplate t = asymmetric_clump();
  ASSERT_GT(t.principal_inertia.y / t.principal_inertia.x, 1.05);
  ASSERT_GT(t.principal_inertia.z / t.principal_inertia.y, 1.05);
  const FreeRun mid = free_rotation(t, 1, 100.0, 1e-3, 1e-5, 100000);
  const FreeRun small = free_rotation(t, 0, 100.0, 1e-3, 1e-5, 100000);
  const FreeRun large = free_rotation(t, 2, 100.0, 1e-3, 1e-5, 100000);
  EXPECT_GE(mid.flips, 2);  // tumbles: ω along the intermediate axis changes sign, repeatedly
  EXPECT_EQ(small.flips, 0);
  EXPECT_EQ(large.flips, 0);
  for (const FreeRun& r : {mid, small, large}) {
    EXPECT_LT(r.max_dl, 1e-10);
    EXPECT_LT(r.max_de, 1e-6);
  }
}

TEST(RigidBody, TorqueChangesMomentumByTorqueTimesStep) {
  const ClumpTemplate t = asymmetric_clump();
  ClumpState s;
  s.add({}, {}, from_rotation_vector({1.0, 0.0, 0.5}), {10.0, -20.0, 5.0}, t.mass, t.principal_inertia);
  const Vec3 torque{1e-4, -2e-4, 3e-4};  // [N m]
  for (int k = 0; k < 100; ++k) {
    const Vec3 l0 = angular_momentum(s, 0);
    step_clump(s, 0, {}, torque, {}, 1e-5);
    const Vec3 dl = angular_momentum(s, 0) - l0 - torque * 1e-5;
    EXPECT_LT(norm(dl), 1e-12 * norm(l0));
  }
  // local damping, M_d = −α |M| sign(ω) per component: a torque along ω acts as (1 − α) M, one
  // against it as (1 + α) M (spin about a principal axis, so that the gyroscopic term is zero)
  for (const double sign : {1.0, -1.0}) {
    ClumpState d;
    d.add({}, {}, {}, {0.0, 0.0, 5.0}, t.mass, t.principal_inertia);
    const Vec3 l0 = angular_momentum(d, 0);
    step_clump(d, 0, {}, {0.0, 0.0, sign * 1e-3}, {{}, 0.7}, 1e-5);
    EXPECT_NEAR(angular_momentum(d, 0).z - l0.z, sign * (1.0 - sign * 0.7) * 1e-3 * 1e-5, 1e-20);
  }
}

TEST(RigidBody, FreeFallIsExact) {
  const ClumpTemplate t = asymmetric_clump();
  ClumpState s;
  const Vec3 g{0.0, 0.0, -9.81}, x0{0.1, 0.2, 0.3}, v0{1.0, -0.5, 2.0};
  const double dt = 1e-4;
  // velocities at half steps: V(−Δt/2) = v0 − g Δt/2 gives x(n Δt) = x0 + v0 t + g t²/2
  s.add(x0, v0 - g * (0.5 * dt), from_rotation_vector({0.2, 0.1, 0.0}), {0.0, 3.0, 1.0}, t.mass, t.principal_inertia);
  const int n = 10000;
  for (int k = 0; k < n; ++k) step_clump(s, 0, {}, {}, {g, 0.0}, dt);
  const double time = n * dt;
  const Vec3 exact = x0 + v0 * time + g * (0.5 * time * time);
  EXPECT_LT(norm(s.position[0] - exact), 1e-12 * norm(exact));
  EXPECT_LT(norm(s.velocity[0] - (v0 + g * (time - 0.5 * dt))), 1e-12 * norm(v0));
}

TEST(RigidBody, FixityAndImposedSpin) {
  const ClumpTemplate t = asymmetric_clump();
  // all spins fixed at ω: the body turns by exp(ω t) whatever the torque
  ClumpState s;
  const Vec3 omega{0.0, 0.0, 2.0};
  s.add({}, {0.5, 0.0, 0.0}, {}, omega, t.mass, t.principal_inertia, kFixSpin | 0b001);
  for (int k = 0; k < 1000; ++k) step_clump(s, 0, {1.0, 0.0, 0.0}, {1.0, -1.0, 1.0}, {{0, 0, -9.81}, 0.0}, 1e-3);
  EXPECT_TRUE(same_bits(s.spin[0], omega));
  const Vec3 ex = rotate(s.orientation[0], {1, 0, 0});
  EXPECT_NEAR(ex.x, std::cos(2.0), 1e-12);
  EXPECT_NEAR(ex.y, std::sin(2.0), 1e-12);
  EXPECT_EQ(s.velocity[0].x, 0.5);  // imposed velocity
  EXPECT_NEAR(s.position[0].x, 0.5, 1e-12);
  EXPECT_LT(s.velocity[0].z, 0.0);  // free components fall
  // one spin fixed: that global component of ω stays at its value, the others evolve
  ClumpState p;
  p.add({}, {}, from_rotation_vector({0.3, 0.2, -0.5}), {1.0, 50.0, 2.0}, t.mass, t.principal_inertia, 0b010000);
  for (int k = 0; k < 1000; ++k) {
    step_clump(p, 0, {}, {0.0, 1e-3, 0.0}, {}, 1e-5);
    EXPECT_EQ(p.spin[0].y, 50.0);
  }
  EXPECT_NE(p.spin[0].x, 1.0);
}

TEST(RigidBody, AdvanceClumpsIsStepClumpForEach) {
  // More clumps than kParallelMin, so that the loop runs on threads where there are any.
  const ClumpTemplate t = asymmetric_clump();
  ClumpState a;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> f, m;
  for (std::size_t i = 0; i < kParallelMin + 500; ++i) {
    a.add({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, from_rotation_vector({u(rng), u(rng), u(rng)}),
          Vec3{u(rng), u(rng), u(rng)} * 50.0, t.mass, t.principal_inertia, i % 7 == 0 ? kFixSpin : 0);
    f.push_back(Vec3{u(rng), u(rng), u(rng)} * 1e-2);
    m.push_back(Vec3{u(rng), u(rng), u(rng)} * 1e-5);
  }
  ClumpState b = a;
  const RigidMotionSettings rs{{0, 0, -9.81}, 0.7};
  for (int step = 0; step < 3; ++step) {
    advance_clumps(a, f, m, rs, 1e-5);
    for (std::size_t i = 0; i < b.size(); ++i) step_clump(b, i, f[i], m[i], rs, 1e-5);
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(same_bits(a.position[i], b.position[i])) << i;
    ASSERT_TRUE(same_bits(a.spin[i], b.spin[i])) << i;
    ASSERT_TRUE(same_bits(a.body_momentum[i], b.body_momentum[i])) << i;
    ASSERT_EQ(std::memcmp(&a.orientation[i], &b.orientation[i], sizeof(Quat)), 0) << i;
  }
}
