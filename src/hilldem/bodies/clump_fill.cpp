#include "hilldem/bodies/clump_fill.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <queue>
#include <string>
#include <tuple>
#include <vector>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {

// Eberly's root of F(s) = Σ (r_i z_i / (s + r_i))² − 1 on s ∈ [z_last − 1, |r z| − 1] by bisection
// to the last bit (s is the Lagrange parameter over the smallest semi-axis squared).
template <int N>
double bisect_root(const double (&r)[N], const double (&z)[N], double g) {
  double n[N];
  double len2 = 0.0;
  for (int i = 0; i < N; ++i) {
    n[i] = r[i] * z[i];
    len2 += n[i] * n[i];
  }
  double s0 = z[N - 1] - 1.0;
  double s1 = g < 0.0 ? 0.0 : std::sqrt(len2) - 1.0;
  double s = 0.0;
  for (int it = 0; it < 2000; ++it) {
    s = 0.5 * (s0 + s1);
    if (s == s0 || s == s1) break;
    double f = -1.0;
    for (int i = 0; i < N; ++i) {
      const double ratio = n[i] / (s + r[i]);
      f += ratio * ratio;
    }
    if (f > 0.0) s0 = s;
    else if (f < 0.0) s1 = s;
    else break;
  }
  return s;
}

// Distance from (y0, y1) ≥ 0 to the ellipse with semi-axes e0 ≥ e1 > 0.
double ellipse_distance(double e0, double e1, double y0, double y1) {
  if (y1 > 0.0) {
    if (y0 > 0.0) {
      const double z[2] = {y0 / e0, y1 / e1};
      const double g = z[0] * z[0] + z[1] * z[1] - 1.0;
      if (g == 0.0) return 0.0;
      const double r[2] = {(e0 / e1) * (e0 / e1), 1.0};
      const double s = bisect_root<2>(r, z, g);
      const double x0 = r[0] * y0 / (s + r[0]), x1 = y1 / (s + 1.0);
      return std::hypot(x0 - y0, x1 - y1);
    }
    return std::abs(y1 - e1);
  }
  const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
  if (numer0 < denom0) {
    const double xde0 = numer0 / denom0;
    const double x0 = e0 * xde0, x1 = e1 * std::sqrt(1.0 - xde0 * xde0);
    return std::hypot(x0 - y0, x1);
  }
  return std::abs(y0 - e0);
}

// Distance from y ≥ 0 (each component) to the ellipsoid with semi-axes e0 ≥ e1 ≥ e2 > 0.
double ellipsoid_distance(double e0, double e1, double e2, double y0, double y1, double y2) {
  if (y2 > 0.0) {
    if (y1 > 0.0) {
      if (y0 > 0.0) {
        const double z[3] = {y0 / e0, y1 / e1, y2 / e2};
        const double g = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] - 1.0;
        if (g == 0.0) return 0.0;
        const double r[3] = {(e0 / e2) * (e0 / e2), (e1 / e2) * (e1 / e2), 1.0};
        const double s = bisect_root<3>(r, z, g);
        const double x0 = r[0] * y0 / (s + r[0]), x1 = r[1] * y1 / (s + r[1]), x2 = y2 / (s + 1.0);
        return std::sqrt((x0 - y0) * (x0 - y0) + (x1 - y1) * (x1 - y1) + (x2 - y2) * (x2 - y2));
      }
      return ellipse_distance(e1, e2, y1, y2);
    }
    if (y0 > 0.0) return ellipse_distance(e0, e2, y0, y2);
    return std::abs(y2 - e2);
  }
  // y2 = 0: the closest point is off the plane z = 0 when the foot of the normal lies inside it.
  const double denom0 = e0 * e0 - e2 * e2, denom1 = e1 * e1 - e2 * e2;
  const double numer0 = e0 * y0, numer1 = e1 * y1;
  if (numer0 < denom0 && numer1 < denom1) {
    const double xde0 = numer0 / denom0, xde1 = numer1 / denom1;
    const double discr = 1.0 - xde0 * xde0 - xde1 * xde1;
    if (discr > 0.0) {
      const double x0 = e0 * xde0, x1 = e1 * xde1, x2 = e2 * std::sqrt(discr);
      return std::sqrt((x0 - y0) * (x0 - y0) + (x1 - y1) * (x1 - y1) + x2 * x2);
    }
  }
  return ellipse_distance(e0, e1, y0, y1);
}

}  // namespace

EllipsoidShape::EllipsoidShape(double a, double b, double c) : a_(a), b_(b), c_(c) {
  if (!(c > 0.0) || !(b >= c) || !(a >= b) || !std::isfinite(a))
    throw InputError("ellipsoid: semi-axes must be a >= b >= c > 0 m, got a = " + std::to_string(a) +
                     ", b = " + std::to_string(b) + ", c = " + std::to_string(c));
}

double EllipsoidShape::volume() const { return 4.0 / 3.0 * std::numbers::pi * a_ * b_ * c_; }

double EllipsoidShape::inner_distance(const Vec3& x) const {
  const double q = x.x * x.x / (a_ * a_) + x.y * x.y / (b_ * b_) + x.z * x.z / (c_ * c_);
  if (!(q < 1.0)) return 0.0;
  if (a_ == c_) return a_ - norm(x);  // a sphere
  return ellipsoid_distance(a_, b_, c_, std::abs(x.x), std::abs(x.y), std::abs(x.z));
}

FillResult fill_shape(const FillShape& shape, const FillParams& f) {
  if (f.count < 1 || f.count > 10000) throw InputError("shape fill: count must be in [1, 10000], got " + std::to_string(f.count));
  if (!(f.smallest_ratio > 0.0) || !(f.smallest_ratio <= 1.0))
    throw InputError("shape fill: smallest_ratio must be in (0, 1], got " + std::to_string(f.smallest_ratio));
  if (!(f.fidelity > 0.0) || !(f.fidelity <= 1.0))
    throw InputError("shape fill: fidelity must be in (0, 1], got " + std::to_string(f.fidelity));
  if (f.resolution < 9 || f.resolution > 301)
    throw InputError("shape fill: resolution must be in [9, 301], got " + std::to_string(f.resolution));

  // The lattice: spacing h, 2 m_i + 1 points along axis i, centred on the box's centre.
  const Vec3 lo = shape.box_min(), hi = shape.box_max();
  const Vec3 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
  const int m = (f.resolution - 1) / 2;
  const double h = std::max({half.x, half.y, half.z}) / m;
  if (!(h > 0.0) || !std::isfinite(h)) throw InputError("shape fill: the shape's bounding box is empty or not finite");
  int mi[3];
  for (int i = 0; i < 3; ++i) mi[i] = std::min(m, static_cast<int>(std::ceil(half[i] / h)));
  const int nx = 2 * mi[0] + 1, ny = 2 * mi[1] + 1, nz = 2 * mi[2] + 1;
  const auto point = [&](int i, int j, int k) {
    return centre + Vec3{(i - mi[0]) * h, (j - mi[1]) * h, (k - mi[2]) * h};
  };
  const std::size_t total = static_cast<std::size_t>(nx) * ny * nz;
  std::vector<double> dist(total, 0.0);
  std::vector<std::uint8_t> covered(total, 0);
  std::size_t inside = 0;
  double largest = 0.0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const std::size_t idx = (static_cast<std::size_t>(i) * ny + j) * nz + k;
        dist[idx] = std::max(0.0, shape.inner_distance(point(i, j, k)));
        if (dist[idx] > 0.0) ++inside;
        largest = std::max(largest, dist[idx]);
      }
  if (inside == 0) throw InputError("shape fill: no lattice point lies inside the shape (raise resolution)");

  // Samples not yet covered inside the pebble at lattice index idx.
  const auto gain = [&](std::size_t idx) {
    const int i0 = static_cast<int>(idx / (static_cast<std::size_t>(ny) * nz));
    const int j0 = static_cast<int>((idx / nz) % ny), k0 = static_cast<int>(idx % nz);
    const double r = dist[idx], r2 = r * r;
    const int w = static_cast<int>(std::floor(r / h));
    std::size_t g = 0;
    for (int i = std::max(0, i0 - w); i <= std::min(nx - 1, i0 + w); ++i)
      for (int j = std::max(0, j0 - w); j <= std::min(ny - 1, j0 + w); ++j)
        for (int k = std::max(0, k0 - w); k <= std::min(nz - 1, k0 + w); ++k) {
          const std::size_t s = (static_cast<std::size_t>(i) * ny + j) * nz + k;
          if (covered[s] || dist[s] <= 0.0) continue;
          const double di = (i - i0) * h, dj = (j - j0) * h, dk = (k - k0) * h;
          if (di * di + dj * dj + dk * dk <= r2) ++g;
        }
    return g;
  };
  const auto cover = [&](std::size_t idx) {
    const int i0 = static_cast<int>(idx / (static_cast<std::size_t>(ny) * nz));
    const int j0 = static_cast<int>((idx / nz) % ny), k0 = static_cast<int>(idx % nz);
    const double r = dist[idx], r2 = r * r;
    const int w = static_cast<int>(std::floor(r / h));
    std::size_t g = 0;
    for (int i = std::max(0, i0 - w); i <= std::min(nx - 1, i0 + w); ++i)
      for (int j = std::max(0, j0 - w); j <= std::min(ny - 1, j0 + w); ++j)
        for (int k = std::max(0, k0 - w); k <= std::min(nz - 1, k0 + w); ++k) {
          const std::size_t s = (static_cast<std::size_t>(i) * ny + j) * nz + k;
          if (covered[s] || dist[s] <= 0.0) continue;
          const double di = (i - i0) * h, dj = (j - j0) * h, dk = (k - k0) * h;
          if (di * di + dj * dj + dk * dk <= r2) covered[s] = 1, ++g;
        }
    return g;
  };

  // Lazy greedy: each entry holds an upper bound of its gain (at first the lattice points a ball of
  // radius r + h√3/2 can hold, each owning a cell of volume h³) or its gain counted after pick `stamp`.
  // Highest gain first, then the lowest index.
  using Entry = std::tuple<double, std::int64_t, int>;  // gain (bound), −index, stamp
  std::priority_queue<Entry> queue;
  const double rmin = f.smallest_ratio * largest;
  for (std::size_t idx = 0; idx < total; ++idx)
    if (dist[idx] > 0.0 && dist[idx] >= rmin) {
      const double rb = dist[idx] / h + std::sqrt(3.0) / 2.0;
      queue.emplace(4.0 / 3.0 * std::numbers::pi * rb * rb * rb + 1.0, -static_cast<std::int64_t>(idx), -1);
    }
  FillResult out;
  std::size_t done = 0;
  int picks = 0;
  while (picks < f.count && !queue.empty() && static_cast<double>(done) < f.fidelity * static_cast<double>(inside)) {
    auto [bound, neg_idx, stamp] = queue.top();
    queue.pop();
    const std::size_t idx = static_cast<std::size_t>(-neg_idx);
    if (stamp != picks) {
      const std::size_t g = gain(idx);
      if (g > 0) queue.emplace(static_cast<double>(g), neg_idx, picks);
      continue;
    }
    (void)bound;
    done += cover(idx);
    const int i = static_cast<int>(idx / (static_cast<std::size_t>(ny) * nz));
    out.pebbles.position.push_back(point(i, static_cast<int>((idx / nz) % ny), static_cast<int>(idx % nz)));
    out.pebbles.radius.push_back(dist[idx]);
    ++picks;
  }
  out.sample_fidelity = static_cast<double>(done) / static_cast<double>(inside);
  return out;
}

}  // namespace hilldem
