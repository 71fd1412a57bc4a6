// The k1–k3 fit of the universal model: exact recovery from noiseless data, recovery within the
// standard errors from noisy data, and its refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hilldem/core/error.hpp"
#include "hilldem/labtests/t307_sequences.hpp"
#include "hilldem/labtests/universal_model.hpp"

namespace hilldem {
namespace {

// The 15 T 307 sequences' θ and τ_oct, M_r from the model plus Gaussian noise of standard deviation
// `noise` × the mean M_r (constant, as the unweighted fit and its standard errors assume).
std::vector<UniversalPoint> synthetic(double k1, double k2, double k3, double noise, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  UniversalFit truth;
  truth.k1 = k1, truth.k2 = k2, truth.k3 = k3;
  std::vector<UniversalPoint> pts;
  double mean = 0.0;
  for (const T307Sequence& s : t307_base_sequences()) {
    if (s.number == 0) continue;
    pts.push_back({s.bulk_stress(), s.octahedral_shear(), truth.predict(s.bulk_stress(), s.octahedral_shear())});
    mean += pts.back().modulus / 15.0;
  }
  for (UniversalPoint& p : pts) p.modulus += noise * mean * n01(rng);
  return pts;
}

TEST(UniversalModel, RecoversExactCoefficients) {
  const UniversalFit f = fit_universal_model(synthetic(1200.0, 0.65, -0.12, 0.0, 1));
  EXPECT_NEAR(f.k1, 1200.0, 1e-6);
  EXPECT_NEAR(f.k2, 0.65, 1e-9);
  EXPECT_NEAR(f.k3, -0.12, 1e-9);
  EXPECT_NEAR(f.r_squared, 1.0, 1e-12);
  EXPECT_TRUE(f.converged);
  EXPECT_EQ(f.points, 15);
}

// Noise of 3 % of the mean M_r on the 15 T 307 points, twenty seeds: each coefficient within 4
// standard errors of the truth in every draw, within 1 standard error in about two thirds (a
// t-distribution with 12 degrees of freedom: 66 %) of the 60 estimates, R² high.
TEST(UniversalModel, RecoversNoisyCoefficientsWithinTheirStandardErrors) {
  const double k1 = 900.0, k2 = 0.7, k3 = -0.3;
  int within_one = 0, total = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const UniversalFit f = fit_universal_model(synthetic(k1, k2, k3, 0.03, seed));
    SCOPED_TRACE(f.text());
    EXPECT_TRUE(f.converged);
    EXPECT_GT(f.se_k1, 0.0);
    EXPECT_GT(f.se_k2, 0.0);
    EXPECT_GT(f.se_k3, 0.0);
    EXPECT_LT(std::abs(f.k1 - k1), 4.0 * f.se_k1);
    EXPECT_LT(std::abs(f.k2 - k2), 4.0 * f.se_k2);
    EXPECT_LT(std::abs(f.k3 - k3), 4.0 * f.se_k3);
    within_one += (std::abs(f.k1 - k1) < f.se_k1) + (std::abs(f.k2 - k2) < f.se_k2) + (std::abs(f.k3 - k3) < f.se_k3);
    total += 3;
    EXPECT_GT(f.r_squared, 0.95);
  }
  EXPECT_GT(within_one, total * 45 / 100);  // the standard errors are neither too small ...
  EXPECT_LT(within_one, total * 90 / 100);  // ... nor too large
}

// The fit minimises the squares of M_r (not of ln M_r): on noisy data no point of a small grid
// around it has a smaller sum of squares.
TEST(UniversalModel, FitIsALocalMinimumOfTheSquaresOfMr) {
  const auto pts = synthetic(900.0, 0.7, -0.3, 0.08, 7);
  const UniversalFit f = fit_universal_model(pts);
  auto ss = [&](double a, double b, double c) {
    UniversalFit g;
    g.k1 = a, g.k2 = b, g.k3 = c;
    double s = 0;
    for (const auto& p : pts) s += std::pow(p.modulus - g.predict(p.bulk_stress, p.octahedral_shear), 2);
    return s;
  };
  const double best = ss(f.k1, f.k2, f.k3);
  for (double da : {-0.01, 0.0, 0.01})
    for (double db : {-0.01, 0.0, 0.01})
      for (double dc : {-0.01, 0.0, 0.01}) EXPECT_GE(ss(f.k1 * (1 + da), f.k2 + db, f.k3 + dc), best * (1 - 1e-12));
}

TEST(UniversalModel, RefusesTooFewOrBadPoints) {
  auto pts = synthetic(900.0, 0.7, -0.3, 0.0, 1);
  pts.resize(3);
  EXPECT_THROW(fit_universal_model(pts), InputError);
  pts = synthetic(900.0, 0.7, -0.3, 0.0, 1);
  pts[4].modulus = -1.0;
  try {
    fit_universal_model(pts);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("point 5"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hilldem
