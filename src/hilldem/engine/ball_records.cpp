#include "hilldem/engine/ball_records.hpp"

#include <omp.h>

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

void BallRecords::fill(const BallStore& balls, bool state, bool terms) {
  const std::size_t n = balls.size();
  kin_.resize(n);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    BallKin& k = kin_[i];
    if (state) {
      k.position = balls.position[i];
      k.velocity = balls.velocity[i];
      k.spin = balls.spin[i];
      k.mass = balls.mass[i];
      k.inertia = balls.inertia[i];
    }
    k.radius = balls.radius[i];
    if (terms) k.terms = hill_body_terms(balls.radius[i], balls.young_mod[i], balls.pois_ratio[i], balls.mass[i]);
  }
  current_ = true;
}

void BallRecords::sync_columns(BallStore& balls) {
  sync_sum_columns(balls);
  if (!columns_stale_) return;
  const std::size_t n = std::min(balls.size(), kin_.size());  // (the same, while the columns lag)
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    balls.position[i] = kin_[i].position;
    balls.velocity[i] = kin_[i].velocity;
    balls.spin[i] = kin_[i].spin;
  }
  columns_stale_ = false;
}

void BallRecords::sync_sum_columns(BallStore& balls) {
  if (!sum_columns_stale_) return;
  const std::size_t n = std::min(balls.size(), sums_.size());
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    motion::store(balls.contact_force[i], sums_[i].force);
    motion::store(balls.contact_moment[i], sums_[i].moment);
  }
  sum_columns_stale_ = false;
}

BallRecords::Motion BallRecords::advance(BallStore& balls, const Vec3& gravity_in, double alpha, double dt,
                                         const double* inertial_mass, const double* inertial_inertia,
                                         bool write_columns, const std::vector<double>& shares, bool live,
                                         const Vec3* at_live) {
  using namespace motion;
  const std::size_t n = balls.size();
  const V4 gravity = load(gravity_in);
  if (!applied_known_) {  // (once per cycle() call: nothing changes them until then)
    const auto zero = [](const std::vector<Vec3>& v) {
      const Vec3 z{};
      return std::all_of(v.begin(), v.end(), [&z](const Vec3& x) { return std::memcmp(&x, &z, sizeof z) == 0; });
    };
    applied_zero_ = zero(balls.applied_force) && zero(balls.applied_moment);
    applied_known_ = true;
  }
  BallKin* kin = kin_.data();
  const motion::ContactSums* sums = contact_sums(n);
  // [m²/s²], [m²], [m²] (a NaN wins: see Simulation::rebuild_if_needed)
  double max_v2 = 0.0, max_x2 = 0.0, worst_live = 0.0;
  // Each thread's balls: in proportion to the threads' shares of the force pass, so that a thread on
  // a slower core is not the one every other waits for. Which thread moves a ball changes no result.
  auto pass = [&](auto applied) {
#pragma omp parallel if (n > kParallelMin)
    {
      double mine_v2 = 0.0, mine_x2 = 0.0, mine_live = 0.0;
      const auto threads = static_cast<std::size_t>(omp_get_num_threads());
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      std::size_t i0 = n * t / threads, i1 = n * (t + 1) / threads;
      if (shares.size() == threads) {
        double before = 0.0;
        for (std::size_t s = 0; s < t; ++s) before += shares[s];
        const auto at = [n](double f) { return static_cast<std::size_t>(static_cast<double>(n) * std::clamp(f, 0.0, 1.0)); };
        i0 = t == 0 ? 0 : at(before);
        i1 = t + 1 == threads ? n : at(before + shares[t]);
      }
      for (std::size_t i = i0; i < i1; ++i) {
        BallKin& k = kin[i];
        V4 x = load(k.position), v = load(k.velocity), w = load(k.spin);
        const V4 cf = sums ? sums[i].force : load(balls.contact_force[i]);
        const V4 cm = sums ? sums[i].moment : load(balls.contact_moment[i]);
        step_ball<decltype(applied)::value>(balls, i, gravity, alpha, dt, k.mass, k.inertia, inertial_mass,
                                            inertial_inertia, cf, cm, x, v, w);
        store(k.velocity, v);
        store(k.spin, w);
        store(k.position, x);
        if (write_columns) {
          store(balls.velocity[i], v);
          store(balls.spin[i], w);
          store(balls.position[i], x);
        }
        const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        const double x2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        if (!(v2 <= mine_v2)) mine_v2 = v2;
        if (!(x2 <= mine_x2)) mine_x2 = x2;
        if (live) {
          const double l2 = norm2(k.position - at_live[i]);
          if (!(l2 <= mine_live)) mine_live = l2;
        }
      }
#pragma omp critical(hilldem_record_motion)
      {
        if (!(mine_v2 <= max_v2)) max_v2 = mine_v2;
        if (!(mine_x2 <= max_x2)) max_x2 = mine_x2;
        if (!(mine_live <= worst_live)) worst_live = mine_live;
      }
    }
  };
  // Without the applied loads' 48 bytes a ball when all are zero.
  if (applied_zero_) pass(std::false_type{});
  else pass(std::true_type{});
  columns_stale_ = !write_columns;
  return {max_v2, max_x2, worst_live};
}

std::pair<double, double> BallRecords::largest_travel2(const BallStore& balls, const Vec3* at_build, bool live,
                                                       const Vec3* at_live) const {
  const std::size_t n = balls.size();
  const bool from_records = columns_stale();
  double worst = 0.0, worst_live = 0.0;
#pragma omp parallel if (n > kParallelMin)
  {
    double mine = 0.0, mine_live = 0.0;
#pragma omp for schedule(static) nowait
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3& x = from_records ? kin_[i].position : balls.position[i];
      const double d2 = norm2(x - at_build[i]);
      if (!(d2 <= mine)) mine = d2;  // (not std::max, which would drop a NaN)
      if (live) {
        const double l2 = norm2(x - at_live[i]);
        if (!(l2 <= mine_live)) mine_live = l2;
      }
    }
#pragma omp critical(hilldem_largest_travel)
    {
      if (!(mine <= worst)) worst = mine;
      if (!(mine_live <= worst_live)) worst_live = mine_live;
    }
  }
  return {worst, worst_live};
}

}  // namespace hilldem
