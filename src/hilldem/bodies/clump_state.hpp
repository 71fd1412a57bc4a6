// ClumpState: every clump's rigid-body state as structure of arrays, as BallStore is for balls. No
// physics: the law of motion is motion/rigid_body.hpp.
#pragma once

#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/core/quaternion.hpp"

namespace hilldem {

// Clumps as structure of arrays, one entry per clump.
struct ClumpState {
  std::vector<Vec3> position;           // centre of mass [m], at t
  std::vector<Vec3> velocity;           // [m/s], at t − Δt/2 (t + Δt/2 after a step)
  std::vector<Quat> orientation;        // principal frame → global, at t
  std::vector<Vec3> spin;               // ω [rad/s], global, at t − Δt/2
  std::vector<Vec3> body_momentum;      // L [kg m²/s] at t − Δt/2, in the principal frame at t
  std::vector<double> mass;             // [kg]
  std::vector<Vec3> principal_inertia;  // I1, I2, I3 [kg m²]
  std::vector<FixityMask> fixity;

  std::size_t size() const { return mass.size(); }
  // Add a clump; L from ω and the inertia at orientation q. Returns the index.
  std::size_t add(const Vec3& x, const Vec3& v, const Quat& q, const Vec3& omega, double m, const Vec3& inertia,
                  FixityMask fix = 0);
};

// L [kg m²/s] and the rotational kinetic energy [J] of clump i in the global frame, from its
// orientation and body-frame momentum.
Vec3 angular_momentum(const ClumpState& s, std::size_t i);
double rotational_energy(const ClumpState& s, std::size_t i);

}  // namespace hilldem
