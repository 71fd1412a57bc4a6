// Law of motion (spec §4): central difference with velocities at half steps, local (non-viscous)
// damping, gravity, applied loads and fixity.
#pragma once

#include "hilldem/bodies/ball_store.hpp"

namespace hilldem {

namespace motion {
struct ContactSums;
}

// Loops shorter than this run on one thread: waking threads costs more than it saves.
inline constexpr std::size_t kParallelMin = 2048;

struct MotionSettings {
  Vec3 gravity;                // g [m/s²]
  double local_damping = 0.0;  // α [-], [0, 1)
};

// Unbalanced force [N] on ball i: contact forces + m g + applied force.
inline Vec3 unbalanced_force(const BallStore& b, std::size_t i, const Vec3& gravity) {
  return b.contact_force[i] + gravity * b.mass[i] + b.applied_force[i];
}
inline Vec3 unbalanced_moment(const BallStore& b, std::size_t i) {
  return b.contact_moment[i] + b.applied_moment[i];
}

// Advance velocities from t−Δt/2 to t+Δt/2 with the forces at t, then positions to t+Δt.
// With density scaling, inertial_mass/inertial_inertia replace m and I in the accelerations only
// (gravity keeps the real mass).
// contact_sums: the force pass's sums of each ball's contact forces and moments (the engine's), or
// null for the BallStore's contact_force and contact_moment columns.
void advance_balls(BallStore& balls, const MotionSettings& s, double dt, const double* inertial_mass = nullptr,
                   const double* inertial_inertia = nullptr, const motion::ContactSums* contact_sums = nullptr);

}  // namespace hilldem
