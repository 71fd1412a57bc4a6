// Small helpers that build simulations in code for the physics tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <initializer_list>
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

// Granite balls of radius 5 mm in a row on the x axis, separated by the given gaps [m], with the
// hill model (μ 0.4, no damping, no suction in the rule) and a fixed Δt of 1e-6 s; no contacts yet.
inline Simulation granite_row(std::initializer_list<double> gaps) {
  Simulation sim;
  const double r = 5e-3;
  double x = 0.0;
  std::int64_t id = 1;
  sim.balls.add(granite(id++, {x, 0, 0}, r));
  for (double g : gaps) {
    x += 2 * r + g;
    sim.balls.add(granite(id++, {x, 0, 0}, r));
  }
  sim.table.rules.push_back(hill_rule(0.4, 0.0));
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-6;
  return sim;
}

// A random cloud of n balls (radii 2-3 mm, scaled to fit) in a cube of side `side` [m] whose overlaps
// are small (at most 2 % of the smaller radius), with random velocities and spins, bounded by six planes.
inline Simulation random_box(int n, unsigned seed, bool walls = true, double side = 40e-3) {
  Simulation sim;
  std::mt19937_64 rng(seed);
  // Shrink the radii so that n balls fill about 30 % of the cube.
  const double scale = std::min(1.0, std::cbrt(0.3 * side * side * side / (n * 4.19 * 2.5e-3 * 2.5e-3 * 2.5e-3)));
  std::uniform_real_distribution<double> pos(0.0, 1.0), rad(2e-3 * scale, 3e-3 * scale), vel(-0.5, 0.5), spin(-50, 50);
  std::vector<Vec3> placed;
  std::vector<double> radii;
  while (static_cast<int>(placed.size()) < n) {
    const double r = rad(rng);
    const Vec3 x{r + (side - 2 * r) * pos(rng), r + (side - 2 * r) * pos(rng), r + (side - 2 * r) * pos(rng)};
    bool ok = true;
    for (std::size_t k = 0; k < placed.size() && ok; ++k)
      ok = norm(placed[k] - x) > r + radii[k] - 0.02 * std::min(r, radii[k]);
    if (!ok) continue;
    placed.push_back(x);
    radii.push_back(r);
    BallInit b = granite(static_cast<std::int64_t>(placed.size()), x, r, {vel(rng), vel(rng), vel(rng)});
    b.spin = {spin(rng), spin(rng), spin(rng)};
    sim.balls.add(b);
  }
  sim.table.rules.push_back(hill_rule(0.4, 0.07, 20e3));
  sim.table.rules.push_back(linear_wall_rule(500e6, 0.4));
  if (walls) {
    for (int d = 0; d < 3; ++d)
      for (int upper = 0; upper < 2; ++upper) {
        Wall w;
        w.name = "plane" + std::to_string(2 * d + upper);
        w.shape = WallShape::Plane;
        w.point[d] = upper ? side : 0.0;
        w.normal[d] = upper ? -1.0 : 1.0;
        sim.walls.add(w);
      }
  }
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 2e-7;
  return sim;
}

}  // namespace hilldem::testing
