// ForcePass::force_block: the ball-ball rows of a block of balls, gathered into the batches of their
// models, and every row's share summed into both balls in the pass's order (force_pass.hpp).
#include <algorithm>

#include "hilldem/engine/force_pass.hpp"
#include "hilldem/engine/lane_gather.hpp"
#include "hilldem/engine/model_dispatch.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {

#if defined(__AVX512F__)
using lanes::transpose8;
using lanes::widen8;
#endif

// Prefetch distances in rows (the pass runs down the rows). The row columns run downwards, and the
// hardware prefetcher follows descending streams poorly, so the pair loop would wait on the first
// loads of the history, parameter and flag columns: the history and parameters are asked for 32
// rows ahead, the byte columns and the keys 128 rows ahead. Only for more than 2^17 rows: below, the
// rows sit in the outer caches, and the prefetches' own work (≈ 30 instructions a row) costs more
// than they hide (the distances and the threshold: docs/performance.md).
namespace {
constexpr std::size_t kPrefetchRows = 16;
constexpr std::size_t kPrefetchColumns = 32;
constexpr std::size_t kPrefetchFlags = 128;
constexpr std::size_t kPrefetchBalls = 8;
constexpr std::size_t kPrefetchRecords = 64;
constexpr std::size_t kFarRows = std::size_t{1} << 17;
}  // namespace

// One force_block call's state, shared by its parts.
struct ForcePass::Block {
  ContactStore& contacts;
  const BallKin* kin;
  const ContactKey* keys;
  // Each ball's force and moment sums in one line, each a vector with a +0.0 fourth lane
  // (motion::ContactSums): a row's share into a ball is one vector operation per sum, not three
  // scalar ones. The same additions component by component, so the same bits.
  motion::ContactSums* sums;
  StiffnessSums& stiffness;
  LiveRows& live_rows;
  const std::uint32_t* row_sets;
  LaneSources sources;
  const PeriodicBox& box;
  double dt, proximity;
  bool want_stiffness, reported;
  bool far;      // more than kFarRows rows: prefetch
  bool live;     // the rows visited: the live rows, or all (through force_row)
  bool records;  // the live rows through their records
  std::size_t range_end;
  ContactBatch& hill;
  ContactBatch& linear;
  std::vector<CrossShare>& crossing;
  std::size_t& bad_row;
  std::int64_t& batched;
};

// A row's shares into its two balls: −F_c and moment1 into ball a, F_c and moment2 into ball b
// (b beyond this thread's range: into the crossing list), and the stiffness terms.
HILLDEM_INLINE void ForcePass::add_to_balls(Block& blk, std::size_t a, std::size_t b, const Vec3& force,
                                            const Vec3& moment1, const Vec3& moment2, double k_tran, double k_shear,
                                            double gap) {
  motion::ContactSums* __restrict sums = blk.sums;
  const motion::V4 f = motion::load(force);
  sums[a].force -= f;
  sums[a].moment += motion::load(moment1);
  if (blk.want_stiffness)
    add_stiffness(k_tran, k_shear, blk.kin[a].radius, gap, blk.stiffness.tran[a], blk.stiffness.rot[a]);
  if (b < blk.range_end) {
    sums[b].force += f;
    sums[b].moment += motion::load(moment2);
    if (blk.want_stiffness)
      add_stiffness(k_tran, k_shear, blk.kin[b].radius, gap, blk.stiffness.tran[b], blk.stiffness.rot[b]);
  } else {
    blk.crossing.push_back({static_cast<std::uint32_t>(b), force, moment2, k_tran, k_shear, gap});
  }
}

// Row c's share (share.force is −F_c: x − (−F) is x + F bit for bit).
HILLDEM_INLINE void ForcePass::add_share(Block& blk, std::size_t c, const RowShare& s) {
  if (!s.ok) blk.bad_row = std::min(blk.bad_row, c);
  add_to_balls(blk, blk.keys[c].a, blk.keys[c].b, -s.force, s.moment, s.moment2, s.k_tran, s.k_shear, s.gap);
}

// One lane's results into its row (or live record) and its balls' sums, in lane order.
HILLDEM_INLINE void ForcePass::scatter_lane(Block& blk, ContactBatch& batch, std::size_t lane) {
  using F = ContactBatch;
  const std::size_t c = batch.row(lane);
  const std::uint32_t slot = &batch == &blk.hill ? batch.slot(lane) : ContactBatch::kNoSlot;
  if (batch.col(F::kQuick)[lane] == 0.0) {  // deleted, or a non-finite force: the general way
    RowShare share;
    store_row(blk.contacts, blk.proximity, c, lane_outcome(blk.contacts, batch, lane, /*wall_row=*/false),
              blk.want_stiffness, blk.reported, share);
    add_share(blk, c, share);
    if (slot != ContactBatch::kNoSlot) blk.live_rows.load_record(slot, blk.contacts, blk.row_sets);  // (store_row wrote the columns)
    return;
  }
  // The shares from the lanes; a live record's history into the record.
  if (slot != ContactBatch::kNoSlot) {
    LiveRecord& h = blk.live_rows.records()[slot];
    h.shear = batch.get3(F::kShx, lane);
    h.normal = batch.get3(F::kNx, lane);
    if (batch.col(F::kRuptured)[lane] != 0.0) h.moisture = Moisture::Ruptured;
    store_kept_lane(blk.contacts, c, batch, lane, blk.want_stiffness, blk.reported, false);
  } else {
    store_kept_lane(blk.contacts, c, batch, lane, blk.want_stiffness, blk.reported);
  }
  double k_tran = 0.0, k_shear = 0.0, gap = 0.0;
  if (blk.want_stiffness)
    k_tran = batch.col(F::kKtran)[lane], k_shear = batch.col(F::kKshear)[lane], gap = batch.col(F::kGap)[lane];
  add_to_balls(blk, batch.ball1(lane), batch.ball2(lane), batch.get3(F::kFx, lane), batch.get3(F::kMax, lane),
               batch.get3(F::kMbx, lane), k_tran, k_shear, gap);
}

// Eight hill lanes at a time when all eight take the common way with live records and nothing more
// is asked of them (kept, finite, no rupture, both balls in this thread's range, no reports, no
// stiffness): their shares transposed in registers into one 64-byte vector per ball, each ball's
// sums (one line, motion::ContactSums) added to in one operation, and n̂_c and F^h_s stored into
// each record at once. The same additions in the same lane order (x − F is x + (−F) bit for bit,
// and a fourth lane +0.0 stays +0.0), so the same bits as scatter_lane. Returns the lanes done.
HILLDEM_INLINE std::size_t ForcePass::scatter_simple_hill_lanes(Block& blk, ContactBatch& batch) {
  std::size_t lane = 0;
#if defined(__AVX512F__)
  using F = ContactBatch;
  if (!(blk.records && &batch == &blk.hill && !blk.reported && !blk.want_stiffness)) return 0;
  const double* quick = batch.col(F::kQuick);
  const double* ruptured = batch.col(F::kRuptured);
  motion::ContactSums* __restrict sums = blk.sums;
  LiveRecord* records = blk.live_rows.records();
  const __m512d zero = _mm512_setzero_pd();
  const __m512i no_slot = _mm512_set1_epi64(ContactBatch::kNoSlot);
  const __m512i end = _mm512_set1_epi64(static_cast<long long>(blk.range_end));
  for (; lane + 8 <= batch.size(); lane += 8) {
    const __mmask8 simple = _mm512_cmp_pd_mask(_mm512_loadu_pd(quick + lane), zero, _CMP_NEQ_UQ) &
                            _mm512_cmp_pd_mask(_mm512_loadu_pd(ruptured + lane), zero, _CMP_EQ_OQ) &
                            _mm512_cmp_epi64_mask(widen8(batch.slots() + lane), no_slot, _MM_CMPINT_NE) &
                            _mm512_cmp_epi64_mask(widen8(batch.balls2() + lane), end, _MM_CMPINT_LT);
    if (simple != 0xFF) {
      for (std::size_t k = 0; k < 8; ++k) scatter_lane(blk, batch, lane + k);
      continue;
    }
    auto col = [&](ContactBatch::Field f) { return _mm512_load_pd(batch.col(f) + lane); };
    const __m512d fx = col(F::kFx), fy = col(F::kFy), fz = col(F::kFz);
    __m512d c[8], share_a[8], share_b[8], history[8];
    // Ball 1: [−F_c, +0.0, moment 1, +0.0]; ball 2: [F_c, +0.0, moment 2, +0.0].
    c[0] = _mm512_sub_pd(zero, fx), c[1] = _mm512_sub_pd(zero, fy), c[2] = _mm512_sub_pd(zero, fz);
    c[3] = zero, c[4] = col(F::kMax), c[5] = col(F::kMay), c[6] = col(F::kMaz), c[7] = zero;
    transpose8(c, share_a);
    c[0] = fx, c[1] = fy, c[2] = fz, c[4] = col(F::kMbx), c[5] = col(F::kMby), c[6] = col(F::kMbz);
    transpose8(c, share_b);
    // The record's doubles 2-7: n̂_c, then F^h_s (LiveRecord).
    c[0] = zero, c[1] = zero, c[2] = col(F::kNx), c[3] = col(F::kNy), c[4] = col(F::kNz);
    c[5] = col(F::kShx), c[6] = col(F::kShy), c[7] = col(F::kShz);
    transpose8(c, history);
    for (std::size_t k = 0; k < 8; ++k) {
      double* a = reinterpret_cast<double*>(sums + batch.ball1(lane + k));
      _mm512_store_pd(a, _mm512_add_pd(_mm512_load_pd(a), share_a[k]));
      double* b = reinterpret_cast<double*>(sums + batch.ball2(lane + k));
      _mm512_store_pd(b, _mm512_add_pd(_mm512_load_pd(b), share_b[k]));
      _mm512_mask_store_pd(reinterpret_cast<double*>(&records[batch.slot(lane + k)]), 0xFC, history[k]);
    }
  }
#else
  (void)blk, (void)batch;
#endif
  return lane;
}

// The law of the gathered lanes, and their results into the rows and the balls.
void ForcePass::flush(Block& blk, ContactBatch& batch) {
  const bool hill = &batch == &blk.hill;
  gather_lanes(batch, hill, blk.sources);
  const LaneStep step{blk.dt, blk.want_stiffness, blk.proximity};
  if (hill) run_hill_lanes(batch, step);
  else run_linear_lanes(batch, step);
  blk.batched += static_cast<std::int64_t>(batch.size());
  for (std::size_t lane = scatter_simple_hill_lanes(blk, batch); lane < batch.size(); ++lane)
    scatter_lane(blk, batch, lane);
  batch.clear();
}

// The record, force sums and row range of the ball some places down: the pass meets each ball first
// as the `a` of its rows, a descending stream.
HILLDEM_INLINE void ForcePass::prefetch_ball(const Block& blk, std::size_t a) const {
  if (!blk.far || a < kPrefetchBalls) return;
  const std::size_t ahead = a - kPrefetchBalls;
  const char* record = reinterpret_cast<const char*>(blk.kin + ahead);
  __builtin_prefetch(record);
  __builtin_prefetch(record + 64);
  if (blk.records) {
    __builtin_prefetch(blk.sums + ahead);  // (to be read: see block_records)
  } else {
    __builtin_prefetch(blk.sums + ahead, 1);
  }
  // Its row range: of its live rows, or of all its rows.
  __builtin_prefetch(blk.live ? blk.live_rows.first() + ahead : w_.neighbours->first_rows().data() + ahead);
}

// Ball a's rows from the last down: k1 − 1 down to k0 of the row sequence row_at, its live rows or
// all of its rows.
template <class RowAt>
HILLDEM_INLINE void ForcePass::block_rows(Block& blk, std::size_t a, std::size_t k1, std::size_t k0, RowAt row_at) {
  ContactStore& contacts = blk.contacts;
  const ContactKey* keys = blk.keys;
  ContactBatch& hill = blk.hill;
  ContactBatch& linear = blk.linear;
  const BallKin& ka = blk.kin[a];
  for (std::size_t k = k1; k-- > k0;) {
    const std::size_t c = row_at(k);
    if (blk.far) {  // (nothing asked for ahead when the rows fit in the caches: see above)
      if (k >= kPrefetchRows) {
        // The ball record of a neighbour some rows on, and its force sums: the neighbours in the layer
        // above a ball are a whole layer away in memory, and the hardware prefetcher misses them.
        const std::size_t ahead_ball = keys[row_at(k - kPrefetchRows)].b;
        const char* ahead = reinterpret_cast<const char*>(blk.kin + ahead_ball);
        __builtin_prefetch(ahead);
        __builtin_prefetch(ahead + 64);
        __builtin_prefetch(blk.sums + ahead_ball, 1);
      }
      if (k >= kPrefetchColumns) {  // the history and the parameters
        const std::size_t r = row_at(k - kPrefetchColumns);
        __builtin_prefetch(contacts.normal.data() + r, 1);
        __builtin_prefetch(contacts.shear_state.data() + r, 1);
        __builtin_prefetch(blk.row_sets + r);
      }
      if (k >= kPrefetchFlags) {  // the byte columns, and the keys (12 B) half as far
        const std::size_t r = row_at(k - kPrefetchFlags);
        __builtin_prefetch(contacts.image.data() + r);
        __builtin_prefetch(contacts.exists.data() + r);
        __builtin_prefetch(contacts.model.data() + r);
        __builtin_prefetch(contacts.moisture.data() + r);
        __builtin_prefetch(keys + row_at(k - kPrefetchFlags / 2));
      }
    }
    const std::size_t b = keys[c].b;
    const bool exists = contacts.exists[c];
    if (contacts.model[c] == ModelKind::Hill) {
      // A hill row, contact or neighbour pair, without a branch on which it is: the row always takes
      // the next lane's slot, which becomes a lane only if it is a contact. A live row is mostly a
      // contact (≈ 90 % in the bench bed; the others are neighbour pairs within reach of one, and
      // contacts deleted since the list was made), so the branch on `exists` is mostly not taken,
      // and the balls' records are read only then. Only a pair within reach that is no contact yet
      // (a new one: rare) goes to force_row, in row order.
      if (linear.size() > 0) flush(blk, linear);
      if (hill.full()) flush(blk, hill);
      const ImageCode image = contacts.image[c];
      hill.add_if(exists, static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                  image);
      if (!exists && pair_within_reach(ka, blk.kin[b], image, blk.box, blk.proximity)) [[unlikely]] {
        if (hill.size() > 0) flush(blk, hill);  // a contact from now on
        add_share(blk, c, force_row(c, blk.dt));
      }
      continue;
    }
    // A neighbour pair beyond reach gives nothing to either ball.
    if (!exists && !pair_within_reach(ka, blk.kin[b], contacts.image[c], blk.box, blk.proximity)) continue;
    ContactBatch* batch = nullptr;  // the model's batch (exhaustive: -Werror=switch)
    switch (batch_of(contacts.model[c])) {
      case BatchKind::Hill: batch = &hill; break;
      case BatchKind::Linear: batch = &linear; break;
      case BatchKind::None: break;  // (row by row)
    }
    if (!exists || batch == nullptr) {  // a new contact, or a model without a batch: row by row
      if (hill.size() > 0) flush(blk, hill);
      if (linear.size() > 0) flush(blk, linear);
      add_share(blk, c, force_row(c, blk.dt));
      continue;
    }
    ContactBatch& other = batch == &hill ? linear : hill;
    if (other.size() > 0) flush(blk, other);
    if (batch->full()) flush(blk, *batch);
    // The lane's inputs are read when the batch runs (gather_lanes).
    batch->add(static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
               contacts.image[c]);
  }
}

// Ball a's live rows from the last down, through their records: the loop of block_rows for live
// rows, with the record of each row in place of its nine columns. A row that is no contact (a
// neighbour pair within reach of one, or a contact deleted since the list) is checked for reach from
// the record and its second ball's, which the lanes read anyway.
HILLDEM_INLINE void ForcePass::block_records(Block& blk, std::size_t a) {
  ContactBatch& hill = blk.hill;
  ContactBatch& linear = blk.linear;
  const BallKin& ka = blk.kin[a];
  LiveRecord* rec = blk.live_rows.records();
  const std::uint32_t* live_first = blk.live_rows.first();
  for (std::size_t k = live_first[a + 1]; k-- > live_first[a];) {
    if (blk.far) {
      // The neighbour's record and sums, as in block_rows, and the record 64 rows on (one line a
      // row). Asked for to be read, not written (prefetchw), although both lines are written later
      // (docs/performance.md).
      if (k >= kPrefetchRows) {
        const std::size_t ahead_ball = rec[k - kPrefetchRows].b;
        const char* ahead = reinterpret_cast<const char*>(blk.kin + ahead_ball);
        __builtin_prefetch(ahead);
        __builtin_prefetch(ahead + 64);
        __builtin_prefetch(blk.sums + ahead_ball);
      }
      if (k >= kPrefetchRecords) __builtin_prefetch(rec + k - kPrefetchRecords);
    } else if (k >= kPrefetchRecords) {
      // The records alone in the caches' range too: the stream runs down, and the hardware
      // prefetcher follows it poorly.
      __builtin_prefetch(rec + k - kPrefetchRecords);
    }
    const LiveRecord& r = rec[k];
    const std::size_t c = r.row, b = r.b;
    if (r.model == ModelKind::Hill) {
      if (linear.size() > 0) flush(blk, linear);
      if (hill.full()) flush(blk, hill);
      const bool exists = r.exists;
      hill.add_if(exists, static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                  r.image, static_cast<std::uint32_t>(k));
      if (!exists && pair_within_reach(ka, blk.kin[b], r.image, blk.box, blk.proximity)) [[unlikely]] {
        if (hill.size() > 0) flush(blk, hill);  // a contact again (force_row)
        add_share(blk, c, force_row(c, blk.dt));
        blk.live_rows.load_record(k, blk.contacts, blk.row_sets);
      }
      continue;
    }
    // Another model keeps its history and flags in the columns: this one row as block_rows takes it.
    block_rows(blk, a, k + 1, k, [rec](std::size_t j) -> std::size_t { return rec[j].row; });
  }
}

void ForcePass::force_block(std::size_t a0, std::size_t a1, std::size_t range_end, BlockScratch& scratch,
                            std::vector<CrossShare>& crossing, std::size_t& bad_row, std::int64_t& batched) {
  // Rows of balls a0..a1-1 (ball-ball rows, contiguous), from the last ball down and each ball's rows
  // from the last down. Existing hill and linear contacts go through the batches; new contacts and
  // the shear-displacement tracking through force_row(). Each row's share is added to both balls
  // when its result is known, in that descending row order (force_pass.hpp): a batch is run before
  // a row of the other batch or of force_row() is added, so the lanes keep the order.
  ContactStore& contacts = *w_.contacts;
  LiveRows& live_rows = *w_.live;
  const BallKin* kin = w_.kin->data();
  const bool live = live_rows.visited();
  Block blk{contacts,
            kin,
            contacts.key.data(),
            w_.kin->sums(),
            *w_.stiffness,
            live_rows,
            w_.hill_sets->row_sets(),
            LaneSources{kin, &w_.settings->box, &contacts, live_rows.records(), w_.hill_sets->sets(),
                        w_.hill_sets->row_sets()},
            w_.settings->box,
            o_.dt,
            w_.settings->proximity,
            want_stiffness(),
            o_.write_results,
            contacts.size() > kFarRows,
            live,
            live && live_rows.records_ready(),
            range_end,
            scratch.hill,
            scratch.linear,
            crossing,
            bad_row,
            batched};
  blk.hill.clear();
  blk.linear.clear();
  for (std::size_t a = a1; a-- > a0;) {
    // Ball a's sums start here: its own rows come first in its order, and rows (x, a) with x < a
    // come later.
    blk.sums[a] = motion::ContactSums{};
    if (blk.want_stiffness) blk.stiffness.tran[a] = blk.stiffness.rot[a] = 0.0;
    prefetch_ball(blk, a);
    if (blk.records) {
      block_records(blk, a);
    } else if (live) {
      const std::uint32_t* rows = live_rows.rows();
      block_rows(blk, a, live_rows.first()[a + 1], live_rows.first()[a],
                 [rows](std::size_t k) -> std::size_t { return rows[k]; });
    } else {  // every row through force_row (each contact's shear displacement tracked)
      const std::vector<std::uint32_t>& first_rows = w_.neighbours->first_rows();
      for (std::size_t c = first_rows[a + 1]; c-- > first_rows[a];) add_share(blk, c, force_row(c, blk.dt));
    }
  }
  if (blk.hill.size() > 0) flush(blk, blk.hill);
  if (blk.linear.size() > 0) flush(blk, blk.linear);
}

}  // namespace hilldem
