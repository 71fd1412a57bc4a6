// Small helpers that build simulations in code for the physics tests.
#pragma once

#include <random>

#include "hilldem/engine/simulation.hpp"

namespace hilldem::testing {

inline constexpr double kGraniteDensity = 2650.0;  // [kg/m^3]
inline constexpr double kGraniteE = 29e9;          // [Pa]
inline constexpr double kGraniteNu = 0.15;         // [-]

inline BallInit granite(std::int64_t id, Vec3 x, double r, Vec3 v = {}) {
  BallInit b;
  b.id = id;
  b.position = x;
  b.radius = r;
  b.density = kGraniteDensity;
  b.young_mod = kGraniteE;
  b.pois_ratio = kGraniteNu;
  b.velocity = v;
  return b;
}

inline ModelRule hill_rule(double fric, double damp, double suction = 0.0) {
  ModelRule r;
  r.name = "hill";
  r.kind = ContactKind::BallBall;
  r.model = ModelKind::Hill;
  r.hill = {fric, damp, suction};
  return r;
}

inline ModelRule linear_wall_rule(double emod, double fric) {
  ModelRule r;
  r.name = "wall";
  r.kind = ContactKind::BallWall;
  r.model = ModelKind::Linear;
  r.linear = {emod, 1.0, fric};
  return r;
}

// A loose random cloud of n balls (radii 2-3 mm) in a 40 mm cube with overlaps, random velocities
// and spins, bounded by six planes.
inline Simulation random_box(int n, unsigned seed, bool walls = true) {
  Simulation sim;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(3e-3, 37e-3), rad(2e-3, 3e-3), vel(-0.5, 0.5), spin(-50, 50);
  for (int i = 0; i < n; ++i) {
    BallInit b = granite(i + 1, {pos(rng), pos(rng), pos(rng)}, rad(rng), {vel(rng), vel(rng), vel(rng)});
    b.spin = {spin(rng), spin(rng), spin(rng)};
    sim.balls.add(b);
  }
  sim.table.rules.push_back(hill_rule(0.4, 0.07, 20e3));
  sim.table.rules.push_back(linear_wall_rule(500e6, 0.4));
  if (walls) {
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        Wall w;
        w.name = "plane" + std::to_string(2 * d + side);
        w.shape = WallShape::Plane;
        w.point[d] = side ? 40e-3 : 0.0;
        w.normal[d] = side ? -1.0 : 1.0;
        sim.walls.add(w);
      }
  }
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 2e-7;
  return sim;
}

}  // namespace hilldem::testing
