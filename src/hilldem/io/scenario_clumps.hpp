// The scenario's clump keys (docs/scenario-format.md, [[clump_template]] and [[clump]]): a
// template's shape and mass properties, and a clump's placement and motion. The caller (io/scenario)
// resolves names, materials, groups and fixity.
#pragma once

#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/engine/clump_bodies.hpp"
#include "hilldem/io/toml_reader.hpp"

namespace hilldem {

// The template of a [[clump_template]] table for density ρ [kg/m³]: its pebbles (`centres` and
// `radii`, or a shape filled by bodies/clump_fill.hpp: `ellipsoid`, `polyhedron`, `vertices` or a
// `mesh` file relative to the scenario, with `count`, `smallest_ratio`, `fidelity`, `resolution`), its mass properties (exact for one or
// two pebbles, else `columns` of column integration; or the user's `volume`, `centre_of_mass` and
// `inertia`), scaled to `size` (the equal-volume diameter) when given.
ClumpTemplate read_clump_template_shape(TableReader& t, double density);

// The placement keys of a [[clump]] table: position, orientation, velocity, spin.
void read_clump_placement(TableReader& t, ClumpInit& c);

}  // namespace hilldem
