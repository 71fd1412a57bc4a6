#include "hilldem/bodies/clump_state.hpp"

namespace hilldem {

std::size_t ClumpState::add(const Vec3& x, const Vec3& v, const Quat& q, const Vec3& omega, double m,
                            const Vec3& inertia, FixityMask fix) {
  const Quat qn = normalized(q);
  position.push_back(x);
  velocity.push_back(v);
  orientation.push_back(qn);
  spin.push_back(omega);
  const Vec3 wb = rotate(conjugate(qn), omega);
  body_momentum.push_back({inertia.x * wb.x, inertia.y * wb.y, inertia.z * wb.z});
  mass.push_back(m);
  principal_inertia.push_back(inertia);
  fixity.push_back(fix);
  return mass.size() - 1;
}

Vec3 angular_momentum(const ClumpState& s, std::size_t i) { return rotate(s.orientation[i], s.body_momentum[i]); }

double rotational_energy(const ClumpState& s, std::size_t i) {
  const Vec3 l = s.body_momentum[i], in = s.principal_inertia[i];
  return 0.5 * (l.x * l.x / in.x + l.y * l.y / in.y + l.z * l.z / in.z);
}

}  // namespace hilldem
