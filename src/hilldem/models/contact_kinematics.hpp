// Contact kinematics (spec §1.1–1.3): what the narrow phase hands to a contact model. Each piece is
// one template over the lane type R (models/lanes.hpp), used by the batched force pass (R = Pack)
// and by the row-by-row path and the unit tests (R = double), so that a model is a pure function
// callable from a unit test, a threaded loop or a GPU kernel.
#pragma once

#include "hilldem/core/vec3.hpp"
#include "hilldem/models/lanes.hpp"

namespace hilldem {

// One contact's kinematics, as the scalar models' callers give it.
struct ContactKinematics {
  Vec3 normal;        // n̂_c, unit, from piece 1 to piece 2 (Eq. 2)
  double gap = 0.0;   // g_c [m], < 0 when overlapping (Eq. 3)
  Vec3 rel_velocity;  // δ̇ = ẋ_c(2) − ẋ_c(1) at the contact point [m/s] (§1.2)
  double dt = 0.0;    // Δt [s]

  double overlap() const { return -gap; }                               // δ_o [m]
  double normal_rate() const { return dot(rel_velocity, normal); }      // δ̇_n [m/s], > 0 apart
  Vec3 shear_rate() const { return rel_velocity - normal * normal_rate(); }  // δ̇_s [m/s]
};

template <class R> struct PairGeometry {
  lanes::V3<R> normal;  // n̂_c
  R gap;                // g_c [m]
};

// Eqs. 2-3 for two balls from d = x2 − x1 [m] and their radii [m]: n̂_c = d/|d|, g_c = |d| − (R1 + R2);
// coincident centres keep the last step's normal n_old.
template <class R>
HILLDEM_INLINE PairGeometry<R> ball_pair_geometry(const lanes::V3<R>& d, R r1, R r2, const lanes::V3<R>& n_old) {
  using namespace lanes;
  const R dist = norm(d);
  const Mask<R> apart = dist > splat<R>(0.0);
  const V3<R> unit{d.x / dist, d.y / dist, d.z / dist};
  return {select(apart, unit, n_old), dist - (r1 + r2)};
}

// §1.2: the relative velocity ẋ_c(2) − ẋ_c(1) [m/s] of the material points at the contact point,
// which lies on the normal at the arm R + g/2 from either centre: ẋ_c(1) = v1 + ω1 × (R1 + g/2) n̂,
// ẋ_c(2) = v2 − ω2 × (R2 + g/2) n̂. A wall is body 2 with r2 = −g/2 (arm exactly 0) and v2 its
// surface velocity at x_c.
template <class R>
HILLDEM_INLINE lanes::V3<R> contact_velocity(const lanes::V3<R>& normal, R gap, R r1, R r2, const lanes::V3<R>& v1,
                                             const lanes::V3<R>& w1, const lanes::V3<R>& v2,
                                             const lanes::V3<R>& w2) {
  const R arm1 = r1 + 0.5 * gap, arm2 = r2 + 0.5 * gap;
  const lanes::V3<R> p1 = v1 + cross(w1, normal * arm1);
  const lanes::V3<R> p2 = v2 - cross(w2, normal * arm2);
  return p2 - p1;
}

// §1.3 (a) and (b): a vector of the last step's contact plane (normal n_old) rotated with the plane
// to n_new: the tilt n_old × n_new, then the twist about n_new by the mean spin ½(ω1 + ω2)·n_new
// [rad/s] over dt [s]. First order, not renormalised.
template <class R>
HILLDEM_INLINE lanes::V3<R> rotate_with_plane(const lanes::V3<R>& f, const lanes::V3<R>& n_old,
                                              const lanes::V3<R>& n_new, R mean_spin_n, double dt) {
  const lanes::V3<R> tilt = cross(n_old, n_new);
  const lanes::V3<R> twist = n_new * (mean_spin_n * dt);
  const lanes::V3<R> g = f - cross(f, tilt);
  return g - cross(g, twist);
}

// §1.3 (a)-(c), for stored forces: rotated with the plane, its residual normal part dropped and its
// magnitude restored. A zero vector stays zero.
template <class R>
HILLDEM_INLINE lanes::V3<R> carry_into_plane(const lanes::V3<R>& f, const lanes::V3<R>& n_old,
                                             const lanes::V3<R>& n_new, R mean_spin_n, double dt) {
  using namespace lanes;
  const R mag2 = norm2(f);
  V3<R> g = rotate_with_plane(f, n_old, n_new, mean_spin_n, dt);
  g = g - n_new * dot(g, n_new);
  const R g2 = norm2(g);
  const R scale = select(g2 > splat<R>(0.0), sqrt(mag2 / g2), splat<R>(1.0));
  return select(mag2 == splat<R>(0.0), f, g * scale);
}

inline Vec3 carry_into_plane(const Vec3& f, const Vec3& n_old, const Vec3& n_new, double mean_spin_n, double dt) {
  return lanes::vec3(carry_into_plane(lanes::v3(f), lanes::v3(n_old), lanes::v3(n_new), mean_spin_n, dt));
}

template <class R> struct ContactMoments {
  lanes::V3<R> on1, on2;  // [N m]
};

// The moments of F_c [N] (on piece 2; −F_c on piece 1) about the two centres: the contact point is
// on the normal at R + g/2 from either, so the moment on either ball is −(R + g/2) n̂ × F_c.
template <class R>
HILLDEM_INLINE ContactMoments<R> contact_moments(const lanes::V3<R>& normal, R gap, R r1, R r2,
                                                 const lanes::V3<R>& force) {
  const lanes::V3<R> torque = cross(normal, force);
  return {torque * -(r1 + 0.5 * gap), torque * -(r2 + 0.5 * gap)};
}

}  // namespace hilldem
