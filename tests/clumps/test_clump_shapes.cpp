#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"

using namespace hilldem;

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
  EXPECT_THROW(named_template("dodecahedron", 1000.0), InputError);
  // the filled shapes: up to 10 pebbles, the union within the shape
  for (const char* name : {"ellipsoid", "cube", "prism", "slab", "rock"}) {
    const ClumpTemplate t = named_template(name, 1000.0);
    EXPECT_GE(t.pebbles.size(), 2u) << name;
    EXPECT_LE(t.pebbles.size(), 10u) << name;
    EXPECT_EQ(t.method, MassMethod::Columns) << name;
  }
}
