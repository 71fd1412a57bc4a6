// Unit tests of the linear contact model (spec §3, reference values L1-L5 of spec §7).
//
// Two granite grains, R1 = 7.5 mm, R2 = 5 mm, E* = 29 GPa, κ* = 1, μ = 0.4:
//   ball-ball: A = π (5e-3)² = 7.853982e-5 m², L = 12.5e-3 m
//              k_n = A E*/L = 7.853982e-5 · 29e9 / 12.5e-3 = π · 5.8e7 = 1.822124e8 N/m   (L1)
//   F_n at 0.1 mm = 1.822124e8 · 1e-4 = 18221.24 N                                         (L2)
//   shear 0.02 rad · 4.95 mm = 99 µm: trial k_s · 99e-6 = 18039.03 N                         (L4)
//   clamp μ F_n = 0.4 · 18221.24 = 7288.495 N                                               (L5)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "hilldem/models/lanes.hpp"
#include "hilldem/models/linear.hpp"

namespace hilldem {
namespace {

constexpr double kR1 = 7.5e-3, kR2 = 5.0e-3;

LinearParams params(double emod, double kratio, double fric) {
  LinearParams p;
  p.emod = emod;
  p.kratio = kratio;
  p.fric = fric;
  return p;
}

ContactKinematics kin(const Vec3& normal, double gap, const Vec3& rel_velocity, double dt = 1e-6) {
  ContactKinematics k;
  k.normal = normal;
  k.gap = gap;
  k.rel_velocity = rel_velocity;
  k.dt = dt;
  return k;
}

LinearState state(const Vec3& shear) {
  LinearState s;
  s.shear_force = shear;
  return s;
}

// The production law at both of its widths (as test_hill.cpp): linear_law<lanes::Pack>, lane j at
// the gap g_c + j·1e-6 m, against linear_force (linear_law<double>) at each lane's gap, bit for bit;
// returns lane 0.
LinearResult linear_force_both_widths(const LinearParams& p, const LinearMapping& m, const ContactKinematics& k,
                                      const LinearState& previous) {
  using lanes::Pack;
  const auto pack3 = lanes::splat3<Pack>;
  Pack gaps;
  for (std::size_t j = 0; j < lanes::kWidth; ++j) gaps[j] = k.gap + static_cast<double>(j) * 1e-6;
  const LinearOutput<Pack> o =
      linear_law<Pack>({lanes::splat<Pack>(m.kn), lanes::splat<Pack>(m.ks), lanes::splat<Pack>(p.fric), pack3(k.normal),
                        gaps, pack3(k.shear_rate()), k.dt, pack3(previous.shear_force)});
  auto lane = [&o](std::size_t j) {
    LinearResult r;
    r.normal_force = o.normal_force[j];
    r.trial_shear = o.trial_shear[j];
    r.shear_force = {o.shear_force.x[j], o.shear_force.y[j], o.shear_force.z[j]};
    r.force = {o.force.x[j], o.force.y[j], o.force.z[j]};
    r.active = o.active[j] != 0;
    r.state.shear_force = r.shear_force;
    return r;
  };
  // Bit for bit: the same operations in the same order, no multiply-add fused (CMakeLists.txt).
  auto near = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (std::size_t j = 0; j < lanes::kWidth; ++j) {
    ContactKinematics kj = k;
    kj.gap = gaps[j];
    const LinearResult r = linear_force(p, m, kj, previous), v = lane(j);
    EXPECT_TRUE(near(v.normal_force, r.normal_force)) << j;
    EXPECT_TRUE(near(v.trial_shear, r.trial_shear)) << j;
    for (int d = 0; d < 3; ++d) {
      EXPECT_TRUE(near(v.force[d], r.force[d])) << j << " " << d;
      EXPECT_TRUE(near(v.shear_force[d], r.shear_force[d])) << j << " " << d;
    }
    EXPECT_EQ(v.active, r.active) << j;
  }
  return lane(0);
}

void expect_vec_near(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

double rel7(double v) { return 1e-6 * std::abs(v); }

const Vec3 kZ{0, 0, 1};

TEST(LinearMapping, BallBallL1) {
  const LinearMapping m = linear_mapping(params(29e9, 1.0, 0.4), kR1, kR2);
  EXPECT_NEAR(m.kn, 1.822124e8, rel7(1.822124e8));
  EXPECT_DOUBLE_EQ(m.ks, m.kn);
  // Symmetric in the two balls.
  const LinearMapping s = linear_mapping(params(29e9, 1.0, 0.4), kR2, kR1);
  EXPECT_DOUBLE_EQ(s.kn, m.kn);
}

TEST(LinearMapping, ShearStiffnessFromKratio) {
  const LinearMapping m = linear_mapping(params(29e9, 2.5, 0.4), kR1, kR2);
  EXPECT_NEAR(m.ks, 1.822124e8 / 2.5, rel7(1.822124e8 / 2.5));
}

// Ball-wall: r̄ = L = R, so k_n = π R² E*/R = π R E* = π · 5e-3 · 29e9 = 4.555309e8 N/m.
TEST(LinearMapping, BallWallUsesTheBallRadius) {
  const LinearMapping m = linear_mapping(params(29e9, 1.0, 0.4), kR2, 0.0);
  EXPECT_NEAR(m.kn, 4.555309e8, rel7(4.555309e8));
  EXPECT_NEAR(m.kn, std::numbers::pi * kR2 * 29e9, 1e-6);
}

TEST(LinearForce, NormalForceL2) {
  const LinearParams p = params(29e9, 1.0, 0.4);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const LinearResult r = linear_force_both_widths(p, m, kin(kZ, -1e-4, {}), LinearState{});
  EXPECT_TRUE(r.active);
  EXPECT_NEAR(r.normal_force, 18221.24, rel7(18221.24));
  expect_vec_near(r.force, {0, 0, 18221.24}, rel7(18221.24));  // pushes piece 2 along +n̂
  expect_vec_near(r.shear_force, {}, 0.0);
}

TEST(LinearForce, NoDashpotNormalVelocityIgnored) {
  const LinearParams p = params(29e9, 1.0, 0.4);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const LinearResult r = linear_force_both_widths(p, m, kin(kZ, -1e-4, {0, 0, -100.0}), LinearState{});
  EXPECT_NEAR(r.normal_force, 18221.24, rel7(18221.24));
}

TEST(LinearForce, NoTensionWhenOpen) {
  const LinearParams p = params(29e9, 1.0, 0.4);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  for (double gap : {0.0, 1e-9, 1e-3}) {
    const LinearResult r = linear_force_both_widths(p, m, kin(kZ, gap, {5.0, 1.0, 3.0}), state({-300.0, 20.0, 0}));
    EXPECT_FALSE(r.active) << gap;
    EXPECT_EQ(r.normal_force, 0.0) << gap;
    EXPECT_TRUE(r.force == Vec3{}) << gap;
    EXPECT_TRUE(r.shear_force == Vec3{}) << gap;
    EXPECT_TRUE(r.state.shear_force == Vec3{}) << gap;  // shear reset
  }
}

// Incremental shear with μ large: F_s = F_s,o − k_s Δδ_s. From 1000 N along −x, a further
// 10 µm (10 m/s over 1e-6 s) along +x adds 1.822124e8 · 1e-5 = 1822.124 N: 2822.124 N along −x.
TEST(LinearForce, IncrementalShear) {
  const LinearParams p = params(29e9, 1.0, 10.0);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const LinearResult r = linear_force_both_widths(p, m, kin(kZ, -1e-4, {10.0, 0, 0}), state({-1000.0, 0, 0}));
  expect_vec_near(r.shear_force, {-2822.124, 0, 0}, rel7(2822.124));
  expect_vec_near(r.state.shear_force, r.shear_force, 0.0);
  EXPECT_NEAR(r.trial_shear, 2822.124, rel7(2822.124));
  expect_vec_near(r.force, {-2822.124, 0, 18221.24}, rel7(18221.24));

  // No relative motion: the stored force is kept.
  const LinearResult again = linear_force_both_widths(p, m, kin(kZ, -1e-4, {}), r.state);
  expect_vec_near(again.shear_force, r.shear_force, 1e-9);

  // Reversing the motion brings it back.
  const LinearResult back = linear_force_both_widths(p, m, kin(kZ, -1e-4, {-10.0, 0, 0}), r.state);
  expect_vec_near(back.shear_force, {-1000.0, 0, 0}, 1e-6);
}

// L4/L5: 99 µm in one step (99 m/s over 1e-6 s): trial 18039.03 N, clamped to μ F_n = 7288.495 N.
TEST(LinearForce, CoulombClampL4L5) {
  const LinearParams p = params(29e9, 1.0, 0.4);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const LinearResult r = linear_force_both_widths(p, m, kin(kZ, -1e-4, {0, 99.0, 0}), LinearState{});
  EXPECT_NEAR(r.trial_shear, 18039.03, rel7(18039.03));
  expect_vec_near(r.shear_force, {0, -7288.495, 0}, rel7(7288.495));
  expect_vec_near(r.state.shear_force, {0, -7288.495, 0}, rel7(7288.495));
}

TEST(LinearForce, ClampKeepsTheTrialDirection) {
  const LinearParams p = params(29e9, 1.0, 0.4);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  // Stored 18039.03 N along +y, increment 99 µm along +x: trial (−18039.03, 18039.03, 0), at 45°.
  const LinearResult r = linear_force_both_widths(p, m, kin(kZ, -1e-4, {99.0, 0, 0}), state({0, m.ks * 99e-6, 0}));
  EXPECT_NEAR(r.trial_shear, 18039.03 * std::sqrt(2.0), rel7(18039.03 * std::sqrt(2.0)));
  EXPECT_NEAR(norm(r.shear_force), 7288.495, rel7(7288.495));
  EXPECT_NEAR(r.shear_force.x, -r.shear_force.y, 1e-9);
  EXPECT_LT(r.shear_force.x, 0.0);
}

TEST(LinearForce, ZeroFrictionGivesNoShear) {
  const LinearParams p = params(29e9, 1.0, 0.0);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const LinearResult r = linear_force_both_widths(p, m, kin(kZ, -1e-4, {5.0, 0, 0}), LinearState{});
  EXPECT_EQ(norm(r.shear_force), 0.0);
  EXPECT_NEAR(r.normal_force, 18221.24, rel7(18221.24));
}

TEST(LinearForce, SwappingPiecesReversesTheForce) {
  const LinearParams p = params(29e9, 1.0, 0.4);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const Vec3 n{1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0};
  const Vec3 stored = Vec3{2.0, -1.0, 0.0} * 500.0;
  const Vec3 v{30.0, -10.0, 20.0};
  const LinearResult a = linear_force_both_widths(p, m, kin(n, -1e-4, v), state(stored));
  const LinearResult b = linear_force_both_widths(p, m, kin(-n, -1e-4, -v), state(-stored));
  expect_vec_near(b.force, -a.force, 1e-9 * norm(a.force));
  expect_vec_near(b.state.shear_force, -a.state.shear_force, 1e-9 * norm(a.force));
}

}  // namespace
}  // namespace hilldem
