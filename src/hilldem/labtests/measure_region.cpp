#include "hilldem/labtests/measure_region.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hilldem {

namespace {
// Area of the intersection of a circle of radius a centred at distance d from the centre of a disk of
// radius b.
double circle_overlap(double a, double b, double d) {
  if (a <= 0.0 || b <= 0.0) return 0.0;
  if (d >= a + b) return 0.0;
  if (d <= std::abs(b - a)) return std::numbers::pi * std::min(a, b) * std::min(a, b);
  const double alpha = std::acos(std::clamp((d * d + a * a - b * b) / (2.0 * d * a), -1.0, 1.0));
  const double beta = std::acos(std::clamp((d * d + b * b - a * a) / (2.0 * d * b), -1.0, 1.0));
  return a * a * (alpha - std::sin(2.0 * alpha) / 2.0) + b * b * (beta - std::sin(2.0 * beta) / 2.0);
}
}  // namespace

double MeasurementCylinder::volume() const { return std::numbers::pi * radius * radius * std::max(0.0, z_hi - z_lo); }

double sphere_volume_inside(const MeasurementCylinder& m, const Vec3& c, double r) {
  const double rho = std::hypot(c.x, c.y);
  const double lo = std::max(c.z - r, m.z_lo), hi = std::min(c.z + r, m.z_hi);
  if (hi <= lo || rho - r >= m.radius) return 0.0;
  if (rho + r <= m.radius) {
    // Only the platen-like cuts: a spherical segment between two planes, in closed form.
    auto below = [&](double z) {  // volume of the sphere below height z
      const double h = std::clamp(z - (c.z - r), 0.0, 2.0 * r);
      return std::numbers::pi * h * h * (3.0 * r - h) / 3.0;
    };
    return below(hi) - below(lo);
  }
  constexpr int n = 64;  // even
  const double h = (hi - lo) / n;
  double sum = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double z = lo + k * h;
    const double a2 = r * r - (z - c.z) * (z - c.z);
    const double area = a2 > 0.0 ? circle_overlap(std::sqrt(a2), m.radius, rho) : 0.0;
    sum += area * (k == 0 || k == n ? 1.0 : (k % 2 ? 4.0 : 2.0));
  }
  return sum * h / 3.0;
}

double region_porosity(const MeasurementCylinder& m, const std::vector<Vec3>& centres, const std::vector<double>& radii) {
  double solid = 0.0;
  for (std::size_t i = 0; i < centres.size(); ++i) solid += sphere_volume_inside(m, centres[i], radii[i]);
  const double v = m.volume();
  return v > 0.0 ? 1.0 - solid / v : 0.0;
}

}  // namespace hilldem
