#include <gtest/gtest.h>

#include "hilldem/bodies/clump_pebbles.hpp"

using namespace hilldem;

namespace {
const Pebbles kThree{{{0.0, 0.0, 0.0}, {0.9e-3, 0.2e-3, 0.0}, {0.1e-3, 0.8e-3, 0.5e-3}}, {0.6e-3, 0.5e-3, 0.4e-3}};
}

TEST(ClumpPebbles, PlacedAtTheTemplateFrameTheyAreWhereTheyWereGiven) {
  const ClumpTemplate t = make_template(kThree, 2650.0);
  ClumpState s;
  ClumpPebbles p;
  add_clump(s, p, t, {1.0, 0.0, 0.0}, {}, {}, {});  // a second clump first: indices must follow
  const std::size_t i = add_clump(s, p, t, t.centre_of_mass, {}, {}, {});
  ASSERT_EQ(i, 1u);
  ASSERT_EQ(p.size(), 6u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(p.clump[3 + k], 1u);
    EXPECT_LT(norm(pebble_position(s, p, 3 + k) - kThree.position[k]), 1e-15);
    EXPECT_EQ(p.radius[3 + k], kThree.radius[k]);
  }
  // turned by q about its centre of mass: the pebbles turn with it
  const Quat q = from_rotation_vector({0.0, 0.0, 1.0});
  ClumpState s2;
  ClumpPebbles p2;
  add_clump(s2, p2, t, t.centre_of_mass, {}, q, {});
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_LT(norm(pebble_position(s2, p2, k) - (t.centre_of_mass + rotate(q, kThree.position[k] - t.centre_of_mass))), 1e-15);
}

TEST(ClumpPebbles, VelocitiesAndLoads) {
  const ClumpTemplate t = make_template(kThree, 2650.0);
  ClumpState s;
  ClumpPebbles p;
  const Vec3 v{0.1, 0.0, -0.2}, w{0.0, 0.0, 10.0};
  add_clump(s, p, t, {0.5, 0.5, 0.5}, v, from_rotation_vector({0.2, 0.4, 0.1}), w);
  for (std::size_t k = 0; k < 3; ++k) {
    const Vec3 r = pebble_position(s, p, k) - s.position[0];
    EXPECT_LT(norm(pebble_velocity(s, p, k) - (v + cross(w, r))), 1e-15);
  }
  // a force at pebble 1's centre and a moment on pebble 2
  std::vector<Vec3> point(3), f(3), m(3), force, torque;
  for (std::size_t k = 0; k < 3; ++k) point[k] = pebble_position(s, p, k);
  f[1] = {0.0, 1.0, 0.0};
  m[2] = {0.0, 0.0, 2e-3};
  sum_pebble_loads(s, p, point, f, m, force, torque);
  ASSERT_EQ(force.size(), 1u);
  EXPECT_EQ(force[0], f[1]);
  const Vec3 expected = cross(point[1] - s.position[0], f[1]) + m[2];
  EXPECT_LT(norm(torque[0] - expected), 1e-18);
  EXPECT_GT(norm(torque[0] - m[2]), 1e-5);  // the lever arm counts
}
