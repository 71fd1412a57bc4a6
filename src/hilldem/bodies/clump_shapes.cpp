#include "hilldem/bodies/clump_shapes.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {

// The radius [m] of the largest sphere centred at (x0, 0, 0) inside the ellipsoid (c ≤ b ≤ a).
double inscribed_radius(double a, double c, double x0) {
  const double x = std::abs(x0);
  if (a == c) return a - x;  // a sphere (b = c = a)
  if (x <= a - c * c / a) return c * std::sqrt(std::max(0.0, 1.0 - x * x / (a * a - c * c)));
  return a - x;
}

}  // namespace

double ellipsoid_volume(const EllipsoidFill& f) { return 4.0 / 3.0 * std::numbers::pi * f.a * f.b * f.c; }

Pebbles fill_ellipsoid(const EllipsoidFill& f) {
  if (!(f.c > 0.0) || !(f.b >= f.c) || !(f.a >= f.b) || !std::isfinite(f.a))
    throw InputError("ellipsoid fill: semi-axes must be a >= b >= c > 0 m, got a = " + std::to_string(f.a) +
                     ", b = " + std::to_string(f.b) + ", c = " + std::to_string(f.c));
  if (f.count < 1) throw InputError("ellipsoid fill: count must be >= 1, got " + std::to_string(f.count));
  if (!(f.smallest_ratio > 0.0) || !(f.smallest_ratio <= 1.0))
    throw InputError("ellipsoid fill: smallest_ratio must be in (0, 1], got " + std::to_string(f.smallest_ratio));
  Pebbles p;
  if (f.count == 1 || f.a == f.c) {
    p.position.push_back({});
    p.radius.push_back(f.c);
    return p;
  }
  // x_end: r(x_end) = ρ c. On the normal branch (ρ c ≥ c²/a, the radius at x = a − c²/a)
  // x_end = √(a² − c²) √(1 − ρ²); on the vertex branch x_end = a − ρ c.
  const double a = f.a, c = f.c, rho = f.smallest_ratio;
  const double x_end = rho * c >= c * c / a ? std::sqrt(a * a - c * c) * std::sqrt(1.0 - rho * rho) : a - rho * c;
  for (int k = 0; k < f.count; ++k) {
    const double x = -x_end + 2.0 * x_end * k / (f.count - 1);
    p.position.push_back({x, 0.0, 0.0});
    p.radius.push_back(inscribed_radius(a, c, x));
  }
  return p;
}

ClumpTemplate named_template(const std::string& name, double density) {
  Pebbles p;
  if (name == "sphere") {
    p.position = {{0.0, 0.0, 0.0}};
  } else if (name == "elongated2") {
    p.position = {{-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}};
  } else if (name == "elongated3") {
    p.position = {{-1.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  } else {
    throw InputError("unknown clump template '" + name + "'; known: " + kNamedTemplates);
  }
  p.radius.assign(p.position.size(), 1.0);
  return make_template(p, density);
}

}  // namespace hilldem
