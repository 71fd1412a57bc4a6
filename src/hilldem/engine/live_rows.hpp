// LiveRows: the ball-ball rows the force pass visits, and their records.
//
// Why: most neighbour pairs of a settled bed are far from touching, and the neighbour list keeps
// them for many steps. The live rows are, per ball and in row order, the rows that were contacts,
// rows of other models than hill, or hill neighbour pairs within proximity + 2 s when the list was
// made (s: the slack [m]). While no ball has moved more than s since, a pair not on the list is still
// beyond proximity, so new contacts come only from live rows and the pass visits only these. The
// list changes no result, only how much the row loop visits; neither does s.
//
// On the steps nobody looks at, the live hill rows' history (n̂_c, F^h_s, M) and what the row loop
// reads of a row are kept in one cache line a row (LiveRecord), in live-row order; the columns get
// the history back (sync_records) before anything else reads them.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/ball_kin.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

// What the row loop and the lanes read and write of a live row. n̂_c, F^h_s and M are those of hill
// rows only (other models keep theirs in the columns, and their `exists` is read there too).
struct alignas(64) LiveRecord {
  std::uint32_t row = 0, b = 0;  // the row; its second ball
  std::uint32_t hill_set = 0;    // the row's hill parameter set (HillParamSets::row_sets)
  ImageCode image = kNoImage;
  std::uint8_t exists = 0;
  ModelKind model = ModelKind::Hill;
  Moisture moisture = Moisture::Dry;
  Vec3 normal;  // n̂_c of the last step
  Vec3 shear;   // F^h_s [N]
};
static_assert(sizeof(LiveRecord) == 64);

class LiveRows {
 public:
  // Make the list from the balls' records (first_rows: the neighbour list's per-ball row ranges,
  // NeighbourList::first_rows), for `n` balls. The slack follows how long the last list lasted.
  void refresh(ContactStore& contacts, const BallKin* kin, const std::uint32_t* first_rows, std::size_t n,
               double proximity, const PeriodicBox& box, double skin);
  // The list is gone (new rows: remade before the next pass that visits it).
  void invalidate() { ready_ = false; }
  // Whether the list was made for this many rows and this proximity [m].
  bool made_for(std::size_t rows, double proximity) const { return rows_of_ == rows && proximity_ == proximity; }
  // Whether the list still holds every pair that may touch: no ball moved more than the slack since
  // (as measured for this pass).
  bool current() const { return ready_ && travel_known_ && travel_ <= slack_; }
  // This force pass visits the live rows (not while every row goes through force_row).
  void set_visited(bool visited) { visited_ = visited; }
  bool visited() const { return visited_; }
  // Per ball a, its live rows rows()[first()[a] .. first()[a + 1]) (valid while covers(n)).
  const std::uint32_t* first() const { return first_.data(); }
  const std::uint32_t* rows() const { return rows_.data(); }
  bool covers(std::size_t n) const { return ready_ && first_.size() == n + 1; }

  // The balls' travel since the list [m]. has_positions: the positions then are at hand, positions().
  bool has_positions(std::size_t n) const { return ready_ && position_at_.size() == n; }
  const Vec3* positions() const { return position_at_.data(); }
  // Whether the travel bound carried from step to step, grown by four more steps like the last,
  // stays within the slack (the record motion then need not measure it ball by ball).
  bool bound_holds() const { return bound_valid_ && travel_ + 4.0 * growth_ <= slack_; }
  // After a record motion whose largest step was `growth` [m]: list: the list has positions; measured:
  // worst2 [m²] is the largest squared travel, measured ball by ball; bounded: the bound grows instead.
  void after_motion(bool list, bool measured, bool bounded, double worst2, double growth) {
    if (measured) travel_ = std::sqrt(worst2);  // (exact)
    else if (bounded) travel_ += growth;
    growth_ = growth;
    bound_valid_ = list;
    travel_known_ = list;
  }
  // The largest squared travel worst2 [m²], measured over the positions (when `list`).
  void measured(bool list, double worst2) {
    travel_ = std::sqrt(worst2);
    travel_known_ = list;
    bound_valid_ = list;
  }
  void end_pass_measure() { travel_known_ = false; }  // (measured again before the next pass)
  void count_pass() { ++passes_; }

  // The records (records_ready: they hold the live hill rows' history).
  bool records_ready() const { return records_ready_; }
  LiveRecord* records() { return records_.data(); }
  const LiveRecord* records() const { return records_.data(); }
  void build_records(const ContactStore& contacts, const std::uint32_t* row_hill_set, std::size_t n);
  // Record k from the columns (row_hill_set: each row's hill parameter set).
  void load_record(std::size_t k, const ContactStore& contacts, const std::uint32_t* row_hill_set) {
    LiveRecord& r = records_[k];
    const std::size_t c = r.row;
    r.b = contacts.key[c].b;
    r.hill_set = row_hill_set[c];
    r.image = contacts.image[c];
    r.exists = contacts.exists[c];
    r.model = contacts.model[c];
    r.moisture = contacts.moisture[c];
    r.normal = contacts.normal[c];
    r.shear = contacts.shear_state[c];
  }
  // The history back into the columns; the records dropped.
  void sync_records(ContactStore& contacts);
  void count_record_pass() { record_passes_ += records_ready_; }

  std::int64_t refreshes() const { return refreshes_; }
  std::int64_t record_passes() const { return record_passes_; }

 private:
  std::vector<std::uint32_t> rows_;
  std::vector<std::uint32_t> first_;
  std::vector<Vec3> position_at_;  // [m] the balls' positions when the list was made
  double slack_ = 0.0;             // s [m]
  std::size_t rows_of_ = 0;        // rows when the list was made
  double proximity_ = 0.0;         // [m] the proximity then
  std::int64_t passes_ = 0;        // force passes since
  std::int64_t refreshes_ = 0;
  bool ready_ = false;
  bool visited_ = false;
  // [m] the largest travel of a ball since the list, or a bound on it carried from step to step
  // (valid while bound_valid_): exact where it was last measured ball by ball, then grown by each
  // record motion by its largest |V| Δt (growth_, the last step's).
  double travel_ = 0.0, growth_ = 0.0;
  bool bound_valid_ = false;
  bool travel_known_ = false;  // measured for this pass
  std::vector<LiveRecord> records_;
  bool records_ready_ = false;
  std::int64_t record_passes_ = 0;
};

}  // namespace hilldem
