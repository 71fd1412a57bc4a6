#include "hilldem/bodies/clump_pebbles.hpp"

namespace hilldem {

std::size_t add_clump(ClumpState& s, ClumpPebbles& p, const ClumpTemplate& t, const Vec3& x, const Vec3& v,
                      const Quat& q, const Vec3& omega, FixityMask fix) {
  const std::size_t i = s.add(x, v, q * t.orientation, omega, t.mass, t.principal_inertia, fix);
  for (std::size_t k = 0; k < t.pebbles.size(); ++k) {
    p.clump.push_back(static_cast<std::uint32_t>(i));
    p.body_position.push_back(t.pebbles.position[k]);
    p.radius.push_back(t.pebbles.radius[k]);
  }
  return i;
}

Vec3 pebble_position(const ClumpState& s, const ClumpPebbles& p, std::size_t k) {
  const std::uint32_t i = p.clump[k];
  return s.position[i] + rotate(s.orientation[i], p.body_position[k]);
}

Vec3 pebble_velocity(const ClumpState& s, const ClumpPebbles& p, std::size_t k) {
  const std::uint32_t i = p.clump[k];
  return s.velocity[i] + cross(s.spin[i], rotate(s.orientation[i], p.body_position[k]));
}

void sum_pebble_loads(const ClumpState& s, const ClumpPebbles& p, const std::vector<Vec3>& point,
                      const std::vector<Vec3>& force_on_pebble, const std::vector<Vec3>& moment_on_pebble,
                      std::vector<Vec3>& force, std::vector<Vec3>& torque) {
  force.assign(s.size(), Vec3{});
  torque.assign(s.size(), Vec3{});
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::uint32_t i = p.clump[k];
    force[i] += force_on_pebble[k];
    torque[i] += cross(point[k] - s.position[i], force_on_pebble[k]) + moment_on_pebble[k];
  }
}

}  // namespace hilldem
