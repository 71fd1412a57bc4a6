#include "hilldem/motion/law_of_motion.hpp"

#include "hilldem/core/select.hpp"

namespace hilldem {

namespace {
// F_d(i) = −α |F(i)| sign(V(i)) (spec §4), then ΔV = (F + F_d)/m Δt.
// Written without branches: in a bed at rest the signs of the velocity components are random, and a
// branch on each of them was mispredicted about every other time (advance_balls took 17 % of an
// in-cache step, perf). Same values: sign ∈ {1, −1, 0} exactly as before.
// (GCC turns a ?: between doubles into a branch: core/select.hpp.)
inline double damped(double f, double v, double alpha) {
  const double sign = static_cast<double>(v > 0.0) - static_cast<double>(v < 0.0);
  return f - alpha * std::abs(f) * sign;
}
// v + Δv unless the component is fixed.
inline double unless_fixed(bool fixed, double v, double dv) { return select_bits(fixed, v, v + dv); }
}  // namespace

void advance_balls(BallStore& balls, const MotionSettings& s, double dt, const double* inertial_mass,
                   const double* inertial_inertia) {
  const double alpha = s.local_damping;
  const std::size_t n = balls.size();
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    const FixityMask fix = balls.fixity[i];
    const Vec3 f = unbalanced_force(balls, i, s.gravity);
    const Vec3 mo = unbalanced_moment(balls, i);
    const double inv_m = 1.0 / (inertial_mass ? inertial_mass[i] : balls.mass[i]);
    const double inv_i = 1.0 / (inertial_inertia ? inertial_inertia[i] : balls.inertia[i]);
    Vec3& v = balls.velocity[i];
    Vec3& w = balls.spin[i];
    for (int d = 0; d < 3; ++d) {
      v[d] = unless_fixed(fix & (1u << d), v[d], damped(f[d], v[d], alpha) * inv_m * dt);
      w[d] = unless_fixed(fix & (1u << (d + 3)), w[d], damped(mo[d], w[d], alpha) * inv_i * dt);
    }
    balls.position[i] += v * dt;
  }
}

}  // namespace hilldem
