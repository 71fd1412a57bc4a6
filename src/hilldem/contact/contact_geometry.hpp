// A contact's geometry at given positions (spec §1.1): the normal, the gap and the contact point.
#pragma once

#include <cstddef>

#include "hilldem/bodies/wall_store.hpp"
#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"

namespace hilldem {

struct ContactGeometry {
  Vec3 normal;        // n̂_c, piece 1 -> piece 2
  double gap = 0.0;   // g_c [m]
  Vec3 point;         // x_c [m]
  bool valid = true;  // false: a ball beyond a cylinder's end (no contact possible)
};

// Row c's geometry with piece 1 at x1 [m] of radius r1 [m] and, for a ball-ball row, piece 2 at x2
// (before its periodic image shift) of radius r2; a wall row's wall from `walls`. Coincident centres
// keep the row's last normal.
ContactGeometry contact_geometry(const ContactStore& contacts, std::size_t c, const Vec3& x1, double r1,
                                 const Vec3& x2, double r2, const WallStore& walls, const PeriodicBox& box);

}  // namespace hilldem
