// The cache sweep of `hilldem bench --caches` (bench/memory_bandwidth.hpp): its random walk must
// visit every line of the working set once before it returns, or a short loop of lines would stay in
// a small cache and the latency it reports would be that cache's, not the working set's.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hilldem/bench/memory_bandwidth.hpp"

namespace hilldem {
namespace {

TEST(CacheSweep, RandomWalkVisitsEveryLineOnceBeforeItReturns) {
  for (const std::size_t lines : {2u, 3u, 17u, 1000u, 65536u}) {
    const std::vector<std::uint32_t> next = random_cycle(lines, 7);
    ASSERT_EQ(next.size(), lines);
    std::vector<bool> seen(lines, false);
    std::uint32_t p = 0;
    for (std::size_t k = 0; k < lines; ++k) {
      ASSERT_LT(p, lines);
      EXPECT_FALSE(seen[p]) << "line " << p << " met twice in " << lines;
      seen[p] = true;
      p = next[p];
    }
    EXPECT_EQ(p, 0u) << "the walk over " << lines << " lines does not close after visiting them all";
  }
}

TEST(CacheSweep, TheSameSeedGivesTheSameWalkAndAnotherSeedAnother) {
  EXPECT_EQ(random_cycle(4096, 3), random_cycle(4096, 3));
  EXPECT_NE(random_cycle(4096, 3), random_cycle(4096, 4));
}

TEST(CacheSweep, EachSizeGetsARateAndALatency) {
  const std::vector<CacheLevel> levels = measure_cache_levels({64u << 10, 256u << 10}, 0.01);
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0].working_set, 64u << 10);
  EXPECT_EQ(levels[1].working_set, 256u << 10);
  for (const CacheLevel& l : levels) {
    EXPECT_TRUE(std::isfinite(l.update) && l.update > 0.0);
    // A load takes more than a picosecond and, for a set this small, less than a microsecond.
    EXPECT_GT(l.random_load, 1e-12);
    EXPECT_LT(l.random_load, 1e-6);
    EXPECT_NE(l.line().find("working_set_kib="), std::string::npos);
  }
}

}  // namespace
}  // namespace hilldem
