#include "hilldem/motion/rigid_body.hpp"

#include <cmath>

#include "hilldem/motion/ball_step.hpp"
#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

namespace {

Vec3 to_vec(motion::V4 v) { return {v[0], v[1], v[2]}; }

Vec3 divide(const Vec3& a, const Vec3& b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
Vec3 times(const Vec3& a, const Vec3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }

// The free body turned about its principal axis k by φ = L_k / I_k τ [rad]: q ← q exp(φ e_k), and
// the body-frame L by −φ about e_k, so that the global L stays.
void turn_about(Quat& q, Vec3& lb, const Vec3& inertia, int k, double tau) {
  const double phi = lb[k] / inertia[k] * tau;
  const double ch = std::cos(0.5 * phi), sh = std::sin(0.5 * phi);
  Quat r{ch, 0.0, 0.0, 0.0};
  (k == 0 ? r.x : k == 1 ? r.y : r.z) = sh;
  q = q * r;
  const double c = ch * ch - sh * sh, s = 2.0 * sh * ch;
  const int a = (k + 1) % 3, b = (k + 2) % 3;
  const double la = lb[a], lbb = lb[b];
  const double na = c * la + s * lbb, nb = -s * la + c * lbb;
  // c² + s² = 1 only to rounding, and its error has a sign: over 1e5 steps × 6 turns it would
  // drift |L| by about 1e-11 relative. The turn keeps L_a² + L_b²; so does this.
  const double n0 = la * la + lbb * lbb, n1 = na * na + nb * nb;
  const double f = n1 > 0.0 ? std::sqrt(n0 / n1) : 1.0;
  lb[a] = na * f;
  lb[b] = nb * f;
}

}  // namespace

void step_clump(ClumpState& s, std::size_t i, const Vec3& force, const Vec3& torque, const RigidMotionSettings& m,
                double dt) {
  using namespace motion;
  const FixityMask fix = s.fixity[i];
  const double alpha = m.local_damping;
  // Translation: step_ball's arithmetic (F = force + m g; ΔV = (F + F_d)/m Δt; x += V Δt).
  {
    const V4 f = load(force) + load(m.gravity) * s.mass[i];
    V4 v = load(s.velocity[i]);
    v = unless_fixed(fixed_lanes(fix, 0), v, damped(f, v, alpha) * (1.0 / s.mass[i]) * dt);
    store(s.velocity[i], v);
    store(s.position[i], load(s.position[i]) + v * dt);
  }
  const Vec3 in = s.principal_inertia[i];
  Quat& q = s.orientation[i];
  const V4 mo = load(torque), w = load(s.spin[i]);
  const V4 damped_torque = damped(mo, w, alpha);  // M + M_d, global
  const bool spherical = in.x == in.y && in.y == in.z;
  const bool all_spins_fixed = (fix & kFixSpin) == kFixSpin;
  if (spherical || all_spins_fixed) {
    // The ball's spin update (exact for isotropic inertia; a fixed spin keeps its bits), then the
    // rotation by the constant ω over Δt.
    const V4 w_new = unless_fixed(fixed_lanes(fix, 3), w, damped_torque * (1.0 / in.x) * dt);
    store(s.spin[i], w_new);
    q = integrate_global(q, s.spin[i], dt);
    s.body_momentum[i] = times(in, rotate(conjugate(q), s.spin[i]));
    return;
  }
  // Kick: L(t + Δt/2) = L(t − Δt/2) + (M + M_d) Δt, global.
  Vec3 l = rotate(q, s.body_momentum[i]) + to_vec(damped_torque) * dt;
  Vec3 lb = rotate(conjugate(q), l);
  if (fix & kFixSpin) {
    // Impose the fixed global components of ω at the orientation at t.
    Vec3 omega = rotate(q, divide(lb, in));
    for (int d = 0; d < 3; ++d)
      if (fix & (1u << (3 + d))) omega[d] = s.spin[i][d];
    lb = times(in, rotate(conjugate(q), omega));
  }
  // Drift: R3(Δt/2) R2(Δt/2) R1(Δt/2) | ω(t + Δt/2) | R1(Δt/2) R2(Δt/2) R3(Δt/2).
  const double h = 0.5 * dt;
  turn_about(q, lb, in, 2, h);
  turn_about(q, lb, in, 1, h);
  turn_about(q, lb, in, 0, h);
  Vec3 omega_mid = rotate(q, divide(lb, in));
  turn_about(q, lb, in, 0, h);
  turn_about(q, lb, in, 1, h);
  turn_about(q, lb, in, 2, h);
  q = normalized(q);
  for (int d = 0; d < 3; ++d)
    if (fix & (1u << (3 + d))) omega_mid[d] = s.spin[i][d];
  s.spin[i] = omega_mid;
  s.body_momentum[i] = lb;
}

void advance_clumps(ClumpState& s, const std::vector<Vec3>& force, const std::vector<Vec3>& torque,
                    const RigidMotionSettings& m, double dt) {
  const std::size_t n = s.size();
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) step_clump(s, i, force[i], torque[i], m, dt);
}

}  // namespace hilldem
