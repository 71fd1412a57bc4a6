// Unit tests of the hill contact model's pure functions (spec §2, reference values of spec §7).
//
// Reference case throughout: two granite grains (spec §7, §9)
//   R1 = 7.5 mm, R2 = 5 mm, E = 29 GPa, ν = 0.15, ρ = 2650 kg/m³.
// Hand calculations:
//   R_e = 1/(1/7.5e-3 + 1/5e-3)            = 3.0e-3 m,       √R_e = 0.05477226
//   E_e = 1/(2 (1 − 0.15²)/29e9)            = 29e9/1.955     = 14.83376e9 Pa
//   G_e = 1/(2·2 (2 − 0.15)(1 + 0.15)/29e9) = 29e9/8.51      = 3.407756e9 Pa
//   k_n = 4/3 · 14.83376e9 · 0.05477226                      = 1.083305e9 N/m^1.5
//   k_s = 8 · 3.407756e9 · 0.05477226                        = 1.493204e9 N/m^1.5
//   m1 = 4/3 π (7.5e-3)³ 2650 = 4.682937e-3 kg, m2 = 4/3 π (5e-3)³ 2650 = 1.387537e-3 kg
//   m_e = 1/(1/m1 + 1/m2)                                    = 1.070385e-3 kg
//   β_n = 0.07 √(1.070385e-3 · 1.083305e9) = 0.07 · 1076.83   = 75.378
//   β_s = 0.07 √(1.070385e-3 · 1.493204e9) = 0.07 · 1264.24   = 88.497
//   R_o = min(R1, R2) = 5e-3 m
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include "hilldem/models/hill.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {
namespace {

constexpr double kR1 = 7.5e-3, kR2 = 5.0e-3, kE = 29e9, kNu = 0.15, kRho = 2650.0;
constexpr double kDt = 1e-6;  // Δt of the two-grain dashpot study (spec §4, D0)

double ball_mass(double r) { return 4.0 / 3.0 * std::numbers::pi * r * r * r * kRho; }

HillBodies granite() {
  HillBodies b;
  b.r1 = kR1;
  b.r2 = kR2;
  b.e1 = b.e2 = kE;
  b.nu1 = b.nu2 = kNu;
  b.m1 = ball_mass(kR1);
  b.m2 = ball_mass(kR2);
  return b;
}

HillParams params(double mu, double gamma, double suction = 0.0) {
  HillParams p;
  p.fric_coef = mu;
  p.damp_con = gamma;
  p.suction = suction;
  return p;
}

ContactKinematics kin(const Vec3& normal, double gap, const Vec3& rel_velocity, double dt = kDt) {
  ContactKinematics k;
  k.normal = normal;
  k.gap = gap;
  k.rel_velocity = rel_velocity;
  k.dt = dt;
  return k;
}

HillState state(const Vec3& shear_hm, Moisture m = Moisture::Dry) {
  HillState s;
  s.shear_hm = shear_hm;
  s.moisture = m;
  return s;
}

// The production law at both of its widths: hill_law<lanes::Pack>, as the batched force pass runs it,
// with the contact in every lane of a Pack (lane j at the gap g_c + j·1e-6 m), and hill_force, its
// one-contact form (hill_law<double>), at each lane's gap. The two agree bit for bit and in every
// flag. Returns lane 0 (the gap g_c) as a HillResult: every hand value below is checked on both
// widths.
HillResult hill_force_both_widths(const HillParams& p, const HillMapping& m, const ContactKinematics& k,
                                  const HillState& previous) {
  using lanes::Pack;
  const auto pack3 = lanes::splat3<Pack>;
  Pack gaps;
  for (std::size_t j = 0; j < lanes::kWidth; ++j) gaps[j] = k.gap + static_cast<double>(j) * 1e-6;
  const Vec3 shear_rate = k.shear_rate();
  const bool wet = previous.moisture == Moisture::Wet;
  const HillOutput<Pack> o = hill_law<Pack>(
      {lanes::splat<Pack>(p.fric_coef), lanes::splat<Pack>(p.suction), lanes::splat<Pack>(m.kn), lanes::splat<Pack>(m.ks),
       lanes::splat<Pack>(m.bn), lanes::splat<Pack>(m.bs), lanes::splat<Pack>(m.r_o), pack3(k.normal), gaps,
       lanes::splat<Pack>(k.normal_rate()), pack3(shear_rate), k.dt, pack3(previous.shear_hm),
       wet ? ~lanes::PackMask{} : lanes::PackMask{}});
  auto lane = [&o, &previous](std::size_t j) {
    HillResult r;
    r.surface_normal = o.surface_normal[j];
    r.moisture_force = o.moisture_force[j];
    r.trial_shear = o.trial_shear[j];
    r.shear_force = {o.shear_force.x[j], o.shear_force.y[j], o.shear_force.z[j]};
    r.force = {o.force.x[j], o.force.y[j], o.force.z[j]};
    r.active = o.active[j] != 0;
    r.state = {{o.shear_hm.x[j], o.shear_hm.y[j], o.shear_hm.z[j]},
               o.ruptured[j] != 0 ? Moisture::Ruptured : previous.moisture};
    return r;
  };
  // Bit for bit: the same operations in the same order, no multiply-add fused (CMakeLists.txt).
  auto near = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (std::size_t j = 0; j < lanes::kWidth; ++j) {
    ContactKinematics kj = k;
    kj.gap = gaps[j];
    const HillResult r = hill_force(p, m, kj, previous), v = lane(j);
    EXPECT_TRUE(near(v.surface_normal, r.surface_normal)) << j << ": " << v.surface_normal << " " << r.surface_normal;
    EXPECT_TRUE(near(v.moisture_force, r.moisture_force)) << j;
    EXPECT_TRUE(near(v.trial_shear, r.trial_shear)) << j;
    for (int d = 0; d < 3; ++d) {
      EXPECT_TRUE(near(v.force[d], r.force[d])) << j << " " << d;
      EXPECT_TRUE(near(v.shear_force[d], r.shear_force[d])) << j << " " << d;
      EXPECT_TRUE(near(v.state.shear_hm[d], r.state.shear_hm[d])) << j << " " << d;
    }
    EXPECT_EQ(v.active, r.active) << j;
    EXPECT_EQ(v.state.moisture, r.state.moisture) << j;
  }
  return lane(0);
}

void expect_vec_near(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

const Vec3 kZ{0, 0, 1};
const Vec3 kX{1, 0, 0};

// Relative tolerance for values quoted with 7 significant digits.
double rel7(double v) { return 1e-6 * std::abs(v); }

// ---------------------------------------------------------------------------------------------
// Table 4 mappings (spec §2.4, H1-H6, D1)

TEST(HillMapping, TwoGraniteGrains) {
  const HillMapping m = hill_mapping(params(0.4, 0.07), granite());
  EXPECT_NEAR(m.eff_young, 14.83376e9, rel7(14.83376e9));  // H1
  EXPECT_NEAR(m.eff_radius, 3e-3, 1e-15);                   // H2
  EXPECT_NEAR(m.eff_shear, 3.407756e9, rel7(3.407756e9));   // H5
  EXPECT_NEAR(m.kn, 1.083305e9, rel7(1.083305e9));          // H3
  EXPECT_NEAR(m.ks, 1.493204e9, rel7(1.493204e9));          // H6
  EXPECT_NEAR(m.eff_mass, 1.070385e-3, rel7(1.070385e-3));  // D1: real masses of both grains
  EXPECT_NEAR(m.bn, 75.378, 5e-4);                          // 5 digits
  EXPECT_NEAR(m.bs, 88.497, 5e-4);
  EXPECT_DOUBLE_EQ(m.r_o, 5e-3);
}

TEST(HillMapping, NoDashpotsWithoutDamping) {
  const HillMapping m = hill_mapping(params(0.4, 0.0), granite());
  EXPECT_EQ(m.bn, 0.0);
  EXPECT_EQ(m.bs, 0.0);
  EXPECT_GT(m.kn, 0.0);
}

TEST(HillMapping, SymmetricInTheTwoBodies) {
  HillBodies a = granite();
  a.e2 = 70e9;
  a.nu2 = 0.3;
  HillBodies b = a;
  std::swap(b.r1, b.r2);
  std::swap(b.e1, b.e2);
  std::swap(b.nu1, b.nu2);
  std::swap(b.m1, b.m2);
  const HillMapping ma = hill_mapping(params(0.4, 0.07), a), mb = hill_mapping(params(0.4, 0.07), b);
  EXPECT_DOUBLE_EQ(ma.eff_young, mb.eff_young);
  EXPECT_DOUBLE_EQ(ma.eff_shear, mb.eff_shear);
  EXPECT_DOUBLE_EQ(ma.kn, mb.kn);
  EXPECT_DOUBLE_EQ(ma.ks, mb.ks);
  EXPECT_DOUBLE_EQ(ma.bn, mb.bn);
  EXPECT_DOUBLE_EQ(ma.r_o, mb.r_o);
}

// ---------------------------------------------------------------------------------------------
// Activity (spec §2.5)

TEST(HillActive, WetOrOverlapping) {
  EXPECT_TRUE(hill_active(Moisture::Dry, 0.0));
  EXPECT_TRUE(hill_active(Moisture::Dry, -1e-4));
  EXPECT_FALSE(hill_active(Moisture::Dry, 1e-9));
  EXPECT_FALSE(hill_active(Moisture::Ruptured, 1e-3));
  EXPECT_TRUE(hill_active(Moisture::Ruptured, -1e-6));
  EXPECT_TRUE(hill_active(Moisture::Wet, 5e-3));
}

// ---------------------------------------------------------------------------------------------
// Normal force, Eq. 13

// H4: F_n = k_n δ^1.5 = 1.083305e9 · (1e-4)^1.5 = 1.083305e9 · 1e-6 = 1083.305 N
TEST(HillNormal, HertzAtTenthOfAMillimetre) {
  const HillMapping m = hill_mapping(params(0.4, 0.0), granite());
  const HillResult r = hill_force_both_widths(params(0.4, 0.0), m, kin(kZ, -1e-4, {}), HillState{});
  EXPECT_TRUE(r.active);
  EXPECT_NEAR(r.surface_normal, 1083.305, rel7(1083.305));
  EXPECT_EQ(r.moisture_force, 0.0);
  // Compression pushes piece 2 away from piece 1: along +n̂.
  expect_vec_near(r.force, {0, 0, 1083.305}, rel7(1083.305));
  expect_vec_near(r.shear_force, {}, 0.0);
}

TEST(HillNormal, ForceAlongAnObliqueNormal) {
  const Vec3 n{1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0};
  const HillMapping m = hill_mapping(params(0.4, 0.0), granite());
  const HillResult r = hill_force_both_widths(params(0.4, 0.0), m, kin(n, -1e-4, {}), HillState{});
  expect_vec_near(r.force, n * 1083.305, rel7(1083.305));
}

TEST(HillNormal, DampingDoesNotChangeTheStaticForce) {
  // With no relative velocity the dashpot adds nothing (D3 and H4 both at rest).
  const HillMapping m = hill_mapping(params(0.4, 0.07), granite());
  const HillResult r = hill_force_both_widths(params(0.4, 0.07), m, kin(kZ, -1e-4, {}), HillState{});
  EXPECT_NEAR(r.surface_normal, 1083.305, rel7(1083.305));
}

// D2: overlap after the step δ = 0.1 mm + 100 m/s · 1e-6 s = 0.2 mm, closing at δ̇_o = 100 m/s:
//   Hertz   k_n δ^1.5           = 1.083305e9 · (2e-4)^1.5 = 1.083305e9 · 2.828427e-6 = 3064.048 N
//   dashpot β_n δ^0.25 δ̇_o       = 75.37780 · (2e-4)^0.25 · 100 = 75.37780 · 0.1189207 · 100 = 896.398 N
//   total                                                                            = 3960.446 N
TEST(HillNormal, DashpotWhileClosingD2) {
  const HillMapping m = hill_mapping(params(0.4, 0.07), granite());
  // δ̇ = v2 − v1 = −100 n̂: piece 2 moves towards piece 1.
  const HillResult r = hill_force_both_widths(params(0.4, 0.07), m, kin(kZ, -2e-4, {0, 0, -100.0}), HillState{});
  EXPECT_NEAR(r.surface_normal, 3960.446, rel7(3960.446));
  expect_vec_near(r.force, {0, 0, 3960.446}, rel7(3960.446));
}

// D3: the same overlap after the velocity is reset to zero: Hertz part only, 3064.048 N.
TEST(HillNormal, AfterVelocityResetD3) {
  const HillMapping m = hill_mapping(params(0.4, 0.07), granite());
  const HillResult r = hill_force_both_widths(params(0.4, 0.07), m, kin(kZ, -2e-4, {}), HillState{});
  EXPECT_NEAR(r.surface_normal, 3064.048, rel7(3064.048));
}

TEST(HillNormal, DashpotOpposesSeparation) {
  // Separating at 100 m/s: 3064.048 − 896.398 = 2167.650 N.
  const HillMapping m = hill_mapping(params(0.4, 0.07), granite());
  const HillResult r = hill_force_both_widths(params(0.4, 0.07), m, kin(kZ, -2e-4, {0, 0, 100.0}), HillState{});
  EXPECT_NEAR(r.surface_normal, 2167.650, 2e-3);
}

TEST(HillNormal, TouchingExactlyGivesNoForce) {
  const HillMapping m = hill_mapping(params(0.4, 0.07), granite());
  const HillResult r =
      hill_force_both_widths(params(0.4, 0.07), m, kin(kZ, 0.0, {3.0, 0.0, -5.0}), state({-100.0, 0, 0}));
  EXPECT_TRUE(r.active);  // g_c ≤ 0
  EXPECT_EQ(r.surface_normal, 0.0);
  expect_vec_near(r.force, {}, 0.0);
  expect_vec_near(r.state.shear_hm, {}, 0.0);  // Eq. 16 with F^μ_s = 0
}

// ---------------------------------------------------------------------------------------------
// Shear force, Eqs. 14-18

// H7/D5: 0.02 rad · 4.95 mm = 99 µm of shear in one step (rate 99 m/s over 1e-6 s), δ = 0.1 mm,
// μ = 1000, γ_h = 0:  k_s δ^0.5 Δδ_s = 1.493204e9 · 0.01 · 99e-6 = 1478.272 N, opposing the motion.
TEST(HillShear, HertzMindlinIncrementH7) {
  const HillParams p = params(1000.0, 0.0);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {99.0, 0, 0}), HillState{});
  expect_vec_near(r.shear_force, {-1478.272, 0, 0}, rel7(1478.272));
  expect_vec_near(r.state.shear_hm, {-1478.272, 0, 0}, rel7(1478.272));
  EXPECT_NEAR(r.trial_shear, 1478.272, rel7(1478.272));
  expect_vec_near(r.force, {-1478.272, 0, 1083.305}, rel7(1478.272));
}

// D6/D7: starting from the stored F^h_s = 1478.272 N (from H7), one step with the contact point
// moving at 1000 rad/s · 4.95 mm = 4.95 m/s (Δδ_s = 4.95 µm), δ = 0.1 mm, γ_h = 0.07:
//   F^h_s = 1478.272 + 1.493204e9 · 0.01 · 4.95e-6  = 1478.272 + 73.914 = 1552.185 N  (stored, D7)
//   F^d_s = β_s δ^0.25 δ̇_s = 88.49682 · 0.1 · 4.95              =   43.806 N
//   F_s   = 1552.185 + 43.806                                   = 1595.991 N  (D6)
TEST(HillShear, DashpotStepD6D7) {
  const HillParams p0 = params(1000.0, 0.0);
  const HillMapping m0 = hill_mapping(p0, granite());
  const HillResult stage_b = hill_force_both_widths(p0, m0, kin(kZ, -1e-4, {99.0, 0, 0}), HillState{});

  const HillParams p = params(1000.0, 0.07);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {4.95, 0, 0}), stage_b.state);
  expect_vec_near(r.shear_force, {-1595.991, 0, 0}, rel7(1595.991));
  expect_vec_near(r.state.shear_hm, {-1552.185, 0, 0}, rel7(1552.185));
  EXPECT_NEAR(r.trial_shear, 1595.991, rel7(1595.991));

  // The rotation stops: the dashpot part disappears and only the stored part remains (D7).
  const HillResult after = hill_force_both_widths(p, m, kin(kZ, -1e-4, {}), r.state);
  expect_vec_near(after.shear_force, {-1552.185, 0, 0}, rel7(1552.185));
  expect_vec_near(after.state.shear_hm, {-1552.185, 0, 0}, rel7(1552.185));
}

TEST(HillShear, NormalVelocityDoesNotEnterTheShear) {
  const HillParams p = params(1000.0, 0.07);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {0, 0, -30.0}), state({0, -500.0, 0}));
  expect_vec_near(r.shear_force, {0, -500.0, 0}, 1e-9);
  expect_vec_near(r.state.shear_hm, {0, -500.0, 0}, 1e-9);
}

// Eq. 16: μ = 0.4, δ = 0.1 mm, γ_h = 0: F^μ_s = 0.4 · 1083.305 = 433.3219 N. The 99 µm trial of
// 1478.272 N is clamped, both the stored F^h_s and the output F_s.
TEST(HillShear, CoulombClampEq16) {
  const HillParams p = params(0.4, 0.0);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {99.0, 0, 0}), HillState{});
  EXPECT_NEAR(r.trial_shear, 1478.272, rel7(1478.272));
  expect_vec_near(r.state.shear_hm, {-433.3219, 0, 0}, rel7(433.3219));
  expect_vec_near(r.shear_force, {-433.3219, 0, 0}, rel7(433.3219));
}

// Eq. 18 without Eq. 16: μ = 0.4, δ = 0.1 mm, γ_h = 0.07, at rest in the normal direction
// (F^s_n = 1083.305, F^μ_s = 433.3219 N), shear rate 20 m/s over 1e-6 s, nothing stored:
//   F^h*_s = 1.493204e9 · 0.01 · 20e-6 = 298.6407 N   (< 433.32: stored unclamped)
//   F^d_s  = 88.49682 · 0.1 · 20        = 176.9936 N
//   |F*_s| = 475.6344 N > 433.32         → F_s = 433.3219 N along −x
TEST(HillShear, CoulombClampEq18OnTheTotal) {
  const HillParams p = params(0.4, 0.07);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {20.0, 0, 0}), HillState{});
  expect_vec_near(r.state.shear_hm, {-298.6407, 0, 0}, rel7(298.6407));
  EXPECT_NEAR(r.trial_shear, 475.6344, rel7(475.6344));
  expect_vec_near(r.shear_force, {-433.3219, 0, 0}, rel7(433.3219));
}

TEST(HillShear, ClampKeepsTheDirectionOfTheTrial) {
  const HillParams p = params(0.4, 0.0);
  const HillMapping m = hill_mapping(p, granite());
  // Stored shear along +y, increment along −x: the trial is (+1478.272, +1000, 0).
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {-99.0, 0, 0}), state({0, 1000.0, 0}));
  const double trial = std::hypot(1478.272, 1000.0);
  EXPECT_NEAR(r.trial_shear, trial, rel7(trial));
  const Vec3 expected = Vec3{1478.272, 1000.0, 0} * (433.3219 / trial);
  expect_vec_near(r.shear_force, expected, 1e-3);
  EXPECT_NEAR(norm(r.shear_force), 433.3219, rel7(433.3219));
}

TEST(HillShear, SlipEnvelope) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const HillParams p = params(0.5, 0.07, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  for (int t = 0; t < 500; ++t) {
    const Vec3 n = unit_or_zero(Vec3{u(rng), u(rng), u(rng)});
    const Vec3 v = Vec3{u(rng), u(rng), u(rng)} * 200.0;
    Vec3 s{u(rng), u(rng), u(rng)};
    s = (s - n * dot(s, n)) * 2000.0;  // stored shear, in the plane
    const double gap = -3e-4 * (u(rng) + 1.0) / 2.0;
    const Moisture mo = t % 2 ? Moisture::Wet : Moisture::Dry;
    const HillResult r = hill_force_both_widths(p, m, kin(n, gap, v), state(s, mo));
    const double limit = std::max(0.0, p.fric_coef * r.surface_normal);
    EXPECT_LE(norm(r.shear_force), limit * (1 + 1e-12) + 1e-12);
    EXPECT_LE(norm(r.state.shear_hm), limit * (1 + 1e-12) + 1e-12);
    EXPECT_NEAR(dot(r.shear_force, n), 0.0, 1e-9 * (1.0 + norm(r.shear_force)));
  }
}

// Guard of spec §2.6: separating fast makes F^s_n negative (dashpot tension). With δ = 0.1 mm and
// δ̇_n = +200 m/s: F^s_n = 1083.305 − 75.3778 · 0.1 · 200 = 1083.305 − 1507.556 = −424.251 N.
// F^μ_s = max(0, μ F^s_n) = 0: the shear force must vanish, not flip direction.
TEST(HillShear, NegativeSurfaceForceGivesZeroShear) {
  const HillParams p = params(0.4, 0.07);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {10.0, 0, 200.0}), state({-300.0, 0, 0}));
  EXPECT_NEAR(r.surface_normal, -424.251, 1e-3);
  EXPECT_GT(r.trial_shear, 0.0);
  EXPECT_EQ(norm(r.shear_force), 0.0);
  EXPECT_EQ(norm(r.state.shear_hm), 0.0);
  // Tension from the dashpot is allowed and is the only force left.
  expect_vec_near(r.force, {0, 0, -424.251}, 1e-3);
}

// ---------------------------------------------------------------------------------------------
// Inactive contacts (spec §2.5)

TEST(HillInactive, DryOpenContactGivesExactlyZero) {
  const HillParams p = params(0.4, 0.07, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, 1e-4, {3.0, -2.0, -50.0}), state({-300.0, 40.0, 0}));
  EXPECT_FALSE(r.active);
  EXPECT_EQ(r.surface_normal, 0.0);
  EXPECT_EQ(r.moisture_force, 0.0);
  EXPECT_TRUE(r.force == Vec3{});
  EXPECT_TRUE(r.shear_force == Vec3{});
  EXPECT_TRUE(r.state.shear_hm == Vec3{});
  EXPECT_EQ(r.state.moisture, Moisture::Dry);
}

TEST(HillInactive, RupturedOpenContactStaysRupturedAndGivesZero) {
  const HillParams p = params(0.4, 0.07, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, 2e-3, {0, 0, -1.0}), state({10.0, 0, 0}, Moisture::Ruptured));
  EXPECT_FALSE(r.active);
  EXPECT_TRUE(r.force == Vec3{});
  EXPECT_TRUE(r.state.shear_hm == Vec3{});
  EXPECT_EQ(r.state.moisture, Moisture::Ruptured);
}

// ---------------------------------------------------------------------------------------------
// Moisture force, Eq. 12 (ψ = 200 kPa, R_o = 5 mm, s_cr = R_o, rupture at 2 s_cr = 10 mm)
//   F_max = −ψ π R_o² = −200e3 · π · 25e-6 = −5π = −15.70796 N                     (M1)
//   at g = 2 mm: −15.70796 · exp(−2/(2·5)) = −15.70796 · 0.8187308 = −12.86059 N     (M3)

TEST(HillMoisture, MaximumWhenTouchingOrOverlapping) {
  EXPECT_NEAR(hill_moisture_force(200e3, 5e-3, 0.0), -15.70796, rel7(15.70796));
  EXPECT_NEAR(hill_moisture_force(200e3, 5e-3, -1e-4), -15.70796, rel7(15.70796));
}

TEST(HillMoisture, ExponentialDecay) {
  EXPECT_NEAR(hill_moisture_force(200e3, 5e-3, 2e-3), -12.86059, rel7(12.86059));
  // Just below rupture: −15.70796 · exp(−0.9999) = −5.779215 N
  EXPECT_NEAR(hill_moisture_force(200e3, 5e-3, 9.999e-3), -5.779215, rel7(5.779215));
}

TEST(HillMoisture, ZeroAtAndBeyondRupture) {
  EXPECT_DOUBLE_EQ(hill_rupture_gap(5e-3), 10e-3);
  EXPECT_EQ(hill_moisture_force(200e3, 5e-3, 10e-3), 0.0);
  EXPECT_EQ(hill_moisture_force(200e3, 5e-3, 25e-3), 0.0);
}

TEST(HillMoisture, WetOpenContactAttracts) {
  const HillParams p = params(0.4, 0.07, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, 2e-3, {1.0, 0, 0.5}), state({5.0, 0, 0}, Moisture::Wet));
  EXPECT_TRUE(r.active);
  EXPECT_EQ(r.state.moisture, Moisture::Wet);
  EXPECT_NEAR(r.moisture_force, -12.86059, rel7(12.86059));
  EXPECT_EQ(r.surface_normal, 0.0);
  EXPECT_EQ(norm(r.shear_force), 0.0);
  EXPECT_EQ(norm(r.state.shear_hm), 0.0);  // open: F^μ_s = 0 resets F^h_s
  // Suction pulls piece 2 towards piece 1: along −n̂.
  expect_vec_near(r.force, {0, 0, -12.86059}, rel7(12.86059));
}

TEST(HillMoisture, WetOverlappingContactAddsSuctionToHertz) {
  const HillParams p = params(0.4, 0.0, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {}), state({}, Moisture::Wet));
  EXPECT_NEAR(r.moisture_force, -15.70796, rel7(15.70796));
  EXPECT_NEAR(r.surface_normal, 1083.305, rel7(1083.305));
  // 1083.305 − 15.70796 = 1067.597 N
  expect_vec_near(r.force, {0, 0, 1067.597}, rel7(1067.597));
}

TEST(HillMoisture, DryContactHasNoMoistureForce) {
  const HillParams p = params(0.4, 0.0, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult r = hill_force_both_widths(p, m, kin(kZ, -1e-4, {}), HillState{});
  EXPECT_EQ(r.moisture_force, 0.0);
}

TEST(HillMoisture, RuptureAtCriticalGap) {
  const HillParams p = params(0.4, 0.07, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  for (double gap : {10e-3, 12e-3}) {
    const HillResult r = hill_force_both_widths(p, m, kin(kZ, gap, {0, 0, 1.0}), state({}, Moisture::Wet));
    EXPECT_EQ(r.state.moisture, Moisture::Ruptured) << gap;
    EXPECT_FALSE(r.active) << gap;
    EXPECT_EQ(r.moisture_force, 0.0) << gap;
    EXPECT_TRUE(r.force == Vec3{}) << gap;
  }
  // Just inside the rupture gap the bridge holds.
  const HillResult held = hill_force_both_widths(p, m, kin(kZ, 9.999e-3, {}), state({}, Moisture::Wet));
  EXPECT_EQ(held.state.moisture, Moisture::Wet);
  EXPECT_TRUE(held.active);
  EXPECT_NEAR(held.moisture_force, -5.779215, rel7(5.779215));
}

// ---------------------------------------------------------------------------------------------
// Appendix A (spec §2.10): shear (δ_s)_A at overlap δ_A = 0.1 mm gives 1478.272 N; doubling the
// overlap with no further shear motion must leave F^h_s unchanged (the absolute update would give
// √2 · 1478.272 = 2090.6 N). μ large so that nothing clamps (F_n at 0.2 mm = 3064.048 N).
TEST(HillAppendixA, DoublingTheOverlapKeepsTheShearForce) {
  const HillParams p = params(1000.0, 0.0);
  const HillMapping m = hill_mapping(p, granite());
  const HillResult a = hill_force_both_widths(p, m, kin(kZ, -1e-4, {99.0, 0, 0}), HillState{});
  ASSERT_NEAR(norm(a.state.shear_hm), 1478.272, rel7(1478.272));
  const HillResult b = hill_force_both_widths(p, m, kin(kZ, -2e-4, {}), a.state);
  EXPECT_NEAR(b.surface_normal, 3064.048, rel7(3064.048));
  expect_vec_near(b.state.shear_hm, {-1478.272, 0, 0}, rel7(1478.272));
  expect_vec_near(b.shear_force, {-1478.272, 0, 0}, rel7(1478.272));
  EXPECT_TRUE(b.state.shear_hm == a.state.shear_hm);
}

// ---------------------------------------------------------------------------------------------
// Time-step stiffness, Eqs. 19-21

// X1: open wet contact, δ := 2e-4 R_o = 1e-6 m, √δ = 1e-3:
//   k̂_n = 1.5 · 1.083305e9 · 1e-3 = 1.624957e6 N/m (≈ 1.625e6), k̂_s = 1.493204e9 · 1e-3 = 1.493204e6 N/m
TEST(HillTimestep, OpenWetContactX1) {
  const HillParams p = params(0.4, 0.0, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  for (double gap : {0.0, 2e-3}) {
    const StiffnessEstimate s = hill_timestep_stiffness(p, m, gap);
    EXPECT_NEAR(s.kn, 1.625e6, 1e-4 * 1.625e6) << gap;
    EXPECT_NEAR(s.kn, 1.624957e6, rel7(1.624957e6)) << gap;
    EXPECT_NEAR(s.ks, 1.493e6, 1e-3 * 1.493e6) << gap;
    EXPECT_NEAR(s.ks, 1.493204e6, rel7(1.493204e6)) << gap;
  }
}

// At δ = 0.1 mm: k̂_n = 1.5 · 1.083305e9 · 0.01 = 1.624957e7, k̂_s = 1.493204e7 N/m.
TEST(HillTimestep, OverlappingContact) {
  const HillParams p = params(0.4, 0.0);
  const HillMapping m = hill_mapping(p, granite());
  const StiffnessEstimate s = hill_timestep_stiffness(p, m, -1e-4);
  EXPECT_NEAR(s.kn, 1.624957e7, rel7(1.624957e7));
  EXPECT_NEAR(s.ks, 1.493204e7, rel7(1.493204e7));
}

// X2: ξ = 0.07/2 = 0.035, F = √(1 + 0.035²) − 0.035 = 0.9656123, 1/F² = 1.072493.
TEST(HillTimestep, DashpotMultiplierX2) {
  const HillParams p0 = params(0.4, 0.0), p7 = params(0.4, 0.07);
  const HillMapping m0 = hill_mapping(p0, granite()), m7 = hill_mapping(p7, granite());
  for (double gap : {-1e-4, 1e-3}) {
    const StiffnessEstimate s0 = hill_timestep_stiffness(p0, m0, gap);
    const StiffnessEstimate s7 = hill_timestep_stiffness(p7, m7, gap);
    EXPECT_NEAR(s7.kn / s0.kn, 1.072493, 1e-6) << gap;
    EXPECT_NEAR(s7.ks / s0.ks, 1.072493, 1e-6) << gap;
  }
}

// ---------------------------------------------------------------------------------------------
// Newton III at law level: swapping the pieces reverses n̂, δ̇ and the stored shear (all measured
// "2 relative to 1"); the force on the new piece 2 (old piece 1) must be the opposite.
TEST(HillSymmetry, SwappingPiecesReversesTheForce) {
  const HillParams p = params(0.5, 0.07, 200e3);
  const HillMapping m = hill_mapping(p, granite());
  const Vec3 n{1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0};
  const Vec3 stored = Vec3{2.0, -1.0, 0.0} * 60.0;  // ⟂ n
  const Vec3 v{3.0, -1.0, 2.0};
  for (double gap : {-1e-4, -2e-4, 3e-3}) {
    for (Moisture mo : {Moisture::Dry, Moisture::Wet}) {
      const HillResult a = hill_force_both_widths(p, m, kin(n, gap, v), state(stored, mo));
      const HillResult b = hill_force_both_widths(p, m, kin(-n, gap, -v), state(-stored, mo));
      expect_vec_near(b.force, -a.force, 1e-9 * (1.0 + norm(a.force)));
      expect_vec_near(b.state.shear_hm, -a.state.shear_hm, 1e-9 * (1.0 + norm(a.state.shear_hm)));
      EXPECT_DOUBLE_EQ(b.surface_normal, a.surface_normal);
      EXPECT_DOUBLE_EQ(b.moisture_force, a.moisture_force);
      EXPECT_EQ(b.state.moisture, a.state.moisture);
    }
  }
}

}  // namespace
}  // namespace hilldem
