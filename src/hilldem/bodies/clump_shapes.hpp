// Named clump templates (issue 32): pebble rows and filled shapes by name, for the command line.
#pragma once

#include <string>

#include "hilldem/bodies/clump_fill.hpp"
#include "hilldem/bodies/clump_template.hpp"

namespace hilldem {

// Named templates for the command line (bench --clumps, docs/clumps.md); scale them with
// ClumpTemplate::scaled. In units of the pebble radius: "sphere", one pebble of radius 1 (a clump
// that is a ball: for comparing the two paths on one geometry); "elongated2", two equal pebbles of
// radius 1 with centres 1 apart (length 3, width 2: aspect ratio 1.5); "elongated3", three equal
// pebbles in a row, centres 1 apart (length 4: aspect ratio 2). Shapes filled by fill_shape
// (bodies/clump_fill.hpp) with its default parameters (10 pebbles at most, smallest 0.5 of the
// largest, fidelity 0.98, resolution 41): "ellipsoid", the triaxial ellipsoid of semi-axes 1.5, 1.2,
// 1; and the polyhedra of aggregate_polyhedron (bodies/clump_mesh.hpp): "cube", "prism", "slab",
// "rock". Mass properties for density ρ [kg/m³] (sphere and elongated2 exact, the others by columns
// at the default n). Throws InputError naming the known names.
ClumpTemplate named_template(const std::string& name, double density);
inline constexpr const char* kNamedTemplates = "sphere, elongated2, elongated3, ellipsoid, cube, prism, slab, rock";

// The pebbles filling a named shape: "ellipsoid" or a polyhedron of aggregate_polyhedron (above).
Pebbles named_shape_fill(const std::string& name, const FillParams& params = {});

}  // namespace hilldem
