// CellGrid: broad phase. Bins ball centres into cubic cells at least as wide as the largest
// interaction distance and returns every pair whose gap is within `reach` [m]. Cost is linear in
// the number of balls (a counting sort into cells, then the 27-cell stencil). Periodic directions
// wrap around; each pair is then found once, with the image of ball j that is closest to ball i.
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

// A box with optional periodic directions. Positions are expected inside [lo, hi) in periodic
// directions (Simulation wraps them at every neighbour-list rebuild).
struct PeriodicBox {
  bool periodic[3] = {false, false, false};
  Vec3 lo, hi;  // [m]
  bool any() const { return periodic[0] || periodic[1] || periodic[2]; }
  Vec3 length() const { return hi - lo; }
  // x moved into [lo, hi) along the periodic directions (the neighbour list's wrap at a rebuild).
  Vec3 wrapped(Vec3 x) const {
    const Vec3 l = length();
    for (int d = 0; d < 3; ++d)
      if (periodic[d]) {
        x[d] = lo[d] + std::fmod(x[d] - lo[d], l[d]);
        if (x[d] < lo[d]) x[d] += l[d];
        if (x[d] >= hi[d]) x[d] -= l[d];
      }
    return x;
  }
};

// Image of ball j relative to ball i: shifts (−1, 0, +1) per direction packed as
// (sx+1) + 3(sy+1) + 9(sz+1); kNoImage = 13 is no shift.
using ImageCode = std::uint8_t;
inline constexpr ImageCode kNoImage = 13;
inline Vec3 image_shift(ImageCode code, const PeriodicBox& box) {
  const Vec3 l = box.length();
  return {(code % 3 - 1) * l.x, (code / 3 % 3 - 1) * l.y, (code / 9 - 1) * l.z};
}
// The image of x_j closest to x_i.
ImageCode nearest_image(const Vec3& xi, const Vec3& xj, const PeriodicBox& box);

struct PairCandidate {
  std::uint32_t i, j;  // i < j
  ImageCode image;
  friend bool operator<(const PairCandidate& a, const PairCandidate& b) {
    return a.i != b.i ? a.i < b.i : a.j < b.j;
  }
};

// Pairs with gap = |x_j + shift − x_i| − R_i − R_j ≤ reach, sorted by (i, j). Throws InputError if
// a periodic length is shorter than three interaction lengths.
std::vector<PairCandidate> find_pair_candidates(const std::vector<Vec3>& position, const std::vector<double>& radius,
                                                double reach, const PeriodicBox& box);

using BallPair = std::pair<std::uint32_t, std::uint32_t>;  // (i, j) ball indices, i < j

// Non-periodic convenience form.
std::vector<BallPair> find_ball_pairs(const std::vector<Vec3>& position, const std::vector<double>& radius,
                                      double proximity);

// Reference N² search used by tests to check the cell grid.
std::vector<BallPair> find_ball_pairs_brute_force(const std::vector<Vec3>& position,
                                                  const std::vector<double>& radius, double proximity);

}  // namespace hilldem
