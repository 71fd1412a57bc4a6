// ContactKinematics: what the narrow phase hands to a contact model (spec §1.1–1.2). A value
// struct, so that a model is a pure function callable from a unit test, a threaded loop or (later)
// a GPU kernel.
#pragma once

#include "hilldem/core/vec3.hpp"

namespace hilldem {

struct ContactKinematics {
  Vec3 normal;        // n̂_c, unit, from piece 1 to piece 2 (Eq. 2)
  double gap = 0.0;   // g_c [m], < 0 when overlapping (Eq. 3)
  Vec3 rel_velocity;  // δ̇ = ẋ_c(2) − ẋ_c(1) at the contact point [m/s] (§1.2)
  double dt = 0.0;    // Δt [s]

  double overlap() const { return -gap; }                               // δ_o [m]
  double normal_rate() const { return dot(rel_velocity, normal); }      // δ̇_n [m/s], > 0 apart
  Vec3 shear_rate() const { return rel_velocity - normal * normal_rate(); }  // δ̇_s [m/s]
};

// Rotation of the contact plane over one step, spec §1.3: (a) with the change of normal
// n_old -> n_new, (b) about the normal by the mean spin component mean_spin_n = ½(ω1+ω2)·n_new
// [rad/s] over dt [s]. Computed once per contact and step, applied to every stored vector.
struct PlaneRotation {
  Vec3 tilt;      // n_old × n_new
  Vec3 twist;     // n_new ω̄_n Δt
  Vec3 normal;    // n_new
  PlaneRotation(const Vec3& n_old, const Vec3& n_new, double mean_spin_n, double dt)
      : tilt(cross(n_old, n_new)), twist(n_new * (mean_spin_n * dt)), normal(n_new) {}
  // (a) and (b) only: first-order rotation, no renormalisation (used for reported quantities).
  HILLDEM_INLINE Vec3 rotate(const Vec3& f) const {
    const Vec3 g = f - cross(f, tilt);
    return g - cross(g, twist);
  }
  // (a), (b) and (c): drop any residual normal part and restore the magnitude (stored forces).
  HILLDEM_INLINE Vec3 carry(const Vec3& f) const {
    const double mag2 = norm2(f);
    if (mag2 == 0.0) return f;
    Vec3 g = rotate(f);
    g = g - normal * dot(g, normal);
    const double g2 = norm2(g);
    return g2 > 0.0 ? g * std::sqrt(mag2 / g2) : g;
  }
};

// Carry a vector stored in the previous contact plane (normal n_old) into the current plane
// (normal n_new), spec §1.3 steps (a)-(c).
inline Vec3 carry_into_plane(const Vec3& f, const Vec3& n_old, const Vec3& n_new, double mean_spin_n,
                             double dt) {
  return PlaneRotation(n_old, n_new, mean_spin_n, dt).carry(f);
}

}  // namespace hilldem
