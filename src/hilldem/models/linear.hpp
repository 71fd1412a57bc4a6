// Linear contact model as PFC uses it for the comparison and for ball-facet contacts (spec §3):
// deformability method k_n = A E*/L, k_s = k_n/κ*, Coulomb friction, incremental shear, no tension,
// no moment, no dashpots. A pure function of (params, mapping, kinematics, previous state).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "hilldem/contact/contact_kinematics.hpp"

namespace hilldem {

struct LinearParams {
  double emod = 0.0;    // E* [Pa], effective modulus of the deformability method, [0, ∞)
  double kratio = 1.0;  // κ* [-], normal-to-shear stiffness ratio, (0, ∞)
  double fric = 0.0;    // μ [-], friction coefficient, [0, ∞)
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

// previous.shear_force must already be carried into the current plane (carry_into_plane).
HILLDEM_INLINE LinearResult linear_force(const LinearParams& p, const LinearMapping& m, const ContactKinematics& k,
                                 const LinearState& previous) {
  LinearResult r;
  const double overlap = k.overlap();
  if (overlap <= 0.0) return r;  // inactive: reference gap 0, no tension, shear reset
  r.active = true;
  r.normal_force = m.kn * overlap;
  const Vec3 trial = previous.shear_force - k.shear_rate() * (m.ks * k.dt);  // F*_s = F_s,o − k_s Δδ_s
  const double limit = p.fric * r.normal_force;
  const double mag = norm(trial);
  r.trial_shear = mag;
  r.shear_force = mag <= limit ? trial : trial * (limit / mag);
  r.force = k.normal * r.normal_force + r.shear_force;
  r.state.shear_force = r.shear_force;
  return r;
}

}  // namespace hilldem
