// The material vessel (docs/spec/lab-tests.md §2): a lateral cylindrical wall (axis z, radius that
// can change) and two platens (planes, bottom at z_b with normal +z, top at z_t with normal −z) whose
// heights can change. Stresses are the walls' summed normal contact forces over the current areas.
#pragma once

#include <cstddef>
#include <cstdint>
#include <numbers>

#include "hilldem/control/servo.hpp"
#include "hilldem/engine/simulation.hpp"

namespace hilldem {

struct Vessel {
  std::size_t lateral = 0, bottom = 0, top = 0;  // wall indices in Simulation::walls

  double radius(const Simulation& s) const { return s.walls.walls[lateral].radius; }
  double bottom_z(const Simulation& s) const { return s.walls.walls[bottom].point.z; }
  double top_z(const Simulation& s) const { return s.walls.walls[top].point.z; }
  double height(const Simulation& s) const { return top_z(s) - bottom_z(s); }
  double platen_area(const Simulation& s) const { return std::numbers::pi * radius(s) * radius(s); }
  double lateral_area(const Simulation& s) const { return 2.0 * std::numbers::pi * radius(s) * height(s); }
  double volume(const Simulation& s) const { return platen_area(s) * height(s); }

  // Stresses [Pa], compression positive.
  double radial_stress(const Simulation& s) const { return s.walls.walls[lateral].normal_force / lateral_area(s); }
  double bottom_stress(const Simulation& s) const { return s.walls.walls[bottom].normal_force / platen_area(s); }
  double top_stress(const Simulation& s) const { return s.walls.walls[top].normal_force / platen_area(s); }
  double axial_stress(const Simulation& s) const { return 0.5 * (bottom_stress(s) + top_stress(s)); }

  // Servos that hold the lateral wall / one platen at a stress (lab-tests.md §3).
  Servo radial_servo(const ServoSettings& settings) const;
  Servo platen_servo(bool top_platen, const ServoSettings& settings) const;

  // All three walls at rest.
  void stop(Simulation& s) const;
};

// Adds the three walls (named vessel.lateral, vessel.bottom, vessel.top, in group `groups`) for a
// vessel of the given radius and height [m], bottom at z = 0, axis through x = y = 0.
Vessel add_vessel(Simulation& sim, double radius, double height, std::uint64_t groups);
// The vessel whose walls carry those names (a Simulation built elsewhere); throws InputError if absent.
Vessel find_vessel(const Simulation& sim);

}  // namespace hilldem
