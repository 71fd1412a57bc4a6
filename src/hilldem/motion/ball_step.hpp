// The law of motion of one ball (spec §4), shared by the two loops that apply it: advance_balls over
// the BallStore's columns, and the engine's pass over its ball records (Simulation, unwatched steps).
// One function, so both give the same bits by construction.
//
// It works on the three components as one vector (a fourth lane is computed and never stored), so
// that the damping signs and fixity selects stay in vector registers. Each lane does exactly the
// scalar arithmetic.
#pragma once

#include <cstdint>

#include "hilldem/bodies/ball_store.hpp"

namespace hilldem::motion {

using V4 = double __attribute__((vector_size(32)));
using M4 = std::int64_t __attribute__((vector_size(32)));
HILLDEM_INLINE V4 load(const Vec3& v) { return V4{v.x, v.y, v.z, 0.0}; }
HILLDEM_INLINE void store(Vec3& v, V4 x) { v.x = x[0], v.y = x[1], v.z = x[2]; }

// A ball's contact force and moment sums [N], [N m] as the force pass adds them up (Simulation): one
// cache line, each vector's fourth lane +0.0, so that a row's share into a ball is one vector
// operation per sum.
struct alignas(64) ContactSums {
  V4 force, moment;
};

// F + F_d with F_d(i) = −α |F(i)| sign(V(i)) per lane (spec §4). Without branches: in a bed at rest
// the signs of the velocity components are random, and a branch on each was mispredicted about every
// other time. sign ∈ {1, −1, 0} exactly (a true comparison is −1 in its lane).
HILLDEM_INLINE V4 damped(V4 f, V4 v, double alpha) {
  const V4 sign = __builtin_convertvector(v < 0.0, V4) - __builtin_convertvector(v > 0.0, V4);
  const M4 magnitude = ~M4{} ^ (M4{} + INT64_MIN);  // all bits but the sign bit
  const V4 abs_f = (V4)((M4)f & magnitude);
  return f - alpha * abs_f * sign;
}
// v + dv in the lanes that are not fixed; v itself, bit for bit, in those that are.
HILLDEM_INLINE V4 unless_fixed(M4 fixed, V4 v, V4 dv) { return (V4)(((M4)v & fixed) | ((M4)(v + dv) & ~fixed)); }
// Per three bits of a fixity mask (velocity: bits 0-2, spin: bits 3-5), the lanes as all-ones
// (fixed) or zero: one load instead of a dozen shifts and inserts per ball.
struct FixedLanes {
  alignas(32) std::int64_t lanes[8][4];
  constexpr FixedLanes() : lanes{} {
    for (int bits = 0; bits < 8; ++bits)
      for (int d = 0; d < 3; ++d) lanes[bits][d] = (bits >> d) & 1 ? -1 : 0;
  }
};
inline constexpr FixedLanes kFixedLanes;
HILLDEM_INLINE M4 fixed_lanes(FixityMask fix, int d0) {
  M4 m;
  __builtin_memcpy(&m, kFixedLanes.lanes[(fix >> d0) & 7], sizeof m);
  return m;
}

// Ball i's velocity v and spin w from t−Δt/2 to t+Δt/2 with its forces at t (the sums of its contact
// forces and moments, m g, the applied loads), then its position x to t+Δt. x, v and w come in and
// go out through the caller (a column or a record), and so do the contact sums and the mass m [kg]
// and inertia I [kg m²] (m g uses m); inertial_mass/inertial_inertia: density scaling's, or null. kApplied = false: every applied force
// and moment is known to be +0.0 (bit for bit), and +0.0 is added in their place, the same sums
// without their two loads.
template <bool kApplied = true>
HILLDEM_INLINE void step_ball(const BallStore& balls, std::size_t i, V4 gravity, double alpha, double dt, double mass,
                              double inertia, const double* inertial_mass, const double* inertial_inertia,
                              V4 contact_force, V4 contact_moment, V4& x, V4& v, V4& w) {
  const FixityMask fix = balls.fixity[i];
  // unbalanced_force(), unbalanced_moment()
  const V4 applied_f = kApplied ? load(balls.applied_force[i]) : V4{};
  const V4 applied_m = kApplied ? load(balls.applied_moment[i]) : V4{};
  const V4 f = contact_force + gravity * mass + applied_f;
  const V4 mo = contact_moment + applied_m;
  const double inv_m = 1.0 / (inertial_mass ? inertial_mass[i] : mass);
  const double inv_i = 1.0 / (inertial_inertia ? inertial_inertia[i] : inertia);
  // ΔV = (F + F_d)/m Δt, then x += V Δt (velocities at half steps)
  v = unless_fixed(fixed_lanes(fix, 0), v, damped(f, v, alpha) * inv_m * dt);
  w = unless_fixed(fixed_lanes(fix, 3), w, damped(mo, w, alpha) * inv_i * dt);
  x = x + v * dt;
}

}  // namespace hilldem::motion
