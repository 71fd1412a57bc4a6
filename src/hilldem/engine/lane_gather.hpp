// The gather of a batch's lanes: what the law reads of a lane's two balls (from their records) and
// of its row (from its live record or the row columns), when the batch runs.
#pragma once

#include <cstdint>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/ball_kin.hpp"
#include "hilldem/engine/contact_batch.hpp"
#include "hilldem/engine/live_rows.hpp"
#include "hilldem/models/hill.hpp"

namespace hilldem {

// Where the lanes' inputs come from.
struct LaneSources {
  const BallKin* kin = nullptr;             // the balls' records (engine/ball_records.hpp)
  const PeriodicBox* box = nullptr;         // for the lanes across a periodic boundary
  const ContactStore* contacts = nullptr;   // the rows' history and linear parameters
  const LiveRecord* records = nullptr;      // the live rows' records (a hill lane with a slot)
  const HillParams* sets = nullptr;         // the hill parameter sets (engine/hill_param_sets.hpp)
  const std::uint32_t* row_sets = nullptr;  // per row, its set
};

// Every input field of the batch's lanes (kDx..kWet) from their balls and rows.
void gather_lanes(ContactBatch& batch, bool hill, const LaneSources& src);

// x2 − x1 of a ball-ball row [m] from the balls' records, ball 2 shifted by the row's periodic image
// (x2 + shift first, as force_row and geometry() do).
template <class Kin>
HILLDEM_INLINE Vec3 separation(const Kin& ka, const Kin& kb, ImageCode image, const PeriodicBox& box) {
  Vec3 x2 = kb.position;
  if (image != kNoImage) x2 += image_shift(image, box);
  return x2 - ka.position;
}
// Whether a ball-ball pair is within reach (gap ≤ proximity [m]): a neighbour pair becomes a contact
// there (as force_row). Not beyond it, so that a non-finite separation goes to force_row, which
// reports it.
template <class Kin>
HILLDEM_INLINE bool pair_within_reach(const Kin& ka, const Kin& kb, ImageCode image, const PeriodicBox& box,
                                      double proximity) {
  const double reach = ka.radius + kb.radius + proximity;
  return !(norm2(separation(ka, kb, image, box)) > reach * reach);
}

}  // namespace hilldem
