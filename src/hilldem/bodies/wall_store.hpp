// Walls: kinematic boundaries (infinite planes, triangular facets, axis-aligned cylinders seen from
// inside). They move with imposed velocities and never respond to forces; the contact forces on each
// wall are summed so that users (and servos, later) can read them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

enum class WallShape { Plane, Facet, Cylinder };

struct Wall {
  std::string name;
  std::uint64_t groups = 0;
  WallShape shape = WallShape::Plane;

  // Plane: a point and the unit normal pointing to the side where balls live (one-sided).
  Vec3 point;
  Vec3 normal{0, 0, 1};
  // Facet: three vertices [m]; two-sided.
  Vec3 vertex[3];
  // Cylinder: axis 0/1/2 (x/y/z) through `point`, inner radius [m], optional extent [lo, hi] [m]
  // along the axis (infinite when lo >= hi). Balls live inside.
  int axis = 2;
  double radius = 0.0;
  double lo = 0.0, hi = 0.0;

  // Imposed motion
  Vec3 velocity;                // [m/s] translation of the whole wall
  Vec3 spin;                    // [rad/s] rotation about rotation_center
  Vec3 rotation_center;         // [m], moves with the wall
  double radial_velocity = 0.0; // [m/s] cylinder only: rate of change of the radius

  // Sums over the wall's contacts, rebuilt every cycle
  Vec3 force;   // [N] total contact force on the wall
  Vec3 moment;  // [N m] about rotation_center
  double normal_force = 0.0;     // [N] Σ of the contacts' normal force components (compression > 0)
  double normal_stiffness = 0.0; // [N/m] Σ of the contacts' normal stiffnesses (servo gain)
  std::size_t active_contacts = 0;
};

// The unit vector of axis 0, 1 or 2 (x, y, z).
inline Vec3 axis_vector(int axis) {
  Vec3 a;
  a[axis] = 1.0;
  return a;
}

// Where a ball touches a wall: unit normal from the ball centre towards the wall (piece 1 = ball,
// piece 2 = wall, spec §1.1) and the signed gap [m] (< 0: overlap).
struct WallTouch {
  Vec3 normal;
  double gap = 0.0;
};

// Geometry of ball (centre c, radius R) against wall w; nullopt if the ball is outside the
// wall's extent (cylinder ends) — then no contact can exist.
std::optional<WallTouch> wall_touch(const Wall& w, const Vec3& c, double R);

// Velocity [m/s] of the wall's surface material point at x.
HILLDEM_INLINE Vec3 wall_point_velocity(const Wall& w, const Vec3& x) {
  Vec3 v = w.velocity + cross(w.spin, x - w.rotation_center);
  if (w.shape == WallShape::Cylinder && w.radial_velocity != 0.0) {
    const Vec3 a = axis_vector(w.axis);
    const Vec3 rel = x - w.point;
    v += unit_or_zero(rel - a * dot(rel, a)) * w.radial_velocity;
  }
  return v;
}
// (Inline: it runs for every wall row of every step, on the lab tests' hot path.)

// Advance the wall's geometry by its imposed motion over dt [s].
void advance_wall(Wall& w, double dt);

// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

class WallStore {
 public:
  std::size_t size() const { return walls.size(); }
  std::size_t add(Wall w) { walls.push_back(std::move(w)); return walls.size() - 1; }
  long find(const std::string& name) const;
  std::vector<Wall> walls;
};

}  // namespace hilldem
