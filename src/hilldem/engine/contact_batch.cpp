#include "hilldem/engine/contact_batch.hpp"

#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/hill.hpp"
#include "hilldem/models/lanes.hpp"
#include "hilldem/models/linear.hpp"

namespace hilldem {

namespace {

using lanes::Pack;
using lanes::V3;
using F = ContactBatch;

// Lanes i..i+kWidth-1 of a batch: its columns as Packs.
struct LanePack {
  ContactBatch& batch;
  std::size_t i;
  HILLDEM_INLINE Pack get(F::Field f) const { return lanes::load(batch.col(f) + i); }
  HILLDEM_INLINE V3<Pack> get3(F::Field f) const {
    return lanes::load3(batch.col(f), batch.col(static_cast<F::Field>(f + 1)), batch.col(static_cast<F::Field>(f + 2)), i);
  }
  HILLDEM_INLINE void put(F::Field f, Pack v) const { lanes::store(batch.col(f) + i, v); }
  HILLDEM_INLINE void put3(F::Field f, const V3<Pack>& v) const {
    lanes::store3(batch.col(f), batch.col(static_cast<F::Field>(f + 1)), batch.col(static_cast<F::Field>(f + 2)), i, v);
  }
};

// The kinematics of a pack of lanes: geometry (Eqs. 2-3, or the wall's, given), the relative
// velocity at the contact point split into its normal and shear rates (§1.2), and the stored shear
// force carried into the current plane (§1.3). Written into the geometry columns.
struct PackKinematics {
  V3<Pack> normal;
  Pack gap, r1, r2;
  Pack normal_rate;
  V3<Pack> shear_rate;
  V3<Pack> carried;
};

HILLDEM_INLINE PackKinematics pack_kinematics(const LanePack& l, double dt, bool geometry_given) {
  const V3<Pack> n_old = l.get3(F::kNox);
  const Pack r1 = l.get(F::kR1), r2 = l.get(F::kR2);
  PairGeometry<Pack> g;
  if (geometry_given) {
    g = {l.get3(F::kNx), l.get(F::kGap)};
  } else {
    g = ball_pair_geometry(l.get3(F::kDx), r1, r2, n_old);
    l.put3(F::kNx, g.normal);
    l.put(F::kGap, g.gap);
  }
  const V3<Pack> wa = l.get3(F::kWax), wb = l.get3(F::kWbx);
  const V3<Pack> rel = contact_velocity(g.normal, g.gap, r1, r2, l.get3(F::kVax), wa, l.get3(F::kVbx), wb);
  const Pack rate = dot(rel, g.normal);
  const V3<Pack> shear_rate = rel - g.normal * rate;
  const V3<Pack> carried = carry_into_plane(l.get3(F::kSx), n_old, g.normal, 0.5 * dot(wa + wb, g.normal), dt);
  return {g.normal, g.gap, r1, r2, rate, shear_rate, carried};
}

// What every model's lanes write besides its own: F_c, its parts, the history, the flags, the
// moments on the two bodies and whether the scatter may take the lane the common way (kQuick: the
// contact is kept, i.e. active or within `proximity` [m] (spec §2.5), and its force is finite).
HILLDEM_INLINE void put_results(const LanePack& l, const PackKinematics& k, const V3<Pack>& force, Pack normal_force,
                                Pack moisture_force, Pack trial, const V3<Pack>& history, lanes::PackMask active,
                                lanes::PackMask ruptured, double proximity) {
  l.put3(F::kFx, force);
  l.put(F::kFn, normal_force);
  l.put(F::kFm, moisture_force);
  l.put(F::kTrial, trial);
  l.put3(F::kShx, history);
  l.put(F::kActive, lanes::flag(active));
  l.put(F::kRuptured, lanes::flag(ruptured));
  const ContactMoments<Pack> m = contact_moments(k.normal, k.gap, k.r1, k.r2, force);
  l.put3(F::kMax, m.on1);
  l.put3(F::kMbx, m.on2);
  // Finite: sum − sum is 0 (NaN for ±inf and NaN).
  const Pack sum = force.x + force.y + force.z;
  const lanes::PackMask kept = active | (k.gap <= proximity);
  l.put(F::kQuick, lanes::flag(kept & (sum - sum == 0.0)));
}

}  // namespace

std::size_t ContactBatch::pad_lanes() {
  static_assert(kLanes % kVector == 0);
  const std::size_t padded = padded_size();  // (0 for an empty batch)
  for (int f = 0; f <= kLastInput; ++f)  // the inputs
    for (std::size_t lane = size_; lane < padded; ++lane) data_[f][lane] = data_[f][size_ - 1];
  return padded;
}

void ContactBatch::pad_geometry(std::size_t padded) {
  for (int f : {kNx, kNy, kNz, kGap})
    for (std::size_t lane = size_; lane < padded; ++lane) data_[f][lane] = data_[f][size_ - 1];
}

void run_hill_lanes(ContactBatch& batch, const LaneStep& step) {
  const std::size_t n = batch.pad_lanes();
  for (std::size_t i = 0; i < n; i += lanes::kWidth) {
    const LanePack l{batch, i};
    const PackKinematics k = pack_kinematics(l, step.dt, false);
    const Pack damp = l.get(F::kDamp);
    const HillCoefficients<Pack> c = hill_coefficients(damp, l.get(F::kIr), l.get(F::kIm), l.get(F::kCn), l.get(F::kCs));
    const Pack r_o = lanes::min(k.r1, k.r2);
    const HillOutput<Pack> o = hill_law<Pack>({l.get(F::kFric), l.get(F::kSuction), c.kn, c.ks, c.bn, c.bs, r_o, k.normal,
                                               k.gap, k.normal_rate, k.shear_rate, step.dt, k.carried,
                                               l.get(F::kWet) != 0.0});
    put_results(l, k, o.force, o.surface_normal, o.moisture_force, o.trial_shear, o.shear_hm, o.active, o.ruptured,
                step.proximity);
    if (step.want_stiffness) {  // Eqs. 19-21, zero when inactive
      const HillStiffness<Pack> s = hill_stiffness(damp, c.kn, c.ks, r_o, k.gap);
      const Pack zero = lanes::splat<Pack>(0.0);
      l.put(F::kKtran, lanes::select(o.active, s.kn + s.ks, zero));
      l.put(F::kKshear, lanes::select(o.active, s.ks, zero));
    }
  }
}

void run_linear_lanes(ContactBatch& batch, const LaneStep& step) {
  const std::size_t n = batch.pad_lanes();
  if (step.geometry_given) batch.pad_geometry(n);
  for (std::size_t i = 0; i < n; i += lanes::kWidth) {
    const LanePack l{batch, i};
    const PackKinematics k = pack_kinematics(l, step.dt, step.geometry_given);
    const Pack kn = l.get(F::kIr), ks = l.get(F::kIm);
    const LinearOutput<Pack> o =
        linear_law<Pack>({kn, ks, l.get(F::kFric), k.normal, k.gap, k.shear_rate, step.dt, k.carried});
    const Pack zero = lanes::splat<Pack>(0.0);
    put_results(l, k, o.force, o.normal_force, zero, o.trial_shear, o.shear_force, o.active, lanes::PackMask{},
                step.proximity);
    if (step.want_stiffness) {
      l.put(F::kKtran, lanes::select(o.active, kn + ks, zero));
      l.put(F::kKshear, lanes::select(o.active, ks, zero));
    }
  }
}

}  // namespace hilldem
