// Hill contact model (PFC 6, version 4), spec ../docs/spec/hill-model.md §2: Hertz-Mindlin springs
// with Tsuji dashpots, Coulomb friction, an incremental shear update with the current stiffness and a
// suction-driven liquid-bridge moisture force that ruptures past a critical gap.
// Pure functions only: (params, mapping, kinematics, previous state) -> (force, new state). The law is
// one template over the lane type R (models/lanes.hpp: double for one contact, Pack for a batch of
// lanes), hill_law; hill_force is its one-contact form over the engine's value types.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {

// Eq. 12 was reconstructed from a garbled memo (spec §2.9). Its two uncertain pieces are named
// constants so that a correction from Tan et al. (2014a/b) is a one-line change:
inline constexpr double kHillCriticalGapFactor = 1.0;   // c_s in s_cr = c_s·R_o  [-]
inline constexpr double kHillDecayDivisor = 2.0;        // exp(−g_c / (2 s_cr)), rupture at 2 s_cr
// Eq. 19: overlap [in units of R_o] at which an open wet contact reports its stiffness (spec §2.8).
inline constexpr double kHillTimestepOverlapFactor = 2.0e-4;

enum class Moisture : std::uint8_t { Dry = 0, Ruptured = 1, Wet = 2 };  // M of spec §2.3

struct HillParams {
  double fric_coef = 0.0;  // μ [-], [0, ∞)
  double damp_con = 0.0;   // γ_h [-], [0, 1)
  double suction = 0.0;    // ψ [Pa], [0, ∞)
};

// Properties of the two bodies a hill mapping needs (spec §2.4).
struct HillBodies {
  double r1 = 0.0, r2 = 0.0;    // R [m]
  double e1 = 0.0, e2 = 0.0;    // E [Pa]
  double nu1 = 0.0, nu2 = 0.0;  // ν [-]
  double m1 = 0.0, m2 = 0.0;    // m [kg] (real masses, even for a fixed body: spec §2.4)
};

// Table 4 mappings (spec §2.4), computed when a contact is created or its properties change.
struct HillMapping {
  double eff_radius = 0.0;  // R_e [m]
  double eff_young = 0.0;   // E_e [Pa]
  double eff_shear = 0.0;   // G_e [Pa]
  double eff_mass = 0.0;    // m_e [kg]
  double kn = 0.0;          // k_n [N/m^{3/2}] = (4/3) E_e √R_e
  double ks = 0.0;          // k_s [N/m^{3/2}] = 8 G_e √R_e
  double bn = 0.0;          // β_n [kg m^{-1/4} s^{-1}] = γ_h √(m_e k_n)
  double bs = 0.0;          // β_s [kg m^{-1/4} s^{-1}] = γ_h √(m_e k_s)
  double r_o = 0.0;         // R_o = min(R1, R2) [m] (Eq. 12)
};

// The per-body terms of the Table 4 mappings: each effective property is the reciprocal of a sum of
// one such term per body, so the force pass can keep them per ball and build a contact's mapping
// every step instead of storing it per contact (memory traffic).
struct HillBodyTerms {
  double inv_radius = 0.0;  // 1/R [1/m]
  double inv_mass = 0.0;    // 1/m [1/kg]
  double normal = 0.0;      // (1 − ν²)/E [1/Pa]
  double shear = 0.0;       // 2 (2 − ν)(1 + ν)/E [1/Pa]
};

HILLDEM_INLINE HillBodyTerms hill_body_terms(double r, double e, double nu, double m) {
  return {1.0 / r, 1.0 / m, (1.0 - nu * nu) / e, 2.0 * (2.0 - nu) * (1.0 + nu) / e};
}

// Table 4 mappings from the sums of the two bodies' terms (t1 + t2, field by field) and γ_h: the
// stiffness and damping coefficients the law reads (R: one contact or a pack of lanes).
template <class R> struct HillCoefficients {
  R kn, ks;  // k_n, k_s [N/m^{3/2}]
  R bn, bs;  // β_n, β_s [kg m^{-1/4} s^{-1}]
};
template <class R>
HILLDEM_INLINE HillCoefficients<R> hill_coefficients(R damp_con, R sum_inv_radius, R sum_inv_mass, R sum_normal,
                                                     R sum_shear) {
  using lanes::sqrt;
  const R eff_radius = 1.0 / sum_inv_radius, eff_young = 1.0 / sum_normal, eff_shear = 1.0 / sum_shear;
  const R eff_mass = 1.0 / sum_inv_mass;
  const R sqrt_re = sqrt(eff_radius);
  const R kn = 4.0 / 3.0 * eff_young * sqrt_re;
  const R ks = 8.0 * eff_shear * sqrt_re;
  return {kn, ks, damp_con * sqrt(eff_mass * kn), damp_con * sqrt(eff_mass * ks)};
}

// Table 4 mappings from the sums of the two bodies' terms (t1 + t2, field by field); r_o = min(R1, R2) [m].
HILLDEM_INLINE HillMapping hill_mapping_of_sums(const HillParams& p, const HillBodyTerms& sum, double r_o) {
  HillMapping m;
  m.eff_radius = 1.0 / sum.inv_radius;
  m.eff_young = 1.0 / sum.normal;
  m.eff_shear = 1.0 / sum.shear;
  m.eff_mass = 1.0 / sum.inv_mass;
  const HillCoefficients<double> c = hill_coefficients(p.damp_con, sum.inv_radius, sum.inv_mass, sum.normal, sum.shear);
  m.kn = c.kn, m.ks = c.ks, m.bn = c.bn, m.bs = c.bs;
  m.r_o = r_o;
  return m;
}

// Table 4 mappings from the two bodies' terms; r_o = min(R1, R2) [m].
HILLDEM_INLINE HillMapping hill_mapping(const HillParams& p, const HillBodyTerms& t1, const HillBodyTerms& t2,
                                        double r_o) {
  return hill_mapping_of_sums(p,
                              {t1.inv_radius + t2.inv_radius, t1.inv_mass + t2.inv_mass, t1.normal + t2.normal,
                               t1.shear + t2.shear},
                              r_o);
}

inline HillMapping hill_mapping(const HillParams& p, const HillBodies& b) {
  return hill_mapping(p, hill_body_terms(b.r1, b.e1, b.nu1, b.m1), hill_body_terms(b.r2, b.e2, b.nu2, b.m2),
                      std::min(b.r1, b.r2));
}

// Rupture gap 2 s_cr [m]: a wet contact at or beyond it ruptures (M = 1).
template <class R> HILLDEM_INLINE R hill_rupture_gap(R r_o) { return kHillDecayDivisor * kHillCriticalGapFactor * r_o; }

// Eq. 12 [R]: moisture force [N] (≤ 0, suction) at gap g [m] where `wet` (and the bridge holds:
// g < 2 s_cr), else 0.
template <class R>
HILLDEM_INLINE R hill_moisture_force(R suction, R r_o, R gap, lanes::Mask<R> wet) {
  using namespace lanes;
  const R zero = splat<R>(0.0);
  const R f_max = -suction * std::numbers::pi * r_o * r_o;  // F^m_max = −ψ π R_o²
  const R s_cr = kHillCriticalGapFactor * r_o;
  const Mask<R> held = gap < kHillDecayDivisor * s_cr;
  const Mask<R> open = gap > zero;
  const R decay = exp_where(wet & held & open, -gap / (kHillDecayDivisor * s_cr));
  return select(wet & held, select(open, f_max * decay, f_max), zero);
}

HILLDEM_INLINE double hill_moisture_force(double suction, double r_o, double gap) {
  return hill_moisture_force<double>(suction, r_o, gap, true);
}

// A hill contact is active if it is wet or overlapping (spec §2.5).
HILLDEM_INLINE bool hill_active(Moisture m, double gap) { return m == Moisture::Wet || gap <= 0.0; }

// What the law reads of one contact (R = double) or of a pack of lanes (R = lanes::Pack).
template <class R> struct HillInput {
  R fric, suction;                    // μ [-], ψ [Pa]
  R kn, ks, bn, bs;                   // the mapping's coefficients (hill_coefficients)
  R r_o;                              // R_o = min(R1, R2) [m]
  lanes::V3<R> normal;                // n̂_c
  R gap;                              // g_c [m]
  R normal_rate;                      // δ̇_n [m/s], > 0 apart
  lanes::V3<R> shear_rate;            // δ̇_s [m/s]
  double dt;                          // Δt [s]
  lanes::V3<R> shear_hm;              // F^h_s of the last step, carried into the current plane [N] (§1.3)
  lanes::Mask<R> wet;                 // M = 2 at the start of the step
};

template <class R> struct HillOutput {
  R surface_normal;          // F^s_n [N], compression positive (may be < 0 from the dashpot)
  R moisture_force;          // F^m [N], ≤ 0
  R trial_shear;             // |F^h*_s + F^d_s| [N]: Eqs. 15 + 17 before any clamp
  lanes::V3<R> shear_force;  // F_s [N] on piece 2 (Eq. 18)
  lanes::V3<R> force;        // F_c = (F^s_n + F^m) n̂ + F_s [N], on piece 2; zero if inactive
  lanes::V3<R> shear_hm;     // F^h_s carried to the next step [N]; zero if inactive
  lanes::Mask<R> active;     // wet, or g_c ≤ 0, after the step (spec §2.5)
  lanes::Mask<R> ruptured;   // the liquid bridge broke this step (M = 1 from now on)
};

// The force-displacement law, spec §2.6 steps 1-3, every branch a select. An inactive contact gives
// no force and forgets its shear force (Eq. 16 with F^μ_s = 0).
template <class R> HILLDEM_INLINE HillOutput<R> hill_law(const HillInput<R>& in) {
  using namespace lanes;
  const R zero = splat<R>(0.0);
  const V3<R> none{zero, zero, zero};
  // Step 1, Eq. 12: rupture and the moisture force.
  const Mask<R> ruptured = in.wet & (in.gap >= hill_rupture_gap(in.r_o));
  const Mask<R> active = (in.wet | (in.gap <= zero)) & (ruptured == Mask<R>{});
  const R moisture = hill_moisture_force(in.suction, in.r_o, in.gap, in.wet);
  // Step 2, Eq. 13: Hertz normal force + δ^{1/4} dashpot.
  const R overlap = -in.gap;
  const Mask<R> touching = overlap > zero;
  const R root2 = select(touching, sqrt(overlap), zero);  // δ_o^{1/2}
  const R root4 = sqrt(root2);                            // δ_o^{1/4}
  const R normal = select(touching, in.kn * overlap * root2 + in.bn * root4 * (-in.normal_rate), zero);
  // Step 3, Eqs. 14-18: shear.
  const R strength = max(zero, in.fric * normal);                    // Eq. 14 (+ guard, §2.6)
  const V3<R> damper = in.shear_rate * (-in.bs * root4);              // F^d_s (Eq. 17)
  V3<R> hm = in.shear_hm - in.shear_rate * (in.ks * root2 * in.dt);  // Eq. 15
  const R trial = norm(hm + damper);  // reported: the shear force before any Coulomb clamp
  const R hm_mag = norm(hm);
  const Mask<R> slips = hm_mag > strength;                            // Eq. 16
  hm = select(slips, select(hm_mag > zero, hm * (strength / hm_mag), none), hm);
  const V3<R> total = hm + damper;                                    // Eq. 17
  const R total_mag = norm(total);
  const V3<R> shear = select(touching, select(total_mag <= strength, total, total * (strength / total_mag)), none);
  const V3<R> force = in.normal * (normal + moisture) + shear;        // Eq. 18 and F_c
  return {select(active, normal, zero), select(active, moisture, zero), select(active, trial, zero),
          select(active, shear, none), select(active, force, none), select(active, hm, none), active, ruptured};
}

struct HillState {
  Vec3 shear_hm;                       // F^h_s [N], Hertz-Mindlin shear force carried between steps
  Moisture moisture = Moisture::Dry;   // M
};

struct HillResult {
  double surface_normal = 0.0;  // F^s_n [N], compression positive (may be < 0 from the dashpot)
  double moisture_force = 0.0;  // F^m [N], ≤ 0
  Vec3 shear_force;             // F_s [N] on piece 2 (Eq. 18)
  double trial_shear = 0.0;     // |F^h*_s + F^d_s| [N]: Eqs. 15 + 17 before any clamp
  Vec3 force;                   // F_c = (F^s_n + F^m) n̂ + F_s [N], on piece 2
  bool active = false;          // wet, or g_c ≤ 0 (spec §2.5)
  HillState state;
};

// hill_law for one contact. previous.shear_hm must already be carried into the current plane
// (carry_into_plane, §1.3).
HILLDEM_INLINE HillResult hill_force(const HillParams& p, const HillMapping& m, const ContactKinematics& k,
                                     const HillState& previous) {
  const Vec3 shear_rate = k.shear_rate();
  const HillOutput<double> o = hill_law<double>({p.fric_coef, p.suction, m.kn, m.ks, m.bn, m.bs, m.r_o,
                                                 lanes::v3(k.normal), k.gap, k.normal_rate(), lanes::v3(shear_rate),
                                                 k.dt, lanes::v3(previous.shear_hm),
                                                 previous.moisture == Moisture::Wet});
  HillResult r;
  r.surface_normal = o.surface_normal;
  r.moisture_force = o.moisture_force;
  r.shear_force = lanes::vec3(o.shear_force);
  r.trial_shear = o.trial_shear;
  r.force = lanes::vec3(o.force);
  r.active = o.active;
  r.state = {lanes::vec3(o.shear_hm), o.ruptured ? Moisture::Ruptured : previous.moisture};
  return r;
}

template <class R> struct HillStiffness {
  R kn, ks;  // k̂_n, k̂_s [N/m]
};

// Eqs. 19-21: tangent stiffnesses for the time-step estimate, inflated for the dashpots; an open
// contact reports those at the overlap kHillTimestepOverlapFactor R_o.
template <class R>
HILLDEM_INLINE HillStiffness<R> hill_stiffness(R damp_con, R kn, R ks, R r_o, R gap) {
  using namespace lanes;
  const R zero = splat<R>(0.0);
  const R overlap = select(-gap <= zero, kHillTimestepOverlapFactor * r_o, -gap);
  const R root2 = sqrt(overlap);
  const R xi = damp_con / 2.0;                                         // Eq. 21
  const R f = sqrt(1.0 + xi * xi) - xi;                                // Eq. 20
  const R f2 = select(damp_con > zero, f * f, splat<R>(1.0));
  return {1.5 * kn * root2 / f2, ks * root2 / f2};                    // Eq. 19
}

struct StiffnessEstimate {
  double kn = 0.0;  // k̂_n [N/m]
  double ks = 0.0;  // k̂_s [N/m]
};

HILLDEM_INLINE StiffnessEstimate hill_timestep_stiffness(const HillParams& p, const HillMapping& m, double gap) {
  const HillStiffness<double> s = hill_stiffness<double>(p.damp_con, m.kn, m.ks, m.r_o, gap);
  return {s.kn, s.ks};
}

}  // namespace hilldem
