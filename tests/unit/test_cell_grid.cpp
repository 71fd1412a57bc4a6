// Unit tests of the broad phase: find_ball_pairs must return exactly the pairs of the N² reference
// search, sorted by (i, j) with i < j, for any layout (dense, sparse, with outliers).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "hilldem/contact/cell_grid.hpp"

namespace hilldem {
namespace {

struct Balls {
  std::vector<Vec3> x;
  std::vector<double> r;
};

// n balls with radii uniform in [rmin, rmax], centres uniform in a cube of side `box` (overlaps
// allowed: a broad phase must cope with them).
Balls random_balls(std::uint32_t seed, std::size_t n, double rmin, double rmax, double box) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, box), rad(rmin, rmax);
  Balls b;
  for (std::size_t i = 0; i < n; ++i) {
    b.x.push_back({pos(rng), pos(rng), pos(rng)});
    b.r.push_back(rad(rng));
  }
  return b;
}

void expect_well_formed(const std::vector<BallPair>& pairs, std::size_t n) {
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  EXPECT_TRUE(std::adjacent_find(pairs.begin(), pairs.end()) == pairs.end());  // no duplicates
  for (const auto& [i, j] : pairs) {
    EXPECT_LT(i, j);
    EXPECT_LT(j, n);
  }
}

void expect_matches_brute_force(const Balls& b, double proximity) {
  const auto grid = find_ball_pairs(b.x, b.r, proximity);
  const auto ref = find_ball_pairs_brute_force(b.x, b.r, proximity);
  expect_well_formed(grid, b.x.size());
  EXPECT_EQ(grid.size(), ref.size());
  EXPECT_TRUE(grid == ref);
}

TEST(CellGrid, MatchesBruteForceOnRandomPolydisperseSets) {
  // 2000 balls, R in [1, 3] mm, in a 60 mm cube (about 30 % solid, many overlaps).
  for (std::uint32_t seed : {1u, 2u, 3u, 42u}) {
    const Balls b = random_balls(seed, 2000, 1e-3, 3e-3, 0.06);
    for (double proximity : {0.0, 0.5e-3}) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << ", proximity " << proximity);
      const auto ref = find_ball_pairs_brute_force(b.x, b.r, proximity);
      ASSERT_GT(ref.size(), 100u);  // the test means something
      expect_matches_brute_force(b, proximity);
    }
  }
}

TEST(CellGrid, MatchesBruteForceOnSparseAndFlatSets) {
  SCOPED_TRACE("sparse");
  expect_matches_brute_force(random_balls(5, 1500, 1e-3, 3e-3, 0.3), 0.5e-3);
  // All centres in a plane: one cell thick in z.
  Balls flat = random_balls(6, 2000, 1e-3, 3e-3, 0.1);
  for (auto& x : flat.x) x.z = 0.0;
  SCOPED_TRACE("flat");
  expect_matches_brute_force(flat, 0.0);
  expect_matches_brute_force(flat, 0.5e-3);
}

TEST(CellGrid, OneLargeBallAmongSmallOnes) {
  Balls b = random_balls(9, 1000, 1e-3, 1.5e-3, 0.05);
  b.r[17] = 20e-3;  // the cells must be wide enough for it
  expect_matches_brute_force(b, 0.0);
  expect_matches_brute_force(b, 0.5e-3);
}

TEST(CellGrid, LargeProximity) {
  const Balls b = random_balls(11, 500, 1e-3, 3e-3, 0.1);
  expect_matches_brute_force(b, 10e-3);
}

TEST(CellGrid, FarAwayBallDoesNotExplodeTheGrid) {
  Balls b = random_balls(7, 2000, 1e-3, 3e-3, 0.06);
  // One ball 1 km away along every axis, one a long way along a single axis.
  b.x.push_back({1e3, 1e3, 1e3});
  b.r.push_back(2e-3);
  b.x.push_back({-1e6, 0.03, 0.03});
  b.r.push_back(2e-3);
  for (double proximity : {0.0, 0.5e-3}) expect_matches_brute_force(b, proximity);
  // The outliers touch nothing.
  const auto pairs = find_ball_pairs(b.x, b.r, 0.0);
  for (const auto& [i, j] : pairs) {
    EXPECT_LT(j, 2000u);
    EXPECT_LT(i, 2000u);
  }
}

TEST(CellGrid, TwoFarAwayBallsFindEachOther) {
  Balls b = random_balls(8, 300, 1e-3, 3e-3, 0.03);
  b.x.push_back({500.0, -200.0, 300.0});
  b.r.push_back(2e-3);
  b.x.push_back({500.0, -200.0, 300.0035});
  b.r.push_back(2e-3);
  const auto pairs = find_ball_pairs(b.x, b.r, 0.0);
  const BallPair outliers{300u, 301u};
  EXPECT_TRUE(std::find(pairs.begin(), pairs.end(), outliers) != pairs.end());
  expect_matches_brute_force(b, 0.0);
}

// Engine bug (not fixed here, see the report): with a ball far away along all three axes the cell
// count dims_x·dims_y·dims_z overflows `long` in find_ball_pairs before the cell width is doubled,
// and the call throws std::length_error / std::bad_alloc (UBSan: signed integer overflow,
// cell_grid.cpp size_dims). With 3 balls of R = 2 mm it happens from about 10 km on.
TEST(CellGrid, VeryFarAwayBallAlongAllAxes) {
  Balls b;
  b.x = {{0, 0, 0}, {0.004, 0, 0}, {1e4, 1e4, 1e4}};
  b.r = {2e-3, 2e-3, 2e-3};
  std::vector<BallPair> pairs;
  EXPECT_NO_THROW(pairs = find_ball_pairs(b.x, b.r, 0.0));
  EXPECT_EQ(pairs, (std::vector<BallPair>{{0u, 1u}}));
}

TEST(CellGrid, NoBallOrOneBall) {
  EXPECT_TRUE(find_ball_pairs({}, {}, 0.0).empty());
  EXPECT_TRUE(find_ball_pairs({}, {}, 1e-3).empty());
  EXPECT_TRUE(find_ball_pairs({{1, 2, 3}}, {1e-3}, 0.0).empty());
  EXPECT_TRUE(find_ball_pairs({{1, 2, 3}}, {1e-3}, 1.0).empty());
}

TEST(CellGrid, CoincidentBallsGiveEveryPair) {
  const std::size_t n = 40;
  const std::vector<Vec3> x(n, Vec3{0.1, 0.2, 0.3});
  const std::vector<double> r(n, 1e-3);
  const auto pairs = find_ball_pairs(x, r, 0.0);
  EXPECT_EQ(pairs.size(), n * (n - 1) / 2);
  expect_well_formed(pairs, n);
}

// Gap exactly equal to the proximity counts (≤), one just beyond does not.
TEST(CellGrid, ProximityBoundary) {
  const std::vector<Vec3> x{{0, 0, 0}, {0.5, 0, 0}, {0.5, 0.75, 0}};
  const std::vector<double> r{0.125, 0.125, 0.125};  // binary-exact: gaps 0.25 and 0.5
  EXPECT_EQ(find_ball_pairs(x, r, 0.25), (std::vector<BallPair>{{0u, 1u}}));
  EXPECT_EQ(find_ball_pairs(x, r, 0.5), (std::vector<BallPair>{{0u, 1u}, {1u, 2u}}));
  EXPECT_TRUE(find_ball_pairs(x, r, 0.2).empty());
}

TEST(CellGrid, OutputSortedWithIBeforeJ) {
  // Insert the balls in reverse spatial order so that the grid's cell order differs from the index
  // order.
  Balls b = random_balls(21, 1000, 1e-3, 3e-3, 0.04);
  std::sort(b.x.begin(), b.x.end(), [](const Vec3& p, const Vec3& q) { return p.x > q.x; });
  const auto pairs = find_ball_pairs(b.x, b.r, 0.5e-3);
  ASSERT_FALSE(pairs.empty());
  expect_well_formed(pairs, b.x.size());
  EXPECT_TRUE(pairs == find_ball_pairs_brute_force(b.x, b.r, 0.5e-3));
}

}  // namespace
}  // namespace hilldem
