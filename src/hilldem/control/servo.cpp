#include "hilldem/control/servo.hpp"

#include <algorithm>
#include <cmath>

#include "hilldem/engine/simulation.hpp"

namespace hilldem {

Servo::Servo(Mode mode, std::vector<std::size_t> walls, Vec3 outward, ServoSettings s,
             std::function<double(const Simulation&)> area)
    : settings(s), mode_(mode), walls_(std::move(walls)), outward_(unit_or_zero(outward)), area_(std::move(area)) {}

double Servo::stress(const Simulation& sim) const {
  double force = 0.0;
  for (std::size_t w : walls_) force += sim.walls.walls[w].normal_force;
  const double a = area_(sim);
  return a > 0.0 ? force / a : 0.0;
}

void Servo::control(Simulation& sim, double dt) {
  if (!enabled) return;
  double stiffness = 0.0;
  for (std::size_t w : walls_) stiffness += sim.walls.walls[w].normal_stiffness;
  const double error = stress(sim) - settings.target_stress;  // > 0: over-stressed, move away
  double v;
  if (stiffness > 0.0 && dt > 0.0) {
    v = settings.gain_factor * area_(sim) / (stiffness * dt) * error;
  } else {
    // No contact yet: close in at full speed (or back off if over-stressed, which cannot happen).
    v = error > 0.0 ? settings.max_speed : -settings.max_speed;
  }
  speed_ = std::clamp(v, -settings.max_speed, settings.max_speed);
  for (std::size_t w : walls_) {
    Wall& wall = sim.walls.walls[w];
    if (mode_ == Mode::Radial) wall.radial_velocity = speed_;
    else wall.velocity = outward_ * speed_;
  }
}

}  // namespace hilldem
