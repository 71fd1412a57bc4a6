#include "hilldem/engine/live_rows.hpp"

#include <algorithm>

#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

void LiveRows::refresh(ContactStore& contacts, const BallKin* kin, const std::uint32_t* first_rows, std::size_t n,
                       double proximity, const PeriodicBox& box, double skin) {
  // The slack s: a list that lasted fewer than kLiveShort passes doubles it (fast balls: fewer
  // remakes, more pairs checked), one that lasted more than kLiveLong halves it (slow balls), between
  // a thousandth and a quarter of the skin.
  constexpr std::int64_t kLiveShort = 25, kLiveLong = 400;
  if (records_ready_) sync_records(contacts);  // (made for the old list)
  const std::int64_t lasted = passes_;
  if (!(slack_ > 0.0) || slack_ > 0.25 * skin) slack_ = 0.002 * skin;
  else if (ready_ && lasted < kLiveShort) slack_ = std::min(2.0 * slack_, 0.25 * skin);
  else if (ready_ && lasted > kLiveLong) slack_ = std::max(0.5 * slack_, 0.001 * skin);
  passes_ = 0;
  const double slack = slack_;
  // Each ball-ball row is live if it is a contact, not a hill row, or a hill neighbour pair within
  // proximity + 2 s (with a margin of 1e-9 of the radii, far above the rounding of the distances and
  // of the travel). A live pair that is no contact costs its record, and a new contact no more than
  // its own row.
  auto is_live = [&](std::size_t c) -> std::uint8_t {
    if (contacts.exists[c] || contacts.model[c] != ModelKind::Hill) return 1;
    const ContactKey& k = contacts.key[c];
    Vec3 xb = kin[k.b].position;
    if (contacts.image[c] != kNoImage) xb += image_shift(contacts.image[c], box);
    const double radii = kin[k.a].radius + kin[k.b].radius;
    const double reach = (radii + proximity + 2.0 * slack) * (1.0 + 1e-9);
    return norm2(xb - kin[k.a].position) > reach * reach ? 0 : 1;
  };
  std::vector<std::uint8_t> live(contacts.size(), 0);
  first_.assign(n + 1, 0);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t a = 0; a < n; ++a) {
    std::uint32_t count = 0;
    for (std::size_t c = first_rows[a]; c < first_rows[a + 1]; ++c) count += live[c] = is_live(c);
    first_[a + 1] = count;
  }
  for (std::size_t a = 0; a < n; ++a) first_[a + 1] += first_[a];
  rows_.resize(first_[n]);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t a = 0; a < n; ++a) {
    std::uint32_t l = first_[a];
    for (std::size_t c = first_rows[a]; c < first_rows[a + 1]; ++c)
      if (live[c]) rows_[l++] = static_cast<std::uint32_t>(c);
  }
  position_at_.resize(n);
  for (std::size_t i = 0; i < n; ++i) position_at_[i] = kin[i].position;
  travel_ = 0.0;
  bound_valid_ = true;
  proximity_ = proximity;
  rows_of_ = contacts.size();
  ready_ = true;
  ++refreshes_;
}

void LiveRows::build_records(const ContactStore& contacts, const std::uint32_t* row_hill_set, std::size_t n) {
  records_.resize(rows_.size());
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t k = first_[a]; k < first_[a + 1]; ++k) {
      records_[k].row = rows_[k];
      load_record(k, contacts, row_hill_set);
    }
  records_ready_ = true;
}

void LiveRows::sync_records(ContactStore& contacts) {
  const std::size_t live = records_.size();
#pragma omp parallel for schedule(static) if (live > kParallelMin)
  for (std::size_t k = 0; k < live; ++k) {
    const LiveRecord& r = records_[k];
    if (r.model != ModelKind::Hill) continue;  // (other models keep theirs in the columns)
    contacts.normal[r.row] = r.normal, contacts.shear_state[r.row] = r.shear;
    contacts.moisture[r.row] = r.moisture;
  }
  records_ready_ = false;
}

}  // namespace hilldem
