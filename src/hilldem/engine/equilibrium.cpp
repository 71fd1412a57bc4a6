#include "hilldem/engine/equilibrium.hpp"

#include <cmath>
#include <vector>

#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

double mean_unbalanced_ratio(const BallStore& balls, const ContactStore& contacts, const Vec3& gravity,
                             const ClumpBodies* clumps) {
  // PFC's mechanical ratio-average (spec lab-tests §3.4): the mean over free bodies of the
  // unbalanced-force magnitude over the mean over the same bodies of the applied-force magnitude,
  // that is the sum over a body's active contacts of |F_c| plus its weight m |g|. A contact's force
  // counts as |F^s_n n̂ + F_s| + |F^m|, the magnitudes of its parts: a wet contact in equilibrium
  // carries a Hertz force and an equal and opposite moisture force, and its net force is zero.
  const std::size_t n = balls.size();
  std::vector<double> applied(n, 0.0);
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (!contacts.active[c]) continue;
    const double fn = contacts.normal_force[c];
    const double f = std::sqrt(fn * fn + norm2(contacts.shear_force(c))) + std::abs(contacts.moisture_force[c]);
    const ContactKey& k = contacts.key[c];
    applied[k.a] += f;
    if (k.kind == ContactKind::BallBall) applied[k.b] += f;
  }
  const double g = norm(gravity);
  double unbalanced = 0.0, applied_sum = 0.0;
  std::size_t free_balls = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const FixityMask fix = balls.fixity[i];
    if ((fix & kFixVel) == kFixVel) continue;
    Vec3 f = unbalanced_force(balls, i, gravity);
    for (int d = 0; d < 3; ++d)
      if (fix & (1u << d)) f[d] = 0.0;
    unbalanced += norm(f);
    applied_sum += applied[i] + balls.mass[i] * g;
    ++free_balls;
  }
  if (clumps) {
    std::vector<Vec3> f(clumps->size());
    std::vector<double> a(clumps->size(), 0.0);
    for (std::size_t k = 0; k < clumps->ball.size(); ++k) {
      const std::uint32_t b = clumps->ball[k], j = clumps->pebbles.clump[k];
      f[j] += balls.contact_force[b] + balls.applied_force[b];
      a[j] += applied[b];
    }
    const ClumpState& s = clumps->state;
    for (std::size_t j = 0; j < s.size(); ++j) {
      if ((s.fixity[j] & kFixVel) == kFixVel) continue;
      Vec3 u = f[j] + gravity * s.mass[j];
      for (int d = 0; d < 3; ++d)
        if (s.fixity[j] & (1u << d)) u[d] = 0.0;
      unbalanced += norm(u);
      applied_sum += a[j] + s.mass[j] * g;
      ++free_balls;
    }
  }
  if (free_balls == 0) return 0.0;
  if (applied_sum == 0.0) return unbalanced > 0.0 ? 1.0 : 0.0;
  return unbalanced / applied_sum;  // the two means share the divisor free_balls
}

}  // namespace hilldem
