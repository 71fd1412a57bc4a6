#include "hilldem/labtests/measure_region.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

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

double clump_volume_inside(const MeasurementCylinder& m, const std::vector<Vec3>& c, const std::vector<double>& r, double volume,
                           int n) {
  if (c.size() == 1) return sphere_volume_inside(m, c[0], r[0]);
  bool all_in = true, all_out = true;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double rho = std::hypot(c[k].x, c[k].y);
    all_in = all_in && rho + r[k] <= m.radius && c[k].z - r[k] >= m.z_lo && c[k].z + r[k] <= m.z_hi;
    all_out = all_out && (rho - r[k] >= m.radius || c[k].z - r[k] >= m.z_hi || c[k].z + r[k] <= m.z_lo);
    lo = Vec3{std::min(lo.x, c[k].x - r[k]), std::min(lo.y, c[k].y - r[k]), 0.0};
    hi = Vec3{std::max(hi.x, c[k].x + r[k]), std::max(hi.y, c[k].y + r[k]), 0.0};
  }
  if (all_in) return volume;
  if (all_out) return 0.0;
  const double hx = (hi.x - lo.x) / n, hy = (hi.y - lo.y) / n;
  std::vector<std::pair<double, double>> chords;
  double total = 0.0, inside = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = lo.x + (i + 0.5) * hx, y = lo.y + (j + 0.5) * hy;
      chords.clear();
      for (std::size_t k = 0; k < c.size(); ++k) {
        const double h2 = r[k] * r[k] - (x - c[k].x) * (x - c[k].x) - (y - c[k].y) * (y - c[k].y);
        if (h2 > 0.0) chords.emplace_back(c[k].z - std::sqrt(h2), c[k].z + std::sqrt(h2));
      }
      if (chords.empty()) continue;
      std::sort(chords.begin(), chords.end());
      const bool in_radius = x * x + y * y <= m.radius * m.radius;
      // The union of the chords: merge overlapping intervals in order of their lower ends.
      double a = chords[0].first, b = chords[0].second;
      auto close = [&] {
        total += b - a;
        if (in_radius) inside += std::max(0.0, std::min(b, m.z_hi) - std::max(a, m.z_lo));
      };
      for (std::size_t k = 1; k < chords.size(); ++k) {
        if (chords[k].first > b) {
          close();
          a = chords[k].first, b = chords[k].second;
        } else {
          b = std::max(b, chords[k].second);
        }
      }
      close();
    }
  return total > 0.0 ? volume * inside / total : 0.0;
}

double region_porosity(const MeasurementCylinder& m, const std::vector<Vec3>& centres, const std::vector<double>& radii) {
  double solid = 0.0;
  for (std::size_t i = 0; i < centres.size(); ++i) solid += sphere_volume_inside(m, centres[i], radii[i]);
  const double v = m.volume();
  return v > 0.0 ? 1.0 - solid / v : 0.0;
}

}  // namespace hilldem
