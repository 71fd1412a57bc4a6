// Grain-size distributions: the built-in gradings, user files, seeded sampling, the realised curve.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hilldem/core/error.hpp"
#include "hilldem/labtests/gsd.hpp"

namespace hilldem {
namespace {

double sum_fractions(const Grading& g) {
  double s = 0.0;
  for (const GradingBin& b : g.bins) s += b.fraction;
  return s;
}

TEST(Grading, BuiltInGradingsAreTheMemos) {
  const Grading n = grading_c5n(), b = grading_c5b();
  ASSERT_EQ(n.bins.size(), 1u);
  EXPECT_DOUBLE_EQ(n.bins[0].d_lower, 14e-3);
  EXPECT_DOUBLE_EQ(n.bins[0].d_upper, 20e-3);
  ASSERT_EQ(b.bins.size(), 8u);
  EXPECT_NEAR(sum_fractions(b), 1.0, 1e-12);  // spec C1
  EXPECT_DOUBLE_EQ(b.bins.back().d_lower, 4.8e-3);
  EXPECT_DOUBLE_EQ(b.bins.back().fraction, 0.39);
  EXPECT_NO_THROW(validate_grading(n));
  EXPECT_NO_THROW(validate_grading(b));
  EXPECT_EQ(resolve_grading("c5B").name, "C5b");
  EXPECT_EQ(resolve_grading("C5n").name, "C5n");
}

TEST(Grading, UnknownNameSaysWhatIsAllowed) {
  try {
    resolve_grading("C5x");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown grading 'C5x'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("C5n, C5b"), std::string::npos) << e.what();
  }
}

TEST(Grading, UserFileWithHeaderAndComments) {
  const Grading g = parse_grading_csv("# mine\nd_lower_mm,d_upper_mm,fraction\n4.8, 6.0, 0.25  # fine\n6.0,9.5,0.75\n", "my.csv");
  ASSERT_EQ(g.bins.size(), 2u);
  EXPECT_EQ(g.name, "my");
  EXPECT_DOUBLE_EQ(g.bins[1].d_upper, 9.5e-3);
  EXPECT_DOUBLE_EQ(g.bins[0].fraction, 0.25);
  const Grading f = resolve_grading(std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv");
  EXPECT_DOUBLE_EQ(f.bins[0].d_lower, 5.6e-3);
}

TEST(Grading, BadUserFilesAreRefusedWithTheReason) {
  auto message = [](const std::string& text) {
    try {
      parse_grading_csv(text, "g.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("4.8,6.0,0.5\n6.0,7.0,0.4\n").find("sum to 0.9"), std::string::npos);
  EXPECT_NE(message("4.8,6.0,0.5\n5.0,7.0,0.5\n").find("overlap"), std::string::npos);
  EXPECT_NE(message("6.0,4.8,1.0\n").find("upper diameter below"), std::string::npos);
  EXPECT_NE(message("-1,4.8,1.0\n").find("> 0"), std::string::npos);
  EXPECT_NE(message("4.8,6.0,-0.5\n6,7,1.5\n").find("volume fraction"), std::string::npos);
  EXPECT_NE(message("4.8,6.0\n").find("g.csv:1"), std::string::npos);
  EXPECT_NE(message("a,b,c\n4.8,x,1\n").find("g.csv:2"), std::string::npos);
  EXPECT_NE(message("# nothing\n").find("no grading bins"), std::string::npos);
  EXPECT_THROW(resolve_grading(std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/bad_sum.csv"), InputError);
}

TEST(Sampling, SameSeedSameGrainsOtherSeedOtherGrains) {
  const Grading g = grading_c5b();
  Rng a(10000), b(10000), c(10001);
  const GrainSample sa = sample_grains(g, 1.0, 2e-4, a);
  const GrainSample sb = sample_grains(g, 1.0, 2e-4, b);
  const GrainSample sc = sample_grains(g, 1.0, 2e-4, c);
  EXPECT_EQ(sa.diameters, sb.diameters);
  EXPECT_NE(sa.diameters, sc.diameters);
  // The first uniform deviates of the seed are fixed by the generator (xoshiro256**), not by the
  // standard library: the same specimen on any platform.
  Rng r(10000);
  const double u = r.uniform();
  EXPECT_GE(u, 0.0);
  EXPECT_LT(u, 1.0);
  Rng r2(10000);
  EXPECT_EQ(r2.uniform(), u);
}

TEST(Sampling, EveryGrainInItsBinAndTheVolumesMatchTheTarget) {
  const Grading g = grading_c5b();
  Rng rng(7);
  const double vs = 5e-3;  // about 30,000 grains
  const GrainSample s = sample_grains(g, 1.0, vs, rng);
  ASSERT_EQ(s.diameters.size(), s.bin.size());
  for (std::size_t i = 0; i < s.diameters.size(); ++i) {
    const GradingBin& b = g.bins[s.bin[i]];
    ASSERT_GE(s.diameters[i], b.d_lower);
    ASSERT_LE(s.diameters[i], b.d_upper);
  }
  // Each bin is filled to within half of its largest grain's volume.
  EXPECT_NEAR(s.solid_volume(), vs, 0.5 * std::numbers::pi / 6 * std::pow(23e-3, 3) * g.bins.size());
  const GradingReport r = grading_report(g, 1.0, s.diameters);
  EXPECT_EQ(r.count, s.diameters.size());
  EXPECT_EQ(r.outside, 0u);
  EXPECT_LT(r.worst_bin_error, 2e-3);
  EXPECT_NEAR(static_cast<double>(s.diameters.size()), expected_grain_count(g, 1.0, vs), 0.02 * s.diameters.size());
  EXPECT_NEAR(r.d50_realised, r.d50_target, 0.1e-3);
}

TEST(Sampling, DiameterMultiplierScalesEverySize) {
  Rng a(3), b(3);
  const GrainSample s1 = sample_grains(grading_c5n(), 1.0, 1e-3, a);
  const GrainSample s2 = sample_grains(grading_c5n(), 0.5, 1e-3 / 8, b);
  ASSERT_EQ(s1.diameters.size(), s2.diameters.size());
  for (std::size_t i = 0; i < s1.diameters.size(); ++i) EXPECT_NEAR(s2.diameters[i], 0.5 * s1.diameters[i], 1e-15);
}

TEST(Sampling, RefusesAbsurdGrainCountsBeforeDrawing) {
  Rng rng(1);
  EXPECT_THROW(sample_grains(grading_c5b(), 0.01, 1.0, rng), InputError);
}

TEST(RealisedCurve, TargetPassingAtTheBinBoundsIsTheCumulativeFraction) {
  const Grading g = grading_c5b();
  EXPECT_DOUBLE_EQ(target_passing(g, 1.0, 4.8e-3), 0.0);
  EXPECT_NEAR(target_passing(g, 1.0, 6.0e-3), 0.39, 1e-12);
  EXPECT_NEAR(target_passing(g, 1.0, 7.0e-3), 0.49, 1e-12);
  EXPECT_NEAR(target_passing(g, 1.0, 19.0e-3), 0.93, 1e-12);
  EXPECT_NEAR(target_passing(g, 1.0, 23.0e-3), 1.0, 1e-12);
  // Inside a bin: (s⁴ − lo⁴)/(hi⁴ − lo⁴) of the bin (uniform diameters by number).
  const double s = 17e-3;
  EXPECT_NEAR(grading_c5n().bins.size(), 1u, 0);
  EXPECT_NEAR(target_passing(grading_c5n(), 1.0, s), (std::pow(17.0, 4) - std::pow(14.0, 4)) / (std::pow(20.0, 4) - std::pow(14.0, 4)),
              1e-12);
}

TEST(RealisedCurve, ReportOfAHandMadeSample) {
  // Two grains of 5 mm and one of 10 mm: volumes 1 : 1 : 8.
  const Grading g{"two", {{4e-3, 6e-3, 0.2}, {9e-3, 11e-3, 0.8}}};
  const GradingReport r = grading_report(g, 1.0, {5e-3, 10e-3, 5e-3});
  EXPECT_EQ(r.bins[0].count, 2u);
  EXPECT_EQ(r.bins[1].count, 1u);
  EXPECT_NEAR(r.bins[0].realised_fraction, 0.2, 1e-12);
  EXPECT_NEAR(r.bins[1].realised_fraction, 0.8, 1e-12);
  EXPECT_NEAR(r.worst_bin_error, 0.0, 1e-12);
  for (const PassingPoint& p : r.curve) {
    const double want = p.size < 5e-3 ? 0.0 : (p.size < 10e-3 ? 0.2 : 1.0);
    EXPECT_NEAR(p.realised, want, 1e-12) << "at " << p.size;
  }
  EXPECT_NE(r.csv().find("size[mm],target_passing[%],realised_passing[%]"), std::string::npos);
  EXPECT_NE(r.text().find("3 grains"), std::string::npos);
  const GradingReport other = grading_report(g, 1.0, {7.5e-3});
  EXPECT_EQ(other.outside, 1u);
}

}  // namespace
}  // namespace hilldem
