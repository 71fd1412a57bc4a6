// Rolling-resistance linear model (PFC's "rrlinear"), docs/spec/rrlinear.md: the linear model of
// spec §3 (k_n, k_s, μ, no tension) plus a rolling-resistance moment M_r in the contact plane, a
// spring k_r = k_s R̄² on the relative bend rotation, limited by μ_r R̄ F_n. A pure function of
// (params, mapping, kinematics, previous state), written once over the lane type R (models/lanes.hpp).
#pragma once

#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/lanes.hpp"
#include "hilldem/models/linear.hpp"

namespace hilldem {

// R̄ [m] of rrlinear (docs/spec/rrlinear.md, Eq. R1): 1/R̄ = 1/R1 + 1/R2 between balls, R̄ = R1 with a
// wall (pass r2 = 0).
HILLDEM_INLINE double rrlinear_radius(double r1, double r2) { return r2 > 0.0 ? r1 * r2 / (r1 + r2) : r1; }

template <class R> struct RollingInput {
  R rr_fric;                 // μ_r [-]
  R radius;                  // R̄ [m]
  R ks;                      // k_s [N/m]
  lanes::V3<R> normal;       // n̂_c
  lanes::V3<R> rel_spin;     // ω2 − ω1 [rad/s]
  double dt;                 // Δt [s]
  lanes::V3<R> moment;       // M_r of the last step, carried into the current plane [N m] (§1.3)
  R normal_force;            // F_n [N] of this step (linear_law)
  lanes::Mask<R> active;     // overlapping
};

template <class R> struct RollingOutput {
  lanes::V3<R> moment;  // M_r [N m] on piece 2 (−M_r on piece 1), carried to the next step; zero if inactive
  R trial;              // |M_r*| [N m] before the limit
};

// Eqs. R2-R4: the bend part of the relative rotation over the step, Δθ_b = (ω2 − ω1 − n̂ (n̂·(ω2 − ω1))) Δt
// (the twist about n̂ is not resisted); the trial M*_r = M_r − k_r Δθ_b with k_r = k_s R̄²; the limit
// |M_r| ≤ μ_r R̄ F_n (the direction of the trial kept).
template <class R> HILLDEM_INLINE RollingOutput<R> rolling_moment(const RollingInput<R>& in) {
  using namespace lanes;
  const R zero = splat<R>(0.0);
  const V3<R> none{zero, zero, zero};
  const V3<R> bend = in.rel_spin - in.normal * dot(in.rel_spin, in.normal);   // [rad/s]
  const R k_roll = in.ks * in.radius * in.radius;                            // k_r [N m/rad]
  const V3<R> trial = in.moment - bend * (k_roll * in.dt);                   // Eq. R3
  const R limit = in.rr_fric * in.radius * in.normal_force;                  // Eq. R4
  const R mag = norm(trial);
  const V3<R> m = select(mag <= limit, trial, trial * (limit / mag));
  return {select(in.active, m, none), select(in.active, mag, zero)};
}

struct RrLinearState {
  Vec3 shear_force;  // F_s [N] on piece 2, in the current contact plane
  Vec3 moment;       // M_r [N m] on piece 2, in the current contact plane
};

struct RrLinearResult {
  LinearResult linear;  // the force part (spec §3)
  Vec3 moment;          // M_r [N m] on piece 2 (−M_r on piece 1)
  double trial_moment = 0.0;  // |M*_r| [N m]
};

// One contact. previous.shear_force and previous.moment must already be carried into the current
// plane (carry_into_plane); rel_spin = ω2 − ω1 [rad/s]; radius = R̄ (rrlinear_radius) [m].
HILLDEM_INLINE RrLinearResult rrlinear_force(const LinearParams& p, const LinearMapping& m, const ContactKinematics& k,
                                             const RrLinearState& previous, const Vec3& rel_spin, double radius) {
  RrLinearResult r;
  r.linear = linear_force(p, m, k, LinearState{previous.shear_force});
  const RollingOutput<double> o = rolling_moment<double>({p.rolling_fric, radius, m.ks, lanes::v3(k.normal),
                                                          lanes::v3(rel_spin), k.dt, lanes::v3(previous.moment),
                                                          r.linear.normal_force, r.linear.active});
  r.moment = lanes::vec3(o.moment);
  r.trial_moment = o.trial;
  return r;
}

}  // namespace hilldem
