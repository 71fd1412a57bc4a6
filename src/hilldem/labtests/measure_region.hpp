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
// 1 − Σ (sphere volume inside) / region volume.
double region_porosity(const MeasurementCylinder& m, const std::vector<Vec3>& centres, const std::vector<double>& radii);

}  // namespace hilldem
