// Linear contact model as PFC uses it for the comparison and for ball-facet contacts (spec §3):
// deformability method k_n = A E*/L, k_s = k_n/κ*, Coulomb friction, incremental shear, no tension,
// no moment, no dashpots. A pure function of (params, mapping, kinematics, previous state): one
// template over the lane type R (models/lanes.hpp), linear_law, and its one-contact form linear_force.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {

struct LinearParams {
  double emod = 0.0;    // E* [Pa], effective modulus of the deformability method, [0, ∞)
  double kratio = 1.0;  // κ* [-], normal-to-shear stiffness ratio, (0, ∞)
  double fric = 0.0;    // μ [-], friction coefficient, [0, ∞)
  double rolling_fric = 0.0;  // μ_r [-], rolling-resistance coefficient, [0, ∞): rrlinear only (models/rrlinear.hpp)
};

struct LinearMapping {
  double kn = 0.0;  // k_n [N/m]
  double ks = 0.0;  // k_s [N/m]
};

// Spec §3: A = π r̄², r̄ = min(R1, R2) and L = R1 + R2 for ball-ball; r̄ = L = R for ball-wall
// (pass r2 = 0 for a wall).
inline LinearMapping linear_mapping(const LinearParams& p, double r1, double r2) {
  const double rbar = r2 > 0.0 ? std::min(r1, r2) : r1;
  const double length = r1 + r2;
  const double kn = std::numbers::pi * rbar * rbar * p.emod / length;
  return {kn, kn / p.kratio};
}

// What the law reads of one contact (R = double) or of a pack of lanes (R = lanes::Pack).
template <class R> struct LinearInput {
  R kn, ks;                  // k_n, k_s [N/m]
  R fric;                    // μ [-]
  lanes::V3<R> normal;       // n̂_c
  R gap;                     // g_c [m]
  lanes::V3<R> shear_rate;   // δ̇_s [m/s]
  double dt;                 // Δt [s]
  lanes::V3<R> shear_force;  // F_s of the last step, carried into the current plane [N] (§1.3)
};

template <class R> struct LinearOutput {
  R normal_force;            // F_n [N], compression positive
  R trial_shear;             // |F*_s| [N] before the Coulomb clamp
  lanes::V3<R> shear_force;  // F_s [N] on piece 2, carried to the next step
  lanes::V3<R> force;        // F_c = F_n n̂ + F_s [N], on piece 2
  lanes::Mask<R> active;     // overlapping
};

// Spec §3, every branch a select: inactive (no overlap) gives no force and resets the shear force
// (reference gap 0, no tension).
template <class R> HILLDEM_INLINE LinearOutput<R> linear_law(const LinearInput<R>& in) {
  using namespace lanes;
  const R zero = splat<R>(0.0);
  const V3<R> none{zero, zero, zero};
  const R overlap = -in.gap;
  const Mask<R> active = overlap > zero;
  const R normal = in.kn * overlap;
  const V3<R> trial = in.shear_force - in.shear_rate * (in.ks * in.dt);  // F*_s = F_s,o − k_s Δδ_s
  const R limit = in.fric * normal;
  const R mag = norm(trial);
  const V3<R> shear = select(mag <= limit, trial, trial * (limit / mag));
  const V3<R> force = in.normal * normal + shear;
  return {select(active, normal, zero), select(active, mag, zero), select(active, shear, none),
          select(active, force, none), active};
}

struct LinearState {
  Vec3 shear_force;  // F_s [N] on piece 2, in the current contact plane
};

struct LinearResult {
  double normal_force = 0.0;  // F_n [N], compression positive
  Vec3 shear_force;           // F_s [N] on piece 2
  double trial_shear = 0.0;   // |F*_s| [N] before the Coulomb clamp
  Vec3 force;                 // F_c = F_n n̂ + F_s [N], on piece 2
  bool active = false;
  LinearState state;
};

// linear_law for one contact. previous.shear_force must already be carried into the current plane
// (carry_into_plane).
HILLDEM_INLINE LinearResult linear_force(const LinearParams& p, const LinearMapping& m, const ContactKinematics& k,
                                         const LinearState& previous) {
  const LinearOutput<double> o = linear_law<double>({m.kn, m.ks, p.fric, lanes::v3(k.normal), k.gap,
                                                     lanes::v3(k.shear_rate()), k.dt, lanes::v3(previous.shear_force)});
  LinearResult r;
  r.normal_force = o.normal_force;
  r.shear_force = lanes::vec3(o.shear_force);
  r.trial_shear = o.trial_shear;
  r.force = lanes::vec3(o.force);
  r.active = o.active;
  r.state.shear_force = r.shear_force;
  return r;
}

}  // namespace hilldem
