#include "hilldem/contact/cell_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hilldem {

namespace {
bool within(const std::vector<Vec3>& x, const std::vector<double>& r, std::size_t i, std::size_t j,
            double proximity) {
  const double reach = r[i] + r[j] + proximity;
  return norm2(x[j] - x[i]) <= reach * reach;
}
}  // namespace

std::vector<BallPair> find_ball_pairs_brute_force(const std::vector<Vec3>& position,
                                                  const std::vector<double>& radius, double proximity) {
  std::vector<BallPair> out;
  for (std::size_t i = 0; i < position.size(); ++i)
    for (std::size_t j = i + 1; j < position.size(); ++j)
      if (within(position, radius, i, j, proximity)) out.emplace_back(i, j);
  return out;
}

std::vector<BallPair> find_ball_pairs(const std::vector<Vec3>& position, const std::vector<double>& radius,
                                      double proximity) {
  const std::size_t n = position.size();
  std::vector<BallPair> out;
  if (n < 2) return out;
  Vec3 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
          std::numeric_limits<double>::max()};
  Vec3 hi = -lo;
  double rmax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], position[i][d]);
      hi[d] = std::max(hi[d], position[i][d]);
    }
    rmax = std::max(rmax, radius[i]);
  }
  // Any interacting pair is at most 2 rmax + proximity apart: one cell of that width suffices.
  double cell = std::max(2.0 * rmax + proximity, 1e-12);
  long dims[3];
  auto size_dims = [&] {
    long total = 1;
    for (int d = 0; d < 3; ++d) {
      dims[d] = std::max(1L, static_cast<long>((hi[d] - lo[d]) / cell) + 1);
      total *= dims[d];
    }
    return total;
  };
  // Keep the grid at most ~8 cells per ball: a ball far away must not blow up memory.
  while (size_dims() > static_cast<long>(8 * n + 64)) cell *= 2.0;
  const long ncell = dims[0] * dims[1] * dims[2];

  std::vector<long> cell_of(n);
  std::vector<std::uint32_t> start(ncell + 1, 0), order(n);
  auto coord = [&](const Vec3& x, int d) {
    return std::min(dims[d] - 1, static_cast<long>((x[d] - lo[d]) / cell));
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& x = position[i];
    cell_of[i] = (coord(x, 2) * dims[1] + coord(x, 1)) * dims[0] + coord(x, 0);
    ++start[cell_of[i] + 1];
  }
  for (long c = 0; c < ncell; ++c) start[c + 1] += start[c];
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& x = position[i];
    const long cx = coord(x, 0), cy = coord(x, 1), cz = coord(x, 2);
    for (long z = std::max(0L, cz - 1); z <= std::min(dims[2] - 1, cz + 1); ++z)
      for (long y = std::max(0L, cy - 1); y <= std::min(dims[1] - 1, cy + 1); ++y)
        for (long xx = std::max(0L, cx - 1); xx <= std::min(dims[0] - 1, cx + 1); ++xx) {
          const long c = (z * dims[1] + y) * dims[0] + xx;
          for (std::uint32_t k = start[c]; k < start[c + 1]; ++k) {
            const std::uint32_t j = order[k];
            if (j > i && within(position, radius, i, j, proximity)) out.emplace_back(i, j);
          }
        }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hilldem
