// Hill contact model (PFC 6, version 4), spec ../docs/spec/hill-model.md §2: Hertz-Mindlin springs
// with Tsuji dashpots, Coulomb friction, an incremental shear update with the current stiffness and a
// suction-driven liquid-bridge moisture force that ruptures past a critical gap.
// Pure functions only: (params, mapping, kinematics, previous state) -> (force, new state).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "hilldem/contact/contact_kinematics.hpp"

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

// Table 4 mappings from the sums of the two bodies' terms (t1 + t2, field by field); r_o = min(R1, R2) [m].
HILLDEM_INLINE HillMapping hill_mapping_of_sums(const HillParams& p, const HillBodyTerms& sum, double r_o) {
  HillMapping m;
  m.eff_radius = 1.0 / sum.inv_radius;
  m.eff_young = 1.0 / sum.normal;
  m.eff_shear = 1.0 / sum.shear;
  m.eff_mass = 1.0 / sum.inv_mass;
  const double sqrt_re = std::sqrt(m.eff_radius);
  m.kn = 4.0 / 3.0 * m.eff_young * sqrt_re;
  m.ks = 8.0 * m.eff_shear * sqrt_re;
  m.bn = p.damp_con * std::sqrt(m.eff_mass * m.kn);
  m.bs = p.damp_con * std::sqrt(m.eff_mass * m.ks);
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

// Eq. 12 [R]: moisture force [N] (≤ 0, suction) of a wet contact at gap g [m].
HILLDEM_INLINE double hill_moisture_force(double suction, double r_o, double gap) {
  const double f_max = -suction * std::numbers::pi * r_o * r_o;  // F^m_max = −ψ π R_o²
  const double s_cr = kHillCriticalGapFactor * r_o;
  if (gap <= 0.0) return f_max;
  if (gap < kHillDecayDivisor * s_cr) return f_max * std::exp(-gap / (kHillDecayDivisor * s_cr));
  return 0.0;
}

// Rupture gap 2 s_cr [m]: a wet contact at or beyond it ruptures (M = 1).
HILLDEM_INLINE double hill_rupture_gap(double r_o) { return kHillDecayDivisor * kHillCriticalGapFactor * r_o; }

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

// A hill contact is active if it is wet or overlapping (spec §2.5).
HILLDEM_INLINE bool hill_active(Moisture m, double gap) { return m == Moisture::Wet || gap <= 0.0; }

// Force-displacement law, spec §2.6 steps 1-3. previous.shear_hm must already be carried into the
// current plane (carry_into_plane, §1.3).
HILLDEM_INLINE HillResult hill_force(const HillParams& p, const HillMapping& m, const ContactKinematics& k,
                             const HillState& previous) {
  HillResult r;
  r.state = previous;
  r.active = hill_active(previous.moisture, k.gap);
  if (!r.active) {
    r.state.shear_hm = Vec3{};  // Eq. 16 with F^μ_s = 0 resets it; an inactive contact gives no force
    return r;
  }
  // Step 1, Eq. 12: moisture force and rupture.
  if (previous.moisture == Moisture::Wet) {
    if (k.gap >= hill_rupture_gap(m.r_o)) {
      r.state.moisture = Moisture::Ruptured;  // the bridge breaks: dry, and inactive since g_c > 0
      r.active = false;
      r.state.shear_hm = Vec3{};
      return r;
    } else {
      r.moisture_force = hill_moisture_force(p.suction, m.r_o, k.gap);
    }
  }
  // Step 2, Eq. 13: Hertz normal force + δ^{1/4} dashpot.
  const double overlap = k.overlap();
  const double root2 = overlap > 0.0 ? std::sqrt(overlap) : 0.0;  // δ_o^{1/2}
  const double root4 = std::sqrt(root2);                           // δ_o^{1/4}
  if (overlap > 0.0) r.surface_normal = m.kn * overlap * root2 + m.bn * root4 * (-k.normal_rate());
  // Step 3, Eqs. 14-18: shear.
  const double strength = std::max(0.0, p.fric_coef * r.surface_normal);  // Eq. 14 (+ guard, §2.6)
  const Vec3 shear_rate = k.shear_rate();
  const Vec3 damper = shear_rate * (-m.bs * root4);                        // F^d_s (Eq. 17)
  Vec3 hm = previous.shear_hm - shear_rate * (m.ks * root2 * k.dt);        // Eq. 15
  r.trial_shear = norm(hm + damper);  // reported: the shear force before any Coulomb clamp
  const double hm_mag = norm(hm);
  if (hm_mag > strength) hm = hm_mag > 0.0 ? hm * (strength / hm_mag) : Vec3{};  // Eq. 16
  r.state.shear_hm = hm;
  const Vec3 trial = hm + damper;                                          // Eq. 17
  const double trial_mag = norm(trial);
  if (overlap > 0.0)                                                       // Eq. 18
    r.shear_force = trial_mag <= strength ? trial : trial * (strength / trial_mag);
  r.force = k.normal * (r.surface_normal + r.moisture_force) + r.shear_force;
  return r;
}

struct StiffnessEstimate {
  double kn = 0.0;  // k̂_n [N/m]
  double ks = 0.0;  // k̂_s [N/m]
};

// Eqs. 19-21: tangent stiffnesses for the time-step estimate, inflated for the dashpots.
HILLDEM_INLINE StiffnessEstimate hill_timestep_stiffness(const HillParams& p, const HillMapping& m, double gap) {
  double overlap = -gap;
  if (overlap <= 0.0) overlap = kHillTimestepOverlapFactor * m.r_o;
  const double root2 = std::sqrt(overlap);
  StiffnessEstimate s{1.5 * m.kn * root2, m.ks * root2};                   // Eq. 19
  if (p.damp_con > 0.0) {
    const double xi = p.damp_con / 2.0;                                    // Eq. 21
    const double f = std::sqrt(1.0 + xi * xi) - xi;                        // Eq. 20
    s.kn /= f * f;
    s.ks /= f * f;
  }
  return s;
}

}  // namespace hilldem
