// Clump templates from shapes (issue 32): pebbles that fill a shape, for make_template.
#pragma once

#include "hilldem/bodies/clump_template.hpp"

namespace hilldem {

// Ellipsoid x²/a² + y²/b² + z²/c² ≤ 1 with semi-axes a ≥ b ≥ c > 0 [m], filled by pebbles centred on
// its major axis (x), each the largest sphere about its centre that stays inside: at x0, the
// distance to the surface is r(x0) = c √(1 − x0²/(a² − c²)) for |x0| ≤ a − c²/a (the foot of the
// normal lies in the x–z plane, c being the smallest semi-axis), and a − |x0| beyond (the vertex).
// count pebbles [-] ≥ 1 are spaced evenly on [−x_end, x_end], x_end where r = smallest_ratio · c
// (the end pebbles' radius as a fraction of c, in (0, 1]); one pebble is the sphere of radius c at
// the centre. Fidelity: for b = c (a spheroid) the union's envelope tends to the surface as count
// grows (the spheres touch it along their normals); for b > c the union is the spheroid (a, c, c)'s
// fill, so its volume tends at most to c/b of the ellipsoid's. The measured fractions are in
// docs/clumps.md and the tests. Throws InputError outside these ranges.
struct EllipsoidFill {
  double a = 0.0, b = 0.0, c = 0.0;  // semi-axes [m], a ≥ b ≥ c
  int count = 10;                    // pebbles
  double smallest_ratio = 0.5;       // end pebbles' radius / c
};
Pebbles fill_ellipsoid(const EllipsoidFill& f);

// The volume (4/3)π a b c [m³] of the ellipsoid.
double ellipsoid_volume(const EllipsoidFill& f);

}  // namespace hilldem
