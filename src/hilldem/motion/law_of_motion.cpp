#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

namespace {
// F_d(i) = −α |F(i)| sign(V(i)) (spec §4), then ΔV = (F + F_d)/m Δt.
inline double damped(double f, double v, double alpha) {
  const double sign = v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
  return f - alpha * std::abs(f) * sign;
}
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
      if (!(fix & (1u << d))) v[d] += damped(f[d], v[d], alpha) * inv_m * dt;
      if (!(fix & (1u << (d + 3)))) w[d] += damped(mo[d], w[d], alpha) * inv_i * dt;
    }
    balls.position[i] += v * dt;
  }
}

}  // namespace hilldem
