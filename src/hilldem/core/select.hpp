// Branch-free selection between two doubles.
//
// Why: GCC turns `c ? a : b` between doubles into a branch, and where c follows the data in no
// predictable order (the sign of a velocity component, whether a neighbour pair is a contact) about
// every other such branch is mispredicted. A bit-mask select gives exactly a or b, whatever the other
// holds (an infinity or a NaN is not touched by arithmetic), so results do not change.
#pragma once

#include <bit>
#include <cstdint>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

// a if c, else b (bit for bit).
HILLDEM_INLINE double select_bits(bool c, double a, double b) {
  const std::uint64_t take_a = std::uint64_t{0} - static_cast<std::uint64_t>(c);
  return std::bit_cast<double>((std::bit_cast<std::uint64_t>(a) & take_a) | (std::bit_cast<std::uint64_t>(b) & ~take_a));
}

}  // namespace hilldem
