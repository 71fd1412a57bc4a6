// What one contact row's law gives: its outcome (RowOutcome), what its two bodies get (RowShare,
// CrossShare), and how the outcome is written into the row's columns (store_row, and for a batch
// lane store_kept_lane). Shared by the row-by-row law (ForcePass::force_row), the batches' scatter
// and the wall rows, so that every path writes the same columns in the same cases.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/contact_batch.hpp"
#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {

// What a row gives its two bodies (zero when the row is not an active contact).
struct RowShare {
  Vec3 force;    // on piece 1: −F_c [N] (piece 2 gets F_c = −force)
  Vec3 moment;   // on piece 1: −(R_1 + g/2) n̂_c × F_c [N m]
  Vec3 moment2;  // on piece 2 (or, for a wall row, on its ball): −(R_2 + g/2) n̂_c × F_c [N m]
  // What the row adds to the stiffness sums (when the time step needs them): k̂_n + k̂_s, k̂_s
  // [N/m] (zero when not an active contact) and the gap [m] (add_stiffness).
  double k_tran = 0.0, k_shear = 0.0, gap = 0.0;
  bool ok = true;  // false on a non-finite force
  // Zero the forces and moments, and the stiffness terms when they are read, field by field:
  // `force = moment = Vec3{}` reloads the moment just stored and stalls store forwarding.
  void clear(bool stiffness) {
    force = Vec3{};
    moment = Vec3{};
    moment2 = Vec3{};
    if (stiffness) {
      k_tran = 0.0;
      k_shear = 0.0;
      gap = 0.0;
    }
  }
};
// A ball-ball row whose second ball lies beyond the range of the thread that ran it: its share of
// that ball, added after the parallel pass (see force_pass).
struct CrossShare {
  std::uint32_t b;
  Vec3 force, moment;
  double k_tran, k_shear, gap;
};
// A row's result, from either law path (row by row or batched).
struct RowOutcome {
  Vec3 normal;                  // n̂_c
  double gap = 0.0;             // g_c [m]
  // [m] the radii of the moments' arms R + g/2 (contact_moments): of the pair loop's ball and of the
  // body that collects the second share (a wall row's: its ball's, as the wall's arm is 0)
  double r1 = 0.0, r2 = 0.0;
  Vec3 force;                   // F_c [N] (zero if inactive)
  Vec3 shear;                   // shear force carried to the next step [N]
  double normal_force = 0.0, moisture_force = 0.0, trial_shear = 0.0;  // [N]
  double k_tran = 0.0, k_shear = 0.0;  // [N/m], written only when the time step needs them
  Vec3 moment;                  // contact moment M_c on piece 2 [N m] (rrlinear; zero for other models)
  bool wall_row = false;        // (for M_c's share: a wall row's second share is its ball's)
  Moisture moisture = Moisture::Dry;
  bool active = false;
};

// A batch lane's results as a row outcome (store_row's input). A wall row's moment on its ball
// takes the ball's arm (the lane's second arm is the wall's, exactly 0: wall_block); a linear lane
// never ruptures, so its moisture state stays as it was.
HILLDEM_INLINE RowOutcome lane_outcome(const ContactStore& contacts, const ContactBatch& batch, std::size_t lane,
                                       bool wall_row) {
  using F = ContactBatch;
  RowOutcome out;
  out.normal = batch.get3(F::kNx, lane);
  out.gap = batch.col(F::kGap)[lane];
  out.r1 = batch.col(F::kR1)[lane];
  out.r2 = wall_row ? out.r1 : batch.col(F::kR2)[lane];
  out.force = batch.get3(F::kFx, lane);
  out.shear = batch.get3(F::kShx, lane);
  out.normal_force = batch.col(F::kFn)[lane];
  out.moisture_force = batch.col(F::kFm)[lane];
  out.trial_shear = batch.col(F::kTrial)[lane];
  out.k_tran = batch.col(F::kKtran)[lane];
  out.k_shear = batch.col(F::kKshear)[lane];
  out.moisture = batch.col(F::kRuptured)[lane] != 0.0 ? Moisture::Ruptured : contacts.moisture[batch.row(lane)];
  out.active = batch.col(F::kActive)[lane] != 0.0;
  return out;
}

HILLDEM_INLINE void store_row(ContactStore& contacts, double proximity, std::size_t c, const RowOutcome& out,
                              bool want_stiffness, bool reported, RowShare& share) {
  // Deleted when inactive beyond the proximity distance (a wet contact stays active: spec §2.5).
  if (!out.active && out.gap > proximity) {
    contacts.remove(c);  // (moisture back to dry)
    contacts.gap[c] = out.gap;
    contacts.normal[c] = out.normal;
    share.clear(want_stiffness);
    share.ok = true;
    return;
  }
  // Force on piece 2 is F_c, on piece 1 −F_c (spec conventions). The contact point lies on the normal
  // at R + g/2 from either centre, so the moment on either ball is −(R + g/2) n̂ × F_c.
  // (The share is written where it belongs, field by field: a share built on the stack and copied
  // reloads fields just stored, which stalls store forwarding.)
  const ContactMoments<double> m =
      contact_moments(lanes::v3(out.normal), out.gap, out.r1, out.r2, lanes::v3(out.force));
  share.force = -out.force;
  // The contact moment M_c (rrlinear) on piece 2, −M_c on piece 1; a wall row's second share is its
  // ball's (piece 1).
  share.moment = lanes::vec3(m.on1) - out.moment;
  share.moment2 = out.wall_row ? lanes::vec3(m.on2) - out.moment : lanes::vec3(m.on2) + out.moment;
  share.ok = std::isfinite(out.force.x + out.force.y + out.force.z);
  if (want_stiffness) {  // what add_row_stiffness reads (zero when inactive)
    share.k_tran = out.k_tran;
    share.k_shear = out.k_shear;
    share.gap = out.gap;
  }
  // Only the columns the cycle needs (memory traffic): F_s = F_c − (F_n + F^m) n̂ is derived. The
  // history always; F_c and the columns only reports read when `reported` (wall rows, which
  // collect_forces reads from F_c, always are); gap and the active flag also when the stiffness
  // sums read them (and the gap when the force is not finite: the run's error message names it).
  contacts.shear_state[c] = out.shear;
  contacts.normal[c] = out.normal;
  contacts.moment_state[c] = out.moment;
  if (reported) contacts.force[c] = out.force;
  if (reported || want_stiffness || !share.ok) contacts.gap[c] = out.gap;
  if (reported) {
    contacts.normal_force[c] = out.normal_force;
    contacts.moisture_force[c] = out.moisture_force;
    contacts.trial_shear[c] = out.trial_shear;
  }
  if (want_stiffness) {  // only the time-step estimate and density scaling read them
    contacts.k_tran[c] = out.k_tran;
    contacts.k_shear[c] = out.k_shear;
  }
  // Byte-sized columns last: a char store may alias anything, so the compiler reloads every
  // column pointer after one.
  contacts.moisture[c] = out.moisture;
  if (reported || want_stiffness) contacts.active[c] = out.active;
}

HILLDEM_INLINE void store_kept_lane(ContactStore& contacts, std::size_t c, const ContactBatch& batch, std::size_t lane,
                                    bool want_stiffness, bool reported, bool history = true) {
  // The columns of store_row for a contact that stays (written in the same cases), straight from the
  // lanes: no RowOutcome and RowShare copied, no moments computed one lane at a time, no keys read
  // again.
  using F = ContactBatch;
  if (history) {
    contacts.shear_state[c] = batch.get3(F::kShx, lane);
    contacts.normal[c] = batch.get3(F::kNx, lane);
  }
  if (reported) {
    contacts.force[c] = batch.get3(F::kFx, lane);
    contacts.normal_force[c] = batch.col(F::kFn)[lane];
    contacts.moisture_force[c] = batch.col(F::kFm)[lane];
    contacts.trial_shear[c] = batch.col(F::kTrial)[lane];
  }
  if (reported || want_stiffness) contacts.gap[c] = batch.col(F::kGap)[lane];
  if (want_stiffness) {
    contacts.k_tran[c] = batch.col(F::kKtran)[lane];
    contacts.k_shear[c] = batch.col(F::kKshear)[lane];
  }
  // Byte-sized columns last (store_row); the moisture changes only when the bridge ruptured.
  if (batch.col(F::kRuptured)[lane] != 0.0) contacts.moisture[c] = Moisture::Ruptured;
  if (reported || want_stiffness) contacts.active[c] = batch.col(F::kActive)[lane] != 0.0;
}

}  // namespace hilldem
