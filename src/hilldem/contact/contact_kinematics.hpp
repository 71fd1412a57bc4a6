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

// Carry a vector stored in the previous contact plane (normal n_old) into the current plane
// (normal n_new), spec §1.3: (a) rotate with the change of normal, (b) rotate about the normal by the
// mean spin component mean_spin_n = ½(ω1+ω2)·n_new [rad/s] over dt [s], (c) drop any residual
// normal part and restore the magnitude.
inline Vec3 carry_into_plane(const Vec3& f, const Vec3& n_old, const Vec3& n_new, double mean_spin_n,
                             double dt) {
  const double mag2 = norm2(f);
  if (mag2 == 0.0) return f;
  Vec3 g = f - cross(f, cross(n_old, n_new));          // (a)
  g = g - cross(g, n_new * mean_spin_n) * dt;          // (b)
  g = g - n_new * dot(g, n_new);                       // (c)
  const double g2 = norm2(g);
  return g2 > 0.0 ? g * std::sqrt(mag2 / g2) : g;
}

}  // namespace hilldem
