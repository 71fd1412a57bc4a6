// CellGrid: broad phase. Bins ball centres into cubic cells at least as wide as the largest
// interaction distance and returns every pair whose gap is within `proximity` [m]. Cost is linear in
// the number of balls (a counting sort into cells, then the 27-cell stencil).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

using BallPair = std::pair<std::uint32_t, std::uint32_t>;  // (i, j) ball indices, i < j

// Pairs with gap = |x_j − x_i| − R_i − R_j ≤ proximity, sorted by (i, j).
std::vector<BallPair> find_ball_pairs(const std::vector<Vec3>& position, const std::vector<double>& radius,
                                      double proximity);

// Reference N² search used by tests to check find_ball_pairs.
std::vector<BallPair> find_ball_pairs_brute_force(const std::vector<Vec3>& position,
                                                  const std::vector<double>& radius, double proximity);

}  // namespace hilldem
