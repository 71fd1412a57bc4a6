#include "hilldem/contact/contact_geometry.hpp"

#include <limits>

namespace hilldem {

ContactGeometry contact_geometry(const ContactStore& contacts, std::size_t c, const Vec3& x1, double r1,
                                 const Vec3& x2_in, double r2, const WallStore& walls, const PeriodicBox& box) {
  const ContactKey& k = contacts.key[c];
  ContactGeometry g;
  if (k.kind == ContactKind::BallBall) {
    Vec3 x2 = x2_in;
    if (contacts.image[c] != kNoImage) x2 += image_shift(contacts.image[c], box);
    const Vec3 d = x2 - x1;
    const double dist = norm(d);
    g.normal = dist > 0.0 ? d / dist : contacts.normal[c];
    g.gap = dist - r1 - r2;
  } else {
    const auto touch = wall_touch(walls.walls[k.b], x1, r1);
    if (!touch) {
      g.valid = false;
      g.normal = contacts.normal[c];
      g.gap = std::numeric_limits<double>::infinity();
      g.point = x1;
      return g;
    }
    g.normal = touch->normal;
    g.gap = touch->gap;
  }
  g.point = x1 + g.normal * (r1 + 0.5 * g.gap);  // centre of the gap/overlap (spec §1.1)
  return g;
}

}  // namespace hilldem
