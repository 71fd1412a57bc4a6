// The benchmark's dense clump bed (bench/bed_bench.hpp, make_pair_bed): touching spheres joined in
// pairs, each pebble where its sphere was.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "hilldem/bench/bed_bench.hpp"

namespace hilldem {
namespace {

TEST(ClumpBed, TouchingSpheresBecomePairs) {
  Packing p;
  p.has_box = true;
  p.box_lo = {0.0, 0.0, 0.0};
  p.box_hi = {0.1, 0.1, 0.1};
  const double r = 5e-3;
  // A row of three touching spheres (overlap 1e-6 m) on the floor: the first two a pair, the third
  // alone; two spheres touching only through the periodic boundary in x: two one-pebble clumps.
  p.balls = {{{0.03, 0.05, r}, r, 2650.0},
             {{0.03 + 2 * r - 1e-6, 0.05, r}, r, 2650.0},
             {{0.03 + 4 * r - 2e-6, 0.05, r}, r, 2650.0},
             {{r, 0.02, r}, r, 2650.0},
             {{0.1 - r + 1e-6, 0.02, r}, r, 2650.0}};
  const Simulation sim = make_pair_bed(p);
  ASSERT_EQ(sim.balls.size(), 5u);
  ASSERT_EQ(sim.clumps.size(), 4u);
  EXPECT_FALSE(sim.settings.box.any());
  int pairs = 0;
  for (std::size_t i = 0; i < sim.clumps.size(); ++i) {
    std::size_t pebbles = 0;
    std::vector<Vec3> at;
    for (std::size_t k = 0; k < sim.clumps.pebbles.size(); ++k)
      if (sim.clumps.pebbles.clump[k] == i) ++pebbles, at.push_back(sim.balls.position[sim.clumps.ball[k]]);
    const double v1 = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    if (pebbles == 2) {
      ++pairs;
      // two equal spheres d ≈ 2r − 1e-6 m apart: 2 V1 minus the lens π (4r + d)(2r − d)² / 12
      const double d = norm(at[1] - at[0]);
      EXPECT_NEAR(d, 2 * r - 1e-6, 1e-8);
      EXPECT_NEAR(sim.clumps.state.mass[i], 2650.0 * (2 * v1 - std::numbers::pi * (4 * r + d) * (2 * r - d) * (2 * r - d) / 12),
                  1e-12 * sim.clumps.state.mass[i]);
    } else {
      EXPECT_EQ(pebbles, 1u);
      EXPECT_NEAR(sim.clumps.state.mass[i], 2650.0 * v1, 1e-12 * sim.clumps.state.mass[i]);
    }
  }
  EXPECT_EQ(pairs, 1);
  // every pebble where a sphere was (after the one step that finds the contacts: 1e-9 m here)
  for (std::size_t b = 0; b < sim.balls.size(); ++b) {
    double best = 1e300;
    for (const ImportedBall& s : p.balls) best = std::min(best, norm(sim.balls.position[b] - s.position));
    EXPECT_LT(best, 1e-8) << b;
  }
}

}  // namespace
}  // namespace hilldem
