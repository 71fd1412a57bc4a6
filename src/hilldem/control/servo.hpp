// Servo: drives walls to a target stress (spec lab-tests.md §3):
//   v = G (σ_measured − σ_target), |v| ≤ v_max,   G = α_s A / (k_n,sum Δt)
// with A the loaded area [m²], k_n,sum the sum of the normal stiffnesses of the walls' contacts
// [N/m] and α_s ≈ 0.5. An over-stressed wall moves away from the specimen. Two modes:
//   Axial  - the walls translate along `outward` (a platen's outward normal, away from the specimen);
//   Radial - the walls are cylinders whose radius changes (radial_velocity).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

class Simulation;

struct ServoSettings {
  double target_stress = 0.0;  // σ_target [Pa], compression positive
  double gain_factor = 0.5;    // α_s [-], (0, 1]
  double max_speed = 1.0;      // v_max [m/s]
};

class Servo {
 public:
  enum class Mode { Axial, Radial };

  // `area` returns the loaded area [m²] at the current state (e.g. π R² for a platen inside a
  // cylinder, 2π R H for the lateral wall).
  Servo(Mode mode, std::vector<std::size_t> walls, Vec3 outward, ServoSettings settings,
        std::function<double(const Simulation&)> area);

  // Measured stress [Pa]: Σ normal contact force on the walls / area.
  double stress(const Simulation& sim) const;
  // Set the walls' velocity for the next step of length dt [s] (a Simulation controller).
  void control(Simulation& sim, double dt);
  // Velocity [m/s] the last call imposed (along `outward`, or radial), for histories.
  double speed() const { return speed_; }

  ServoSettings settings;
  bool enabled = true;

 private:
  Mode mode_;
  std::vector<std::size_t> walls_;
  Vec3 outward_;
  std::function<double(const Simulation&)> area_;
  double speed_ = 0.0;
};

}  // namespace hilldem
