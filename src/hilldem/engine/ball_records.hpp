// BallRecords: the balls' records (BallKin) that the force pass reads, the law of motion on them,
// and each ball's contact force and moment sums.
//
// Why: within one cycle() call the records are the balls' state (position, velocity, spin): the
// force pass reads them, one memory stream per neighbourhood, and the law of motion moves them in
// the same pass that measures the travel. The BallStore's columns follow only when someone may
// read them (columns_stale), and sync_columns brings them up to date. The sums are added up by the
// force pass, one line a ball (motion::ContactSums), and read by the law of motion while current;
// the BallStore's contact_force and contact_moment columns are written from them on watched passes.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/ball_kin.hpp"
#include "hilldem/motion/ball_step.hpp"

namespace hilldem {

class BallRecords {
 public:
  // The records, one per ball (valid while current()).
  BallKin* data() { return kin_.data(); }
  const BallKin* data() const { return kin_.data(); }
  std::size_t size() const { return kin_.size(); }
  BallKin& operator[](std::size_t i) { return kin_[i]; }
  const BallKin& operator[](std::size_t i) const { return kin_[i]; }
  void resize(std::size_t n) { kin_.resize(n); }

  // Whether the records hold the balls' state (from the force pass's copy on, through the record
  // motion of the steps that follow within one cycle() call).
  bool current() const { return current_; }
  // Whether the columns lag behind the records (only while current()).
  bool columns_stale() const { return columns_stale_; }
  // The records from the columns: the position, velocity, spin, mass and inertia when `state`, the
  // radius always, and the hill terms (spec §2.4, real masses) when `terms`. Current from here on.
  void fill(const BallStore& balls, bool state, bool terms);
  // The columns from the records, if they lag (and the sums' columns, if those lag).
  void sync_columns(BallStore& balls);
  // From now on the columns hold the balls' state (synced first).
  void drop(BallStore& balls) {
    sync_columns(balls);
    current_ = false;
    applied_known_ = false;
  }

  // What one record motion found: the largest |V|² [m²/s²], |x|² [m²] and squared travel since the
  // live rows [m²] (a NaN wins).
  struct Motion {
    double max_v2 = 0.0, max_x2 = 0.0, worst_live = 0.0;
  };
  // The law of motion (motion::step_ball, advance_balls's) on the records over Δt = dt [s], with the
  // inertial masses and inertias given (density scaling) or the real ones (nullptr); write_columns:
  // the BallStore's columns too. Each thread moves the balls of its share of the work (`shares`, one
  // per thread, or equal ones). live: measure each ball's travel since at_live [m].
  Motion advance(BallStore& balls, const Vec3& gravity, double alpha, double dt, const double* inertial_mass,
                 const double* inertial_inertia, bool write_columns, const std::vector<double>& shares, bool live,
                 const Vec3* at_live);

  // The largest squared travel of any ball [m²] since at_build (first) and since at_live (second,
  // if live; else 0), from the records when the columns lag behind them. A NaN wins: it asks for a
  // rebuild, which ends the run. Parallel: a maximum does not depend on the order.
  std::pair<double, double> largest_travel2(const BallStore& balls, const Vec3* at_build, bool live,
                                            const Vec3* at_live) const;

  // The sums [N], [N m]: written by the force pass, read by the law of motion while current.
  motion::ContactSums* sums() { return sums_.data(); }
  // Sized for n balls and not current, before a force pass adds them up.
  void begin_sums(std::size_t n) {
    if (sums_.size() != n) sums_.resize(n);
    sums_current_ = false;
  }
  // Every share added: current, and the columns lag behind them.
  void end_sums() {
    sums_current_ = true;
    sum_columns_stale_ = true;
  }
  // The sums for the law of motion of n balls, or nullptr when the columns hold them.
  const motion::ContactSums* contact_sums(std::size_t n) const {
    return sums_current_ && sums_.size() == n ? sums_.data() : nullptr;
  }
  // Forces to be recomputed: the law of motion reads the columns until the next pass.
  void invalidate_sums() { sums_current_ = false; }
  // The columns hold the sums (restored with them).
  void forget_sums() {
    sums_current_ = false;
    sum_columns_stale_ = false;
  }
  // The BallStore's contact_force and contact_moment columns from the sums, if they lag.
  void sync_sum_columns(BallStore& balls);

 private:
  std::vector<BallKin> kin_;
  bool current_ = false;
  bool columns_stale_ = false;
  std::vector<motion::ContactSums> sums_;
  bool sums_current_ = false;
  bool sum_columns_stale_ = false;
  // Within one cycle() call nothing but a controller changes the applied loads, and a controller
  // drops the records: applied_zero_ (every applied force and moment is +0.0: step_ball<false>)
  // holds until drop().
  bool applied_known_ = false, applied_zero_ = false;
};

}  // namespace hilldem
