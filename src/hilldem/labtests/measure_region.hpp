// Porosity in a measurement region: a coaxial cylinder inside the vessel, away from the walls, where
// the packing is free of the wall layer (the wall effect raises the vessel's porosity: grains cannot
// fill the space next to a flat or curved wall as they fill the bulk). Sphere volumes inside the region
// are exact for grains wholly in or out; for grains crossing its boundary the slice areas (circle ∩
// disk, closed form) are integrated along the axis (composite Simpson, 64 intervals).
#pragma once

#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

struct MeasurementCylinder {
  double radius = 0.0;       // [m], axis x = y = 0
  double z_lo = 0.0, z_hi = 0.0;  // [m]
  double volume() const;
};

// Volume [m³] of the sphere (c, r) inside the region.
double sphere_volume_inside(const MeasurementCylinder& m, const Vec3& c, double r);
// Volume [m³] of a clump inside the region: its pebbles (centres, radii [m], global) and its union
// volume V [m³] (the template's). Exact when the clump is one pebble (sphere_volume_inside) or every
// pebble lies wholly inside (V) or wholly outside (0). A clump crossing the region's boundary gets
// V × f, f the fraction of its union inside measured by columns: an n × n grid of columns along z
// across the pebbles' x–y extent; in each column (its centre) the union of the pebbles' chords is
// found exactly, and the part of it inside the region (the column's centre within the radius, the
// chords clipped to [z_lo, z_hi]); f = Σ inside lengths / Σ lengths. Measured accuracy of f
// (tests/labtests/test_clump_specimens.cpp): within 2e-3 of the exact fraction at n = 64.
inline constexpr int kRegionColumns = 64;
double clump_volume_inside(const MeasurementCylinder& m, const std::vector<Vec3>& centres, const std::vector<double>& radii,
                           double volume, int n = kRegionColumns);
// 1 − Σ (sphere volume inside) / region volume.
double region_porosity(const MeasurementCylinder& m, const std::vector<Vec3>& centres, const std::vector<double>& radii);

}  // namespace hilldem
