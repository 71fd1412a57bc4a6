// AASHTO T 307 base/subbase sequences against the standard's table: σ₃ and σ_max are the standard's
// psi values converted (1 psi = 6.894757 kPa) and rounded to 0.1 kPa; σ_contact is 0.1 σ_max
// rounded (half up) to 0.1 kPa and σ_cyclic = σ_max − σ_contact, which is 0.9 σ_max to within the
// 0.05 kPa of that rounding (as tabulated); θ and τ_oct from the peak.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hilldem/core/error.hpp"
#include "hilldem/labtests/t307_sequences.hpp"

namespace hilldem {
namespace {

constexpr double kPsi = 6.894757;  // kPa

double round_01(double kpa) { return std::round(kpa * 10.0 + 1e-9) / 10.0; }

TEST(T307Sequences, EveryNumberOfTheStandardsBaseTable) {
  // The standard's table in psi: {σ₃, σ_max}, conditioning first.
  const double psi[16][2] = {{15, 15}, {3, 3},   {3, 6},   {3, 9},   {5, 5},   {5, 10},  {5, 15},  {10, 10},
                             {10, 20}, {10, 30}, {15, 10}, {15, 15}, {15, 30}, {20, 15}, {20, 20}, {20, 40}};
  const auto seq = t307_base_sequences();
  ASSERT_EQ(seq.size(), 16u);
  for (int i = 0; i < 16; ++i) {
    SCOPED_TRACE(i);
    const T307Sequence& s = seq[i];
    EXPECT_EQ(s.number, i);
    EXPECT_EQ(s.standard_cycles, i == 0 ? 500 : 100);
    const double s3 = round_01(psi[i][0] * kPsi), smax = round_01(psi[i][1] * kPsi);
    EXPECT_NEAR(s.confining, s3 * 1e3, 1e-6);
    EXPECT_NEAR(s.max_stress, smax * 1e3, 1e-6);
    EXPECT_NEAR(s.contact, round_01(0.1 * smax) * 1e3, 1e-6);
    EXPECT_NEAR(s.cyclic, (smax - round_01(0.1 * smax)) * 1e3, 1e-6);
    // Internal consistency: σ_cyclic = 0.9 σ_max and σ_contact = 0.1 σ_max to the table's rounding.
    EXPECT_LE(std::abs(s.cyclic - 0.9 * s.max_stress), 50.0 + 1e-6);
    EXPECT_LE(std::abs(s.contact - 0.1 * s.max_stress), 50.0 + 1e-6);
    EXPECT_NEAR(s.bulk_stress(), 3 * s.confining + s.max_stress, 1e-9);
    EXPECT_NEAR(s.octahedral_shear(), std::sqrt(2.0) / 3.0 * s.max_stress, 1e-9);
  }
  // Spot values as tabulated in the spec (kPa).
  EXPECT_NEAR(seq[2].cyclic, 37.3e3, 1e-6);    // 41.4 − 4.1, not 5.4 psi (37.2 kPa)
  EXPECT_NEAR(seq[4].contact, 3.5e3, 1e-6);    // 0.1 × 34.5 rounded up, not 0.5 psi (3.4 kPa)
  EXPECT_NEAR(seq[4].cyclic, 31.0e3, 1e-6);    // 34.5 − 3.5, not 0.9 × 34.5 rounded (31.1 kPa)
  EXPECT_NEAR(seq[15].max_stress, 275.8e3, 1e-6);
  EXPECT_NEAR(seq[15].bulk_stress(), 689.5e3, 1e-6);
}

TEST(T307Sequences, HaversineShape) {
  EXPECT_EQ(haversine(0.0, 0.1), 0.0);
  EXPECT_NEAR(haversine(0.05, 0.1), 1.0, 1e-15);
  EXPECT_NEAR(haversine(0.025, 0.1), 0.5, 1e-12);
  EXPECT_EQ(haversine(0.1, 0.1), 0.0);
  EXPECT_EQ(haversine(0.2, 0.1), 0.0);
}

TEST(T307Timing, DefaultsAreValidAndBadValuesNameTheRange) {
  EXPECT_NO_THROW(validate(T307Timing{}));
  auto message = [](T307Timing t) {
    try {
      validate(t);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  T307Timing t;
  t.pulse_duration = 0;
  EXPECT_EQ(message(t), "pulse duration [s] must be in [1e-05, 1], got 0");
  t = {};
  t.cycles = 101;
  EXPECT_EQ(message(t), "cycles per sequence must be in [1, 100], got 101");
  t = {};
  t.cycles = 4;
  EXPECT_EQ(message(t), "averaged cycles must be in [1, 4], got 5");
  t = {};
  t.rest_duration = NAN;
  EXPECT_EQ(message(t), "rest duration [s] must be in [0, 10], got nan");
  t = {};
  t.servo_gain = 0;
  EXPECT_EQ(message(t), "servo gain [-] must be in (0, 1], got 0");
  t = {};
  t.conditioning_cycles = -1;
  EXPECT_EQ(message(t), "conditioning cycles must be in [0, 1000], got -1");
}

}  // namespace
}  // namespace hilldem
