// Quat: a unit quaternion q = (w, x, y, z) for the orientation of a rigid body. Convention: q maps
// the body frame to the global frame, v_global = q v_body q* (Hamilton product, right-handed,
// active rotation), so that q1 q2 is "first q2, then q1".
#pragma once

#include <cmath>

#include "hilldem/core/mat3.hpp"

namespace hilldem {

struct Quat {
  double w = 1.0, x = 0.0, y = 0.0, z = 0.0;
  constexpr Vec3 vec() const { return {x, y, z}; }
};

// Hamilton product: (a b) v (a b)* = a (b v b*) a*.
constexpr Quat operator*(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
constexpr Quat conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }
constexpr double norm2(const Quat& q) { return q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z; }
// q / |q|, with the sign chosen so that w ≥ 0 (q and −q are the same rotation).
inline Quat normalized(const Quat& q) {
  const double s = (q.w < 0.0 ? -1.0 : 1.0) / std::sqrt(norm2(q));
  return {q.w * s, q.x * s, q.y * s, q.z * s};
}

// q v q* for a unit q: v + 2w (u × v) + 2 u × (u × v), u = (x, y, z).
constexpr Vec3 rotate(const Quat& q, const Vec3& v) {
  const Vec3 u = q.vec();
  const Vec3 t = cross(u, v) * 2.0;
  return v + t * q.w + cross(u, t);
}

// The rotation matrix R of a unit q (R v = q v q*); its columns are the body axes in the global frame.
constexpr Mat3 to_matrix(const Quat& q) {
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  Mat3 r;
  r.m[0][0] = 1.0 - 2.0 * (y * y + z * z), r.m[0][1] = 2.0 * (x * y - w * z), r.m[0][2] = 2.0 * (x * z + w * y);
  r.m[1][0] = 2.0 * (x * y + w * z), r.m[1][1] = 1.0 - 2.0 * (x * x + z * z), r.m[1][2] = 2.0 * (y * z - w * x);
  r.m[2][0] = 2.0 * (x * z - w * y), r.m[2][1] = 2.0 * (y * z + w * x), r.m[2][2] = 1.0 - 2.0 * (x * x + y * y);
  return r;
}

// The unit quaternion of a rotation matrix (Shepperd 1978, J. Guidance Control 1(3) 223: from the
// largest of w², x², y², z², so that no division is by a small number). R must be orthonormal with
// det +1.
inline Quat from_matrix(const Mat3& r) {
  const double tr = r(0, 0) + r(1, 1) + r(2, 2);
  Quat q;
  if (tr >= r(0, 0) && tr >= r(1, 1) && tr >= r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + tr);  // 4w
    q = {0.25 * s, (r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s};
  } else if (r(0, 0) >= r(1, 1) && r(0, 0) >= r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(0, 0) - r(1, 1) - r(2, 2));  // 4x
    q = {(r(2, 1) - r(1, 2)) / s, 0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s};
  } else if (r(1, 1) >= r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(1, 1) - r(0, 0) - r(2, 2));  // 4y
    q = {(r(0, 2) - r(2, 0)) / s, (r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + r(2, 2) - r(0, 0) - r(1, 1));  // 4z
    q = {(r(1, 0) - r(0, 1)) / s, (r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s};
  }
  return normalized(q);
}

// The exponential map: the rotation by |θ| [rad] about θ/|θ|, q = (cos(|θ|/2), sin(|θ|/2) θ/|θ|).
// For |θ| < 1e-4 rad, sin(h)/|θ| = (1 − h²/6 + h⁴/120)/2 with h = |θ|/2 (the next term, h⁶/5040, is at
// most 3.1e-30 there); θ = 0 gives the identity exactly.
inline Quat from_rotation_vector(const Vec3& theta) {
  const double a = norm(theta);
  const double h = 0.5 * a;
  double s;  // sin(h) / a
  if (a < 1e-4) {
    const double h2 = h * h;
    s = 0.5 * (1.0 - h2 / 6.0 + h2 * h2 / 120.0);
  } else {
    s = std::sin(h) / a;
  }
  return {std::cos(h), theta.x * s, theta.y * s, theta.z * s};
}
// The rotation about the unit axis k by angle [rad].
inline Quat from_axis_angle(const Vec3& k, double angle) { return from_rotation_vector(k * angle); }

// Orientation q advanced by a constant angular velocity ω [rad/s] given in the global frame over Δt
// [s]: q' = exp(ω Δt) q, renormalised.
inline Quat integrate_global(const Quat& q, const Vec3& omega, double dt) {
  return normalized(from_rotation_vector(omega * dt) * q);
}
// The same for ω given in the body frame: q' = q exp(ω_body Δt).
inline Quat integrate_body(const Quat& q, const Vec3& omega_body, double dt) {
  return normalized(q * from_rotation_vector(omega_body * dt));
}

}  // namespace hilldem
