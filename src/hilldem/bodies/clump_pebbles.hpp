// The pebbles of clumps as structure of arrays, each with its clump's index, for the force pass to
// treat as spheres: their global positions and velocities from the clumps' state, and the sum of
// their loads into each clump's force and torque about its centre of mass.
#pragma once

#include <cstdint>
#include <vector>

#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/bodies/clump_state.hpp"

namespace hilldem {

// "No clump": a ball that is not a pebble (ClumpBodies::clump_of_balls).
inline constexpr std::uint32_t kNoClump = 0xffffffffu;

struct ClumpPebbles {
  std::vector<std::uint32_t> clump;  // index into ClumpState
  std::vector<Vec3> body_position;   // centre [m] in the clump's principal frame, from its centre of mass
  std::vector<double> radius;        // [m]
  std::size_t size() const { return clump.size(); }
};

// A clump from template t: its centre of mass at x [m], velocity v [m/s], spin ω [rad/s] (global),
// and its orientation q t.orientation (q: the placement's rotation of the template's frame); its
// pebbles appended to p. Returns the clump's index.
std::size_t add_clump(ClumpState& s, ClumpPebbles& p, const ClumpTemplate& t, const Vec3& x, const Vec3& v,
                      const Quat& q, const Vec3& omega, FixityMask fix = 0);

// Pebble k's centre [m] and its velocity V + ω × (x_k − X) [m/s] (ω at half steps, as V).
Vec3 pebble_position(const ClumpState& s, const ClumpPebbles& p, std::size_t k);
Vec3 pebble_velocity(const ClumpState& s, const ClumpPebbles& p, std::size_t k);

// Each clump's force [N] and torque [N m] about its centre of mass from forces acting at points
// (force[k] at point[k] on pebble k) and moments on pebbles (moment[k]): F = Σ f_k,
// M = Σ (point_k − X) × f_k + m_k, summed in pebble order (a fixed order: the same bits for any
// thread count when the force pass adds them up so). force, torque: resized to the clump count.
void sum_pebble_loads(const ClumpState& s, const ClumpPebbles& p, const std::vector<Vec3>& point,
                      const std::vector<Vec3>& force_on_pebble, const std::vector<Vec3>& moment_on_pebble,
                      std::vector<Vec3>& force, std::vector<Vec3>& torque);

}  // namespace hilldem
