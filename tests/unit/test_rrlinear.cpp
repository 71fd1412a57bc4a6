// Unit tests of the rolling-resistance linear model (models/rrlinear.hpp, docs/spec/rrlinear.md).
//
// Two granite grains, R1 = 7.5 mm, R2 = 5 mm, E* = 29 GPa, κ* = 1, μ = 0.4, μ_r = 0.1:
//   k_n = k_s = π (5e-3)² 29e9 / 12.5e-3 = 1.822124e8 N/m (spec §3, L1)
//   R̄ = 1/(1/7.5e-3 + 1/5e-3) = 3e-3 m;  k_r = k_s R̄² = 1.822124e8 · 9e-6 = 1639.911 N m/rad
//   at 0.1 mm overlap F_n = 18221.24 N;  M* = μ_r R̄ F_n = 0.1 · 3e-3 · 18221.24 = 5.466372 N m
// Ball on a wall, R1 = 7.5 mm: R̄ = 7.5e-3 m, k_n = π R1 E* = 6.832964e8 N/m, k_r = 38435.42 N m/rad.
#include <gtest/gtest.h>

#include <cmath>

#include "hilldem/models/lanes.hpp"
#include "hilldem/models/rrlinear.hpp"

namespace hilldem {
namespace {

constexpr double kR1 = 7.5e-3, kR2 = 5.0e-3, kDt = 1e-6;
const Vec3 kZ{0, 0, 1};

LinearParams params(double rolling_fric) { return {29e9, 1.0, 0.4, rolling_fric}; }

ContactKinematics kin(double gap) { return {kZ, gap, {}, kDt}; }

double rel7(double v) { return 1e-6 * std::abs(v); }

TEST(RrLinear, RadiusAndRollingStiffness) {
  EXPECT_NEAR(rrlinear_radius(kR1, kR2), 3e-3, 1e-15);
  EXPECT_DOUBLE_EQ(rrlinear_radius(kR1, 0.0), kR1);  // a wall
  const LinearMapping m = linear_mapping(params(0.1), kR1, kR2);
  EXPECT_NEAR(m.ks * 3e-3 * 3e-3, 1639.911, rel7(1639.911));
  const LinearMapping w = linear_mapping(params(0.1), kR1, 0.0);
  EXPECT_NEAR(w.kn, 6.832964e8, rel7(6.832964e8));
  EXPECT_NEAR(w.ks * kR1 * kR1, 38435.42, rel7(38435.42));
}

// A relative bend rotation of 10 rad/s about y for one step: M_r = −k_r Δθ_b = −1639.911 · 1e-5.
TEST(RrLinear, ElasticRollingMoment) {
  const LinearParams p = params(0.1);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const RrLinearResult r = rrlinear_force(p, m, kin(-1e-4), {}, {0, 10.0, 0}, rrlinear_radius(kR1, kR2));
  EXPECT_NEAR(r.linear.normal_force, 18221.24, rel7(18221.24));  // the linear part is the linear model's
  EXPECT_NEAR(r.moment.y, -0.01639911, rel7(0.01639911));
  EXPECT_EQ(r.moment.x, 0.0);
  EXPECT_EQ(r.moment.z, 0.0);
  EXPECT_NEAR(r.trial_moment, 0.01639911, rel7(0.01639911));
}

// The twist about n̂ is not resisted: a relative spin along the normal gives no moment.
TEST(RrLinear, TwistIsNotResisted) {
  const LinearParams p = params(0.1);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const RrLinearResult r = rrlinear_force(p, m, kin(-1e-4), {}, {0, 0, 50.0}, rrlinear_radius(kR1, kR2));
  EXPECT_EQ(norm(r.moment), 0.0);
}

// A stored moment of 10 N m plus one step's increment exceeds M* = 5.466372 N m: clamped to M*, the
// direction kept; the trial (10.01639911 N m) reported.
TEST(RrLinear, MomentLimitedByRollingFriction) {
  const LinearParams p = params(0.1);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const RrLinearResult r =
      rrlinear_force(p, m, kin(-1e-4), {{}, {0, -10.0, 0}}, {0, 10.0, 0}, rrlinear_radius(kR1, kR2));
  EXPECT_NEAR(r.moment.y, -5.466372, rel7(5.466372));
  EXPECT_NEAR(norm(r.moment), 5.466372, rel7(5.466372));
  EXPECT_NEAR(r.trial_moment, 10.01639911, rel7(10.01639911));
  // μ_r = 0: no rolling resistance at all, as the linear model.
  const RrLinearResult free = rrlinear_force(params(0.0), m, kin(-1e-4), {{}, {0, -10.0, 0}}, {0, 10.0, 0}, 3e-3);
  EXPECT_EQ(norm(free.moment), 0.0);
}

// No overlap: inactive, no force, the moment forgotten.
TEST(RrLinear, InactiveContactForgetsItsMoment) {
  const LinearParams p = params(0.1);
  const LinearMapping m = linear_mapping(p, kR1, kR2);
  const RrLinearResult r = rrlinear_force(p, m, kin(1e-5), {{}, {0, -1.0, 0}}, {0, 10.0, 0}, 3e-3);
  EXPECT_FALSE(r.linear.active);
  EXPECT_EQ(norm(r.moment), 0.0);
  EXPECT_EQ(norm(r.linear.force), 0.0);
}

// The law at the batch's lane width gives the one-contact values lane by lane.
TEST(RrLinear, BothLaneWidths) {
  using lanes::Pack;
  const double ks = linear_mapping(params(0.1), kR1, kR2).ks;
  Pack fn, spin_y;
  for (std::size_t j = 0; j < lanes::kWidth; ++j) fn[j] = 18221.24 * static_cast<double>(j), spin_y[j] = 10.0 + 1e5 * j;
  const auto s = [](double x) { return lanes::splat<Pack>(x); };
  const RollingOutput<Pack> o = rolling_moment<Pack>({s(0.1), s(3e-3), s(ks), {s(0), s(0), s(1)}, {s(0), spin_y, s(0)}, kDt,
                                                      {s(0), s(-1.0), s(0)}, fn, fn > 0.0});
  for (std::size_t j = 0; j < lanes::kWidth; ++j) {
    const RollingOutput<double> one = rolling_moment<double>(
        {0.1, 3e-3, ks, {0, 0, 1}, {0, spin_y[j], 0}, kDt, {0, -1.0, 0}, fn[j], fn[j] > 0.0});
    EXPECT_NEAR(o.moment.y[j], one.moment.y, 1e-13 * std::abs(one.moment.y) + 1e-15) << j;
    EXPECT_NEAR(o.trial[j], one.trial, 1e-13 * one.trial + 1e-15) << j;
  }
}

}  // namespace
}  // namespace hilldem
