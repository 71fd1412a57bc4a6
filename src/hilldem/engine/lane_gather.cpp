#include "hilldem/engine/lane_gather.hpp"

#include <algorithm>
#include <cstddef>

#include "hilldem/models/lanes.hpp"

namespace hilldem {

namespace {
#if defined(__AVX512F__)
using lanes::transpose8;
using lanes::widen8;
#endif

HILLDEM_INLINE void fill_ball_lanes(ContactBatch& batch, bool hill, const LaneSources& src) {
  // Each lane's inputs: from the records of its two balls x2 − x1 (x2 with its periodic image), the
  // radii, velocities and spins, and for the hill law the sums of the two balls' terms; from its row
  // the last normal and shear force and the parameters. The ball values copied lane by lane are 28
  // loads and 28 stores a lane, and a core stores about one value a cycle to different lines; with
  // AVX-512 the records of eight lanes are loaded whole and transposed in registers, and each field
  // is stored once for the eight lanes (docs/performance.md). The arithmetic is the same (x2 − x1 and
  // the sums, lane by lane), so the bits are those of the lane-by-lane copy.
  using F = ContactBatch;
  const BallKin* kin = src.kin;
  const std::size_t n = batch.size();
  std::size_t lane = 0;
#if defined(__AVX512F__)
  {
    static_assert(sizeof(BallKin) == 128 && alignof(BallKin) == 64);
    static_assert(offsetof(BallKin, position) == 0 && offsetof(BallKin, radius) == 24 &&
                  offsetof(BallKin, velocity) == 32 && offsetof(BallKin, spin) == 56 && offsetof(BallKin, terms) == 80);
    for (; lane < n; lane += 8) {
      // (A last group of fewer than eight lanes repeats its last lane; the batch has room for 64.)
      const double* pa[8];
      const double* pb[8];
      __m512d ra[8], rb[8], a0[8], a1[8], b0[8], b1[8];
      for (std::size_t k = 0; k < 8; ++k) {
        const std::size_t l = std::min(lane + k, n - 1);
        pa[k] = reinterpret_cast<const double*>(kin + batch.ball1(l));
        pb[k] = reinterpret_cast<const double*>(kin + batch.ball2(l));
        ra[k] = _mm512_load_pd(pa[k]);
        rb[k] = _mm512_load_pd(pb[k]);
      }
      transpose8(ra, a0);  // position, radius, velocity, spin.x
      transpose8(rb, b0);
      for (std::size_t k = 0; k < 8; ++k) {
        ra[k] = _mm512_load_pd(pa[k] + 8);
        rb[k] = _mm512_load_pd(pb[k] + 8);
      }
      transpose8(ra, a1);  // spin.y, spin.z, the four terms, padding
      transpose8(rb, b1);
      _mm512_store_pd(batch.col(F::kDx) + lane, _mm512_sub_pd(b0[0], a0[0]));
      _mm512_store_pd(batch.col(F::kDy) + lane, _mm512_sub_pd(b0[1], a0[1]));
      _mm512_store_pd(batch.col(F::kDz) + lane, _mm512_sub_pd(b0[2], a0[2]));
      _mm512_store_pd(batch.col(F::kR1) + lane, a0[3]);
      _mm512_store_pd(batch.col(F::kR2) + lane, b0[3]);
      _mm512_store_pd(batch.col(F::kVax) + lane, a0[4]);
      _mm512_store_pd(batch.col(F::kVay) + lane, a0[5]);
      _mm512_store_pd(batch.col(F::kVaz) + lane, a0[6]);
      _mm512_store_pd(batch.col(F::kVbx) + lane, b0[4]);
      _mm512_store_pd(batch.col(F::kVby) + lane, b0[5]);
      _mm512_store_pd(batch.col(F::kVbz) + lane, b0[6]);
      _mm512_store_pd(batch.col(F::kWax) + lane, a0[7]);
      _mm512_store_pd(batch.col(F::kWay) + lane, a1[0]);
      _mm512_store_pd(batch.col(F::kWaz) + lane, a1[1]);
      _mm512_store_pd(batch.col(F::kWbx) + lane, b0[7]);
      _mm512_store_pd(batch.col(F::kWby) + lane, b1[0]);
      _mm512_store_pd(batch.col(F::kWbz) + lane, b1[1]);
      if (hill) {
        _mm512_store_pd(batch.col(F::kIr) + lane, _mm512_add_pd(a1[2], b1[2]));
        _mm512_store_pd(batch.col(F::kIm) + lane, _mm512_add_pd(a1[3], b1[3]));
        _mm512_store_pd(batch.col(F::kCn) + lane, _mm512_add_pd(a1[4], b1[4]));
        _mm512_store_pd(batch.col(F::kCs) + lane, _mm512_add_pd(a1[5], b1[5]));
      }
    }
    // Lanes across a periodic boundary: x2 − x1 again, with the image.
    for (std::size_t l = 0; l < n; ++l)
      if (batch.image(l) != kNoImage)
        batch.put3(F::kDx, l, separation(kin[batch.ball1(l)], kin[batch.ball2(l)], batch.image(l), *src.box));
    lane = n;
  }
#endif
  for (; lane < n; ++lane) {  // lane by lane (no AVX-512)
    const BallKin& ka = kin[batch.ball1(lane)];
    const BallKin& kb = kin[batch.ball2(lane)];
    batch.put3(F::kDx, lane, separation(ka, kb, batch.image(lane), *src.box));
    batch.col(F::kR1)[lane] = ka.radius;
    batch.col(F::kR2)[lane] = kb.radius;
    batch.put3(F::kVax, lane, ka.velocity);
    batch.put3(F::kVbx, lane, kb.velocity);
    batch.put3(F::kWax, lane, ka.spin);
    batch.put3(F::kWbx, lane, kb.spin);
    if (hill) {
      batch.col(F::kIr)[lane] = ka.terms.inv_radius + kb.terms.inv_radius;
      batch.col(F::kIm)[lane] = ka.terms.inv_mass + kb.terms.inv_mass;
      batch.col(F::kCn)[lane] = ka.terms.normal + kb.terms.normal;
      batch.col(F::kCs)[lane] = ka.terms.shear + kb.terms.shear;
    }
  }
}

HILLDEM_INLINE void fill_row_lanes(ContactBatch& batch, bool hill, const LaneSources& src) {
  const ContactStore& contacts = *src.contacts;
  using F = ContactBatch;
  const std::size_t n = batch.size();
  // The rows' own inputs. A hill lane's history, parameter set and M: from its live record (eight
  // lanes at a time with AVX-512: one aligned line a row), or from the row columns.
  auto put_hill = [&](std::size_t lane, const Vec3& normal, const Vec3& shear, std::uint32_t set, Moisture m) {
    batch.put3(F::kNox, lane, normal);
    batch.put3(F::kSx, lane, shear);
    const HillParams& p = src.sets[set];
    batch.col(F::kFric)[lane] = p.fric_coef, batch.col(F::kSuction)[lane] = p.suction;
    batch.col(F::kDamp)[lane] = p.damp_con;
    batch.col(F::kWet)[lane] = m == Moisture::Wet ? 1.0 : 0.0;
  };
  std::size_t lane = 0;
#if defined(__AVX512F__)
  if (hill) {
    // Eight lanes with live records at a time: the records loaded whole and transposed in registers
    // (n̂_c and F^h_s stored once for the eight lanes), the parameters gathered by set, M compared
    // for the eight at once. The same values as put_hill's, so the same bits.
    static_assert(sizeof(LiveRecord) == 64 && alignof(LiveRecord) == 64);
    static_assert(offsetof(LiveRecord, hill_set) == 8 && offsetof(LiveRecord, moisture) == 15 &&
                  offsetof(LiveRecord, normal) == 16 && offsetof(LiveRecord, shear) == 40);
    static_assert(sizeof(HillParams) == 24 && offsetof(HillParams, fric_coef) == 0 &&
                  offsetof(HillParams, damp_con) == 8 && offsetof(HillParams, suction) == 16);
    const __m512i no_slot = _mm512_set1_epi64(ContactBatch::kNoSlot);
    const double* sets = reinterpret_cast<const double*>(src.sets);
    for (; lane + 8 <= n; lane += 8) {
      if (_mm512_cmp_epi64_mask(widen8(batch.slots() + lane), no_slot, _MM_CMPINT_NE) != 0xFF) break;  // (the rest lane by lane)
      __m512d r[8], c[8];
      for (std::size_t k = 0; k < 8; ++k) r[k] = _mm512_load_pd(reinterpret_cast<const double*>(&src.records[batch.slot(lane + k)]));
      transpose8(r, c);  // c[1]: set and flags; c[2..4]: n̂_c; c[5..7]: F^h_s
      const F::Field history[6] = {F::kNox, F::kNoy, F::kNoz, F::kSx, F::kSy, F::kSz};
      for (int f = 0; f < 6; ++f) _mm512_store_pd(batch.col(history[f]) + lane, c[2 + f]);
      const __m512i flags = _mm512_castpd_si512(c[1]);
      const __m512i at = _mm512_mullo_epi64(_mm512_and_si512(flags, _mm512_set1_epi64(0xFFFFFFFF)), _mm512_set1_epi64(3));
      _mm512_store_pd(batch.col(F::kFric) + lane, _mm512_i64gather_pd(at, sets + 0, 8));
      _mm512_store_pd(batch.col(F::kDamp) + lane, _mm512_i64gather_pd(at, sets + 1, 8));
      _mm512_store_pd(batch.col(F::kSuction) + lane, _mm512_i64gather_pd(at, sets + 2, 8));
      const __mmask8 wet = _mm512_cmp_epi64_mask(_mm512_srli_epi64(flags, 56),
                                                 _mm512_set1_epi64(static_cast<int>(Moisture::Wet)), _MM_CMPINT_EQ);
      _mm512_store_pd(batch.col(F::kWet) + lane, _mm512_maskz_mov_pd(wet, _mm512_set1_pd(1.0)));
    }
  }
#endif
  for (; lane < n; ++lane) {
    const std::size_t c = batch.row(lane);
    if (hill) {
      const std::uint32_t slot = batch.slot(lane);
      if (slot != ContactBatch::kNoSlot) {
        const LiveRecord& r = src.records[slot];
        put_hill(lane, r.normal, r.shear, r.hill_set, r.moisture);
      } else {
        put_hill(lane, contacts.normal[c], contacts.shear_state[c], src.row_sets[c], contacts.moisture[c]);
      }
    } else {  // the linear law's history, and its parameters: the row's (LinearMapping, LinearParams)
      batch.put3(F::kNox, lane, contacts.normal[c]);
      batch.put3(F::kSx, lane, contacts.shear_state[c]);
      batch.col(F::kIr)[lane] = contacts.linear_map[c].kn;
      batch.col(F::kIm)[lane] = contacts.linear_map[c].ks;
      batch.col(F::kFric)[lane] = contacts.linear_params[c].fric;
    }
  }
}

}  // namespace

void gather_lanes(ContactBatch& batch, bool hill, const LaneSources& src) {
  fill_ball_lanes(batch, hill, src);
  fill_row_lanes(batch, hill, src);
}

}  // namespace hilldem
