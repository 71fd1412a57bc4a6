// Clump templates from shapes (issue 32): pebbles that fill a shape, for make_template.
#pragma once

#include <string>

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

// Named templates for the command line (bench --clumps, docs/clumps.md), in units of the pebble
// radius (scale them with ClumpTemplate::scaled): "sphere", one pebble of radius 1 (a clump that is
// a ball: for comparing the two paths on one geometry); "elongated2", two equal pebbles of radius 1 with
// centres 1 apart (length 3, width 2: aspect ratio 1.5); "elongated3", three equal pebbles in a row,
// centres 1 apart (length 4: aspect ratio 2). Mass properties for density ρ [kg/m³] (sphere and elongated2
// exact, elongated3 by columns at the default n). Throws InputError naming the known names.
ClumpTemplate named_template(const std::string& name, double density);
inline constexpr const char* kNamedTemplates = "sphere, elongated2, elongated3";

// The volume (4/3)π a b c [m³] of the ellipsoid.
double ellipsoid_volume(const EllipsoidFill& f);

}  // namespace hilldem
