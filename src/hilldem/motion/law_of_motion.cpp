#include "hilldem/motion/law_of_motion.hpp"

#include <cstdint>

namespace hilldem {

namespace {
// The law of motion of one ball as a few vector operations on its three components (a fourth lane
// is computed and never stored): the scalar version ran three chains per vector with their damping
// signs and fixity selects through integer registers, 185 instructions per ball (callgrind). Each
// lane does exactly the scalar arithmetic, so the results are the same bits.
using V4 = double __attribute__((vector_size(32)));
using M4 = std::int64_t __attribute__((vector_size(32)));
HILLDEM_INLINE V4 load(const Vec3& v) { return V4{v.x, v.y, v.z, 0.0}; }
HILLDEM_INLINE void store(Vec3& v, V4 x) { v.x = x[0], v.y = x[1], v.z = x[2]; }

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
constexpr FixedLanes kFixedLanes;
HILLDEM_INLINE M4 fixed_lanes(FixityMask fix, int d0) {
  M4 m;
  __builtin_memcpy(&m, kFixedLanes.lanes[(fix >> d0) & 7], sizeof m);
  return m;
}
}  // namespace

void advance_balls(BallStore& balls, const MotionSettings& s, double dt, const double* inertial_mass,
                   const double* inertial_inertia) {
  const double alpha = s.local_damping;
  const std::size_t n = balls.size();
  const V4 gravity = load(s.gravity);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    const FixityMask fix = balls.fixity[i];
    // unbalanced_force(), unbalanced_moment()
    const V4 f = load(balls.contact_force[i]) + gravity * balls.mass[i] + load(balls.applied_force[i]);
    const V4 mo = load(balls.contact_moment[i]) + load(balls.applied_moment[i]);
    const double inv_m = 1.0 / (inertial_mass ? inertial_mass[i] : balls.mass[i]);
    const double inv_i = 1.0 / (inertial_inertia ? inertial_inertia[i] : balls.inertia[i]);
    const V4 v0 = load(balls.velocity[i]), w0 = load(balls.spin[i]);
    // ΔV = (F + F_d)/m Δt, then x += V Δt (velocities at half steps)
    const V4 v = unless_fixed(fixed_lanes(fix, 0), v0, damped(f, v0, alpha) * inv_m * dt);
    const V4 w = unless_fixed(fixed_lanes(fix, 3), w0, damped(mo, w0, alpha) * inv_i * dt);
    store(balls.velocity[i], v);
    store(balls.spin[i], w);
    store(balls.position[i], load(balls.position[i]) + v * dt);
  }
}

}  // namespace hilldem
