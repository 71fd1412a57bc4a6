// Porosity in a measurement cylinder: exact sphere volumes inside the region.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hilldem/labtests/measure_region.hpp"

namespace hilldem {
namespace {

const double kR = 5e-3;
const double kBall = 4.0 / 3.0 * std::numbers::pi * kR * kR * kR;
const MeasurementCylinder kRegion{0.05, 0.0, 0.1};

TEST(MeasureRegion, WholeSpheresInAndOut) {
  EXPECT_DOUBLE_EQ(sphere_volume_inside(kRegion, {0, 0, 0.05}, kR), kBall);
  EXPECT_DOUBLE_EQ(sphere_volume_inside(kRegion, {0.02, -0.01, 0.02}, kR), kBall);
  EXPECT_EQ(sphere_volume_inside(kRegion, {0.056, 0, 0.05}, kR), 0.0);
  EXPECT_EQ(sphere_volume_inside(kRegion, {0, 0, -0.006}, kR), 0.0);
}

TEST(MeasureRegion, CutByThePlanesExactly) {
  EXPECT_NEAR(sphere_volume_inside(kRegion, {0, 0, 0.0}, kR), 0.5 * kBall, 1e-12 * kBall);
  EXPECT_NEAR(sphere_volume_inside(kRegion, {0.01, 0, 0.1}, kR), 0.5 * kBall, 1e-12 * kBall);
  // A cap of height h = R/2: π h² (3R − h)/3.
  const double h = 0.5 * kR;
  EXPECT_NEAR(sphere_volume_inside(kRegion, {0, 0, 0.1 - kR}, kR), kBall, 1e-12 * kBall);  // touching from inside
  EXPECT_NEAR(sphere_volume_inside(kRegion, {0, 0, -kR + h}, kR), std::numbers::pi * h * h * (3 * kR - h) / 3, 1e-12 * kBall);
}

TEST(MeasureRegion, CutByTheCylinderWall) {
  // Centre on the curved wall of a wide region: very nearly half (the wall curves away by R²/2R_m).
  const double v = sphere_volume_inside(kRegion, {0.05, 0, 0.05}, kR);
  EXPECT_NEAR(v, 0.5 * kBall, 0.02 * kBall);
  EXPECT_LT(v, 0.5 * kBall);  // the inside of a convex boundary is the smaller part
  // Symmetry: the same at any angle.
  const double a = 0.7;
  EXPECT_NEAR(sphere_volume_inside(kRegion, {0.05 * std::cos(a), 0.05 * std::sin(a), 0.05}, kR), v, 1e-12 * kBall);
  // Inside and outside parts of a sphere straddling the wall add up to the sphere: region and its
  // complement, via a region of radius large enough to hold it all.
  const MeasurementCylinder big{1.0, 0.0, 0.1};
  EXPECT_NEAR(sphere_volume_inside(big, {0.05, 0, 0.05}, kR), kBall, 1e-12 * kBall);
  // A corner: the sphere cut by the wall and a plane at once, a quarter (nearly).
  EXPECT_NEAR(sphere_volume_inside(kRegion, {0.05, 0, 0.0}, kR), 0.25 * kBall, 0.02 * kBall);
}

TEST(MeasureRegion, PorosityOfAKnownPacking) {
  // Simple cubic packing of touching spheres, far larger than the region: porosity 1 − π/6.
  std::vector<Vec3> c;
  std::vector<double> r;
  const double d = 2 * kR;
  for (int i = -8; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -2; k <= 13; ++k) c.push_back({i * d, j * d, k * d}), r.push_back(kR);
  const MeasurementCylinder m{0.06, 0.0, 0.1};
  EXPECT_NEAR(region_porosity(m, c, r), 1 - std::numbers::pi / 6, 0.01);
}

}  // namespace
}  // namespace hilldem
