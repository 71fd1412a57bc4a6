// ContactBatch: many contacts' law at once, in structure-of-arrays lanes.
//
// Why: one contact's law is a long chain of dependent square roots and divisions (distance, normal,
// the carried shear's magnitude, δ^{1/2}, δ^{1/4}, two norms and two clamps), longer than the
// out-of-order window of a core, so a row-by-row loop runs at the speed of that chain. Here the force
// pass gathers the existing contacts of a block of balls into lanes (one batch per model), runs the
// model's law (models/: the same template the row-by-row path runs, over lanes::Pack instead of
// double) on kWidth lanes at a time, and scatters the results back.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hilldem/core/vec3.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {

class ContactBatch {
 public:
  // Lane columns. Inputs are gathered by the force pass; outputs are written by run_hill_lanes() or run_linear_lanes().
  enum Field : int {
    // inputs
    kDx, kDy, kDz,      // x2 − x1 [m] (periodic image applied)
    kR1, kR2,           // radii [m]
    kVax, kVay, kVaz,   // velocity of ball 1 [m/s]
    kVbx, kVby, kVbz,   // velocity of ball 2 [m/s]
    kWax, kWay, kWaz,   // spin of ball 1 [rad/s]
    kWbx, kWby, kWbz,   // spin of ball 2 [rad/s]
    kNox, kNoy, kNoz,   // n̂_c of the last step
    kSx, kSy, kSz,      // F^h_s of the last step [N], in its plane
    // hill: the sums of the two balls' terms of the mapping (HillBodyTerms: 1/R1 + 1/R2 [1/m],
    // 1/m1 + 1/m2 [1/kg], Σ(1 − ν²)/E, Σ 2(2 − ν)(1 + ν)/E [1/Pa]), the first step of the mapping
    // (hill_mapping), done in the gather: four fields instead of eight;
    // linear: kIr = k_n, kIm = k_s [N/m] (LinearMapping)
    kIr, kIm, kCn, kCs,
    kFric, kSuction, kDamp,   // μ [-], ψ [Pa], γ_h [-]
    kWet,               // 1 if M = 2 (wet) at the start of the step, else 0
    // outputs
    kNx, kNy, kNz,      // n̂_c
    kGap,               // g_c [m]
    kFx, kFy, kFz,      // F_c on ball 2 [N] (zero if inactive)
    kFn, kFm, kTrial,   // F^s_n, F^m, |F*_s| [N]
    kShx, kShy, kShz,   // F^h_s carried to the next step [N]
    kActive,            // 1 if active after the step
    kRuptured,          // 1 if the liquid bridge ruptured this step
    kKtran, kKshear,    // k̂_n + k̂_s, k̂_s [N/m] (when asked for)
    // what the scatter adds to the two balls' sums
    kMax, kMay, kMaz,   // moment on ball 1: −(R1 + g/2) n̂ × F_c [N m]
    kMbx, kMby, kMbz,   // moment on ball 2 (a wall lane: on its ball, see wall_block): −(R2 + g/2) n̂ × F_c [N m]
    kQuick,             // 1 if the row stays a contact and its force is finite (the scatter's common case)
    kFieldCount
  };

  // Lanes per batch: 64 lanes of every field take ≈ 30 kB, so a batch stays in the L1 cache between
  // the gather, the law and the scatter.
  static constexpr std::size_t kLanes = 64;
  // A lane whose row has no live record (see add_if).
  static constexpr std::uint32_t kNoSlot = 0xFFFFFFFFu;

  // The last input field (pad_lanes copies kDx..kLastInput).
  static constexpr int kLastInput = kWet;

  void clear() { size_ = 0; }
  bool full() const { return size_ == kLanes; }
  // A new lane for contact row `row`; returns its index. Only when !full().
  std::size_t add(std::uint32_t row) {
    row_[size_] = row;
    slot_[size_] = kNoSlot;
    return size_++;
  }
  // A ball-ball lane for row `row`, kept only if `keep`: the slot after the last lane is written either
  // way and becomes a lane only for a row that is a contact, so that the row loop needs no branch on
  // it (ForcePass::block_rows). The row's two balls (the scatter adds to their sums) and the
  // periodic image of ball 2: the force pass fills the lanes' ball fields (kDx..kWbz, and the hill
  // terms kIr..kCs) from the balls' records when the batch is run (gather_lanes, engine/lane_gather.hpp), not row by
  // row. Only when !full().
  // `slot`: the row's live record (engine/live_rows.hpp), whose history the lane reads and
  // writes instead of the row columns; kNoSlot: the columns.
  void add_if(bool keep, std::uint32_t row, std::uint32_t ball1, std::uint32_t ball2, std::uint8_t image,
              std::uint32_t slot = kNoSlot) {
    image_[size_] = image;
    slot_[size_] = slot;
    ball1_[size_] = ball1;
    ball2_[size_] = ball2;
    row_[size_] = row;
    size_ += keep ? 1 : 0;
  }
  // The same, always kept.
  void add(std::uint32_t row, std::uint32_t ball1, std::uint32_t ball2, std::uint8_t image,
           std::uint32_t slot = kNoSlot) {
    add_if(true, row, ball1, ball2, image, slot);
  }
  std::uint32_t slot(std::size_t lane) const { return slot_[lane]; }
  const std::uint32_t* slots() const { return slot_; }
  const std::uint32_t* balls2() const { return ball2_; }
  std::uint8_t image(std::size_t lane) const { return image_[lane]; }
  std::uint32_t ball1(std::size_t lane) const { return ball1_[lane]; }
  std::uint32_t ball2(std::size_t lane) const { return ball2_[lane]; }
  std::size_t size() const { return size_; }
  // Lanes the laws compute: size() rounded up to a whole number of vectors (kVector), the extra
  // lanes holding copies of the last lane's inputs. Every lane is then computed by the vectorised
  // body of the law's loops, none by a scalar remainder loop (whose multiply-adds the compiler fuses
  // differently), so a contact's result does not depend on how contacts fall into batches, and the
  // block size of the force pass is a pure tuning knob. Their results are never read.
  std::size_t pad_lanes();
  // size() rounded up to a whole number of vectors: the lanes pad_lanes() fills.
  std::size_t padded_size() const { return (size_ + kVector - 1) / kVector * kVector; }
  // The same for the geometry columns (kNx..kNz, kGap) when the lanes were given their geometry.
  void pad_geometry(std::size_t padded);
  static constexpr std::size_t kVector = lanes::kWidth;
  std::uint32_t row(std::size_t lane) const { return row_[lane]; }
  double* col(Field f) { return data_[f]; }
  const double* col(Field f) const { return data_[f]; }
  // A 3-vector in the three columns from `first` (kDx, kVax, kNx, kFx, ...).
  void put3(Field first, std::size_t lane, const Vec3& v) {
    data_[first][lane] = v.x, data_[first + 1][lane] = v.y, data_[first + 2][lane] = v.z;
  }
  Vec3 get3(Field first, std::size_t lane) const {
    return {data_[first][lane], data_[first + 1][lane], data_[first + 2][lane]};
  }

 private:
  std::size_t size_ = 0;
  alignas(64) double data_[kFieldCount][kLanes];
  std::uint32_t row_[kLanes];
  std::uint32_t ball1_[kLanes];
  std::uint32_t ball2_[kLanes];
  std::uint8_t image_[kLanes];
  std::uint32_t slot_[kLanes];  // live record or kNoSlot
};

// One step of a batch's lanes.
struct LaneStep {
  double dt = 0.0;              // Δt [s]
  bool want_stiffness = false;  // write k̂_n + k̂_s and k̂_s (the time-step estimate, density scaling)
  double proximity = 0.0;       // [m] an inactive contact within it is kept (spec §2.5)
  // The lanes hold n̂_c and g_c already (kNx..kNz, kGap: ball-wall rows, whose geometry is the
  // wall's), and kDx..kDz are not read. A wall lane holds the wall's surface velocity at x_c in
  // kVbx..kVbz, its spin in kWbx..kWbz (the twist of §1.3) and R2 = −g/2, so that the arm R2 + g/2
  // of the second body is exactly 0 and ẋ_c(2) is the surface velocity itself (§1.2).
  bool geometry_given = false;
};

// The hill law (models/hill.hpp, hill_law) of every lane: the mapping from the summed body terms
// (kIr..kCs), the kinematics (models/contact_kinematics.hpp), Eqs. 12-18 and, when asked for,
// Eqs. 19-21; then F_c, the moments and kQuick for the scatter. Ball-ball lanes only.
void run_hill_lanes(ContactBatch& batch, const LaneStep& step);

// The linear law (models/linear.hpp, linear_law) of every lane: k_n, k_s in kIr, kIm, μ in kFric;
// the same outputs (F^m and rupture 0; the stiffnesses k_n, k_s when asked for).
void run_linear_lanes(ContactBatch& batch, const LaneStep& step);

}  // namespace hilldem
