#include "hilldem/bodies/wall_store.hpp"

namespace hilldem {

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

std::optional<WallTouch> wall_touch(const Wall& w, const Vec3& c, double R) {
  switch (w.shape) {
    case WallShape::Plane: {
      const double s = dot(c - w.point, w.normal);  // distance of the centre on the ball side
      return WallTouch{-w.normal, s - R};
    }
    case WallShape::Facet: {
      const Vec3 q = closest_point_on_triangle(c, w.vertex[0], w.vertex[1], w.vertex[2]);
      const Vec3 d = q - c;
      const double dist = norm(d);
      // Rounding in the face region leaves |q − c| ~ 1e-18 m for a centre in the facet's plane:
      // treat anything that small as "on the facet" and use the face normal.
      if (dist > 1e-12 * R) return WallTouch{d / dist, dist - R};
      // Centre exactly on the facet: push along the face normal.
      const Vec3 n = unit_or_zero(cross(w.vertex[1] - w.vertex[0], w.vertex[2] - w.vertex[0]));
      return WallTouch{-n, -R};
    }
    case WallShape::Cylinder: {
      const Vec3 a = axis_vector(w.axis);
      const Vec3 rel = c - w.point;
      const double along = dot(rel, a);
      if (w.lo < w.hi && (along < w.lo || along > w.hi)) return std::nullopt;
      const Vec3 radial = rel - a * along;
      const double rho = norm(radial);
      const Vec3 n = rho > 0.0 ? radial / rho : axis_vector((w.axis + 1) % 3);
      return WallTouch{n, w.radius - rho - R};
    }
  }
  return std::nullopt;
}

void advance_wall(Wall& w, double dt) {
  const double angle = norm(w.spin) * dt;
  if (angle > 0.0) {
    const Vec3 k = w.spin / norm(w.spin);
    const Vec3 o = w.rotation_center;
    w.point = o + rotate(w.point - o, k, angle);
    w.normal = rotate(w.normal, k, angle);
    for (auto& v : w.vertex) v = o + rotate(v - o, k, angle);
  }
  const Vec3 d = w.velocity * dt;
  w.point += d;
  for (auto& v : w.vertex) v += d;
  w.rotation_center += d;
  if (w.shape == WallShape::Cylinder) w.radius += w.radial_velocity * dt;
}

long WallStore::find(const std::string& name) const {
  for (std::size_t k = 0; k < walls.size(); ++k)
    if (walls[k].name == name) return static_cast<long>(k);
  return -1;
}

}  // namespace hilldem
