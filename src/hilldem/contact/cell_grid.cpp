#include "hilldem/contact/cell_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {
bool within(const Vec3& xi, const Vec3& xj, double ri, double rj, double reach) {
  const double r = ri + rj + reach;
  return norm2(xj - xi) <= r * r;
}
}  // namespace

ImageCode nearest_image(const Vec3& xi, const Vec3& xj, const PeriodicBox& box) {
  int code = kNoImage;
  const Vec3 l = box.length();
  const int weight[3] = {1, 3, 9};
  for (int d = 0; d < 3; ++d) {
    if (!box.periodic[d]) continue;
    const double delta = xj[d] - xi[d];
    if (delta > 0.5 * l[d]) code -= weight[d];
    else if (delta < -0.5 * l[d]) code += weight[d];
  }
  return static_cast<ImageCode>(code);
}

std::vector<BallPair> find_ball_pairs_brute_force(const std::vector<Vec3>& position,
                                                  const std::vector<double>& radius, double proximity) {
  std::vector<BallPair> out;
  for (std::size_t i = 0; i < position.size(); ++i)
    for (std::size_t j = i + 1; j < position.size(); ++j)
      if (within(position[i], position[j], radius[i], radius[j], proximity)) out.emplace_back(i, j);
  return out;
}

std::vector<BallPair> find_ball_pairs(const std::vector<Vec3>& position, const std::vector<double>& radius,
                                      double proximity) {
  std::vector<BallPair> out;
  for (const PairCandidate& p : find_pair_candidates(position, radius, proximity, PeriodicBox{}))
    out.emplace_back(p.i, p.j);
  return out;
}

std::vector<PairCandidate> find_pair_candidates(const std::vector<Vec3>& position, const std::vector<double>& radius,
                                                double reach, const PeriodicBox& box) {
  const std::size_t n = position.size();
  std::vector<PairCandidate> out;
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
  for (int d = 0; d < 3; ++d)
    if (box.periodic[d]) {
      lo[d] = box.lo[d];
      hi[d] = box.hi[d];
    }
  // Any interacting pair is at most 2 rmax + reach apart: one cell of that width suffices.
  const double interaction = std::max(2.0 * rmax + reach, 1e-12);
  double cell = interaction;
  long dims[3];
  double width[3];
  // Cell counts are computed in double and capped before any integer conversion: a ball very far
  // away must neither overflow the count nor blow up memory.
  auto size_dims = [&] {
    double total = 1.0;
    for (int d = 0; d < 3; ++d) {
      // (NaN, from a non-finite extent or reach, counts as no extent: a cast of NaN to an integer is
      // undefined; callers reject non-finite positions with a clear message, Simulation::rebuild.)
      const double ratio = (hi[d] - lo[d]) / cell;
      const double cells = ratio >= 0.0 ? std::min(ratio, 1e15) : 0.0;
      if (box.periodic[d]) {
        // Whole number of cells across the period, each at least `cell` wide.
        dims[d] = std::max(1L, static_cast<long>(std::floor(cells)));
        width[d] = (hi[d] - lo[d]) / static_cast<double>(dims[d]);
      } else {
        dims[d] = std::max(1L, static_cast<long>(cells) + 1);
        width[d] = cell;
      }
      total *= static_cast<double>(dims[d]);
    }
    return total;
  };
  // Keep the grid at most ~8 cells per ball.
  while (size_dims() > static_cast<double>(8 * n + 64)) cell *= 2.0;
  for (int d = 0; d < 3; ++d)
    if (box.periodic[d] && dims[d] < 3)
      throw InputError("periodic box too small in " + std::string(1, static_cast<char>('x' + d)) +
                       ": its length must be at least 3 interaction lengths (2 R_max + proximity + skin = " +
                       std::to_string(interaction) + " m)");
  const long ncell = dims[0] * dims[1] * dims[2];

  std::vector<long> cell_of(n);
  std::vector<std::uint32_t> start(ncell + 1, 0), order(n);
  auto coord = [&](const Vec3& x, int d) {
    const double c = std::clamp((x[d] - lo[d]) / width[d], 0.0, static_cast<double>(dims[d] - 1));
    return static_cast<long>(c);
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
  const Vec3 period = box.length();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& x = position[i];
    const long c0[3] = {coord(x, 0), coord(x, 1), coord(x, 2)};
    long from[3], to[3];
    for (int d = 0; d < 3; ++d) {
      from[d] = box.periodic[d] ? c0[d] - 1 : std::max(0L, c0[d] - 1);
      to[d] = box.periodic[d] ? c0[d] + 1 : std::min(dims[d] - 1, c0[d] + 1);
    }
    for (long z = from[2]; z <= to[2]; ++z)
      for (long y = from[1]; y <= to[1]; ++y)
        for (long xx = from[0]; xx <= to[0]; ++xx) {
          long cc[3] = {xx, y, z};
          int shift[3] = {0, 0, 0};
          for (int d = 0; d < 3; ++d) {
            if (cc[d] < 0) cc[d] += dims[d], shift[d] = -1;
            else if (cc[d] >= dims[d]) cc[d] -= dims[d], shift[d] = 1;
          }
          const Vec3 offset{shift[0] * period.x, shift[1] * period.y, shift[2] * period.z};
          const ImageCode code = static_cast<ImageCode>((shift[0] + 1) + 3 * (shift[1] + 1) + 9 * (shift[2] + 1));
          const long c = (cc[2] * dims[1] + cc[1]) * dims[0] + cc[0];
          for (std::uint32_t k = start[c]; k < start[c + 1]; ++k) {
            const std::uint32_t j = order[k];
            if (j > i && within(x, position[j] + offset, radius[i], radius[j], reach))
              out.push_back({static_cast<std::uint32_t>(i), j, code});
          }
        }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hilldem
