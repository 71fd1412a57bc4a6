#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"

using namespace hilldem;

namespace {

// The largest x²/a² + y²/b² + z²/c² over points of pebble k's surface (≤ 1: inside the ellipsoid),
// on a 60 × 120 grid of directions.
double worst_surface_point(const EllipsoidFill& f, const Pebbles& p, std::size_t k) {
  double worst = 0.0;
  for (int i = 0; i <= 60; ++i)
    for (int j = 0; j < 120; ++j) {
      const double th = std::numbers::pi * i / 60, ph = 2 * std::numbers::pi * j / 120;
      const Vec3 x = p.position[k] + Vec3{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)} * p.radius[k];
      worst = std::max(worst, x.x * x.x / (f.a * f.a) + x.y * x.y / (f.b * f.b) + x.z * x.z / (f.c * f.c));
    }
  return worst;
}

}  // namespace

TEST(ClumpShapes, EllipsoidPebblesInsideAndAsAsked) {
  for (const EllipsoidFill f : {EllipsoidFill{2e-3, 1e-3, 1e-3, 10, 0.5}, EllipsoidFill{3e-3, 1e-3, 1e-3, 20, 0.3},
                                EllipsoidFill{2e-3, 1.5e-3, 1e-3, 7, 0.4}, EllipsoidFill{1.1e-3, 1e-3, 1e-3, 5, 0.2}}) {
    const Pebbles p = fill_ellipsoid(f);
    ASSERT_EQ(p.size(), static_cast<std::size_t>(f.count));
    double smallest = 1e300;
    for (std::size_t k = 0; k < p.size(); ++k) {
      EXPECT_LE(worst_surface_point(f, p, k), 1.0 + 1e-12) << k;
      smallest = std::min(smallest, p.radius[k]);
    }
    EXPECT_NEAR(smallest, f.smallest_ratio * f.c, 1e-15);
    // the ends touch the surface: each end pebble's farthest point is on it
    EXPECT_NEAR(worst_surface_point(f, p, 0), 1.0, 1e-3);
  }
}

TEST(ClumpShapes, SpheroidVolumeFraction) {
  // Prolate spheroid 2:1 (b = c): the union's volume against the spheroid's, measured at 256 columns.
  const EllipsoidFill f{2e-3, 1e-3, 1e-3, 20, 0.5};
  const ClumpTemplate t = make_template_columns(fill_ellipsoid(f), 2650.0, 256);
  const double fraction = t.volume / ellipsoid_volume(f);
  EXPECT_GT(fraction, 0.99);
  EXPECT_LT(fraction, 1.0);
  // more pebbles, closer
  EllipsoidFill few = f;
  few.count = 5;
  EXPECT_LT(make_template_columns(fill_ellipsoid(few), 2650.0, 256).volume, t.volume);
  // the major axis is the axis of the smallest moment, and the two others are equal (to the columns)
  EXPECT_GT(std::abs(to_matrix(t.orientation).column(0).x), 1.0 - 1e-9);
  EXPECT_NEAR(t.principal_inertia.y, t.principal_inertia.z, 1e-3 * t.principal_inertia.z);
  // the spheroid's own moments, (m/5)(b² + c²) about x and (m/5)(a² + c²) about y, within 2 %
  const double m = t.mass;
  EXPECT_NEAR(t.principal_inertia.x, m / 5 * (f.b * f.b + f.c * f.c), 0.02 * t.principal_inertia.x);
  EXPECT_NEAR(t.principal_inertia.z, m / 5 * (f.a * f.a + f.c * f.c), 0.02 * t.principal_inertia.z);
}

TEST(ClumpShapes, TriaxialFractionBoundedByCOverB) {
  const EllipsoidFill f{2e-3, 1.5e-3, 1e-3, 40, 0.5};
  const double fraction = make_template_columns(fill_ellipsoid(f), 2650.0, 256).volume / ellipsoid_volume(f);
  EXPECT_LT(fraction, f.c / f.b);
  EXPECT_GT(fraction, 0.99 * f.c / f.b);
}

TEST(ClumpShapes, OnePebbleAndBadInput) {
  const Pebbles one = fill_ellipsoid({2e-3, 1e-3, 1e-3, 1, 0.5});
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one.radius[0], 1e-3);
  EXPECT_THROW(fill_ellipsoid({1e-3, 2e-3, 1e-3, 5, 0.5}), InputError);  // a < b
  EXPECT_THROW(fill_ellipsoid({2e-3, 1e-3, 1e-3, 0, 0.5}), InputError);
  EXPECT_THROW(fill_ellipsoid({2e-3, 1e-3, 1e-3, 5, 0.0}), InputError);
  EXPECT_THROW(fill_ellipsoid({2e-3, 1e-3, 0.0, 5, 0.5}), InputError);
}

// The named templates of the command line: their pebbles and (exact) volumes in pebble radii.
TEST(ClumpShapes, NamedTemplates) {
  const double pi = std::numbers::pi;
  const ClumpTemplate s = named_template("sphere", 1000.0);
  ASSERT_EQ(s.pebbles.size(), 1u);
  EXPECT_NEAR(s.volume, 4.0 / 3.0 * pi, 1e-14);
  // Two unit spheres 1 apart: 2 (4/3)π minus the lens π (4r + d)(2r − d)² / 12 = 5π/12.
  const ClumpTemplate e2 = named_template("elongated2", 1000.0);
  ASSERT_EQ(e2.pebbles.size(), 2u);
  EXPECT_NEAR(e2.volume, 8.0 / 3.0 * pi - 5.0 * pi / 12.0, 1e-13);
  EXPECT_NEAR(e2.mass, 1000.0 * e2.volume, 1e-10);
  EXPECT_NEAR(std::abs(e2.pebbles.position[0].x - e2.pebbles.position[1].x), 1.0, 1e-14);  // along the I1 axis
  const ClumpTemplate e3 = named_template("elongated3", 1000.0);
  ASSERT_EQ(e3.pebbles.size(), 3u);
  EXPECT_NEAR(e3.volume, 4.0 / 3.0 * pi * 3.0 - 2.0 * 5.0 * pi / 12.0, 2e-3 * e3.volume);
  EXPECT_THROW(named_template("cube", 1000.0), InputError);
}
