#include "hilldem/bodies/clump_template.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "hilldem/core/error.hpp"
#include "hilldem/core/sym_eigen.hpp"

namespace hilldem {

namespace {

constexpr double kPi = std::numbers::pi;

// The moments of solid g moved by o [m]: first + V o, S + o firstᵀ + first oᵀ + V o oᵀ.
GeometricMoments shifted(const GeometricMoments& g, const Vec3& o) {
  GeometricMoments r = g;
  r.first = g.first + o * g.volume;
  r.second = g.second + outer(o, g.first) + outer(g.first, o) + outer(o, o) * g.volume;
  return r;
}

// The slab z0 ≤ z ≤ z1 of a sphere of radius r centred at c, z along the unit axis e from c. With
// ρ(z)² = r² − z², a disc's area is π ρ², its ∫x² is π ρ⁴/4, so (antiderivatives in z):
//   V = π (r² z − z³/3),  ∫z dV = π (r² z²/2 − z⁴/4),  ∫z² dV = π (r² z³/3 − z⁵/5),
//   ∫x² dV = ∫y² dV = (π/4)(r⁴ z − 2 r² z³/3 + z⁵/5);
// the mixed moments vanish by symmetry about the axis.
GeometricMoments sphere_slab(const Vec3& c, const Vec3& e, double r, double z0, double z1) {
  const double r2 = r * r;
  auto vol = [&](double z) { return kPi * (r2 * z - z * z * z / 3.0); };
  auto mz = [&](double z) { return kPi * (r2 * z * z / 2.0 - z * z * z * z / 4.0); };
  auto mzz = [&](double z) { return kPi * (r2 * z * z * z / 3.0 - std::pow(z, 5) / 5.0); };
  auto mxx = [&](double z) { return kPi / 4.0 * (r2 * r2 * z - 2.0 * r2 * z * z * z / 3.0 + std::pow(z, 5) / 5.0); };
  GeometricMoments local;
  local.volume = vol(z1) - vol(z0);
  local.first = e * (mz(z1) - mz(z0));
  const Mat3 ee = outer(e, e);
  local.second = (Mat3::identity() + ee * -1.0) * (mxx(z1) - mxx(z0)) + ee * (mzz(z1) - mzz(z0));
  return shifted(local, c);
}

void check_pebbles(const Pebbles& p, double density) {
  if (p.size() == 0) throw InputError("clump template: no pebbles");
  if (p.position.size() != p.radius.size()) throw InputError("clump template: pebble positions and radii differ in count");
  for (std::size_t k = 0; k < p.size(); ++k)
    if (!(p.radius[k] > 0.0) || !std::isfinite(p.radius[k]))
      throw InputError("clump template: pebble " + std::to_string(k) + " radius must be > 0 m, got " +
                       std::to_string(p.radius[k]));
  if (!(density > 0.0) || !std::isfinite(density))
    throw InputError("clump template: density must be > 0 kg/m^3, got " + std::to_string(density));
}

// The template in the principal frame of the inertia tensor J [kg m²] about centre c [m].
ClumpTemplate in_principal_frame(const Pebbles& p, double density, double volume, const Vec3& c, const Mat3& j) {
  const SymEigen e = sym_eigen(j);
  ClumpTemplate t;
  t.density = density;
  t.volume = volume;
  t.mass = density * volume;
  t.principal_inertia = e.values;
  t.centre_of_mass = c;
  t.orientation = from_matrix(e.vectors);
  const Mat3 rt = transpose(to_matrix(t.orientation));
  t.pebbles.radius = p.radius;
  for (const Vec3& x : p.position) t.pebbles.position.push_back(rt * (x - c));
  return t;
}

// The mean of the pebble centres [m]: the moments are taken about it, so that the central inertia
// does not lose digits to a far origin (|o|²/r² of them).
Vec3 mean_centre(const Pebbles& p) {
  Vec3 o;
  for (const Vec3& x : p.position) o += x;
  return o / static_cast<double>(p.size());
}
Pebbles relative_to(const Pebbles& p, const Vec3& o) {
  Pebbles q = p;
  for (Vec3& x : q.position) x -= o;
  return q;
}

// g: the moments of the pebbles relative to o.
ClumpTemplate from_moments(const Pebbles& p, double density, const GeometricMoments& g, const Vec3& o) {
  return in_principal_frame(p, density, g.volume, o + g.first / g.volume, central_inertia(g) * density);
}

}  // namespace

GeometricMoments operator+(const GeometricMoments& a, const GeometricMoments& b) {
  return {a.volume + b.volume, a.first + b.first, a.second + b.second};
}

// A whole sphere in closed form: V = 4/3 π r³ and ∫x² dV = ∫y² dV = ∫z² dV = 4/15 π r⁵ about its
// centre, equal to the bit (the slab integrals along one axis differ from the others in the last
// bit), so that a one-pebble template has I1 = I2 = I3 exactly and its clumps take the ball's spin
// update (motion/rigid_body.hpp).
GeometricMoments sphere_moments(const Vec3& c, double r) {
  GeometricMoments local;
  local.volume = 4.0 / 3.0 * kPi * r * r * r;
  local.second = Mat3::identity() * (4.0 / 15.0 * kPi * std::pow(r, 5));
  return shifted(local, c);
}

// Two spheres (r1, r2, centres d apart along e) that intersect, |r1 − r2| < d < r1 + r2, meet on the
// plane at a = (d² + r1² − r2²)/(2d) from centre 1 (the radical plane). The union is sphere 1 on its
// side of the plane (z ∈ [−r1, a]) and sphere 2 on the other (z ∈ [a − d, r2] from centre 2), two
// disjoint slabs: V = V1 + V2 − V_lens without forming the lens (Weisstein, "Sphere-Sphere
// Intersection", MathWorld; the lens is the two caps of heights r1 − a and r2 − d + a).
GeometricMoments union_moments_exact(const Pebbles& p) {
  if (p.size() == 1) return sphere_moments(p.position[0], p.radius[0]);
  if (p.size() != 2) throw std::invalid_argument("union_moments_exact: one or two pebbles");
  const double r1 = p.radius[0], r2 = p.radius[1];
  const Vec3 c1 = p.position[0], c2 = p.position[1];
  const double d = norm(c2 - c1);
  if (d >= r1 + r2) return sphere_moments(c1, r1) + sphere_moments(c2, r2);
  if (d <= std::abs(r1 - r2)) return r1 >= r2 ? sphere_moments(c1, r1) : sphere_moments(c2, r2);
  const Vec3 e = (c2 - c1) / d;
  const double a = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
  return sphere_slab(c1, e, r1, -r1, a) + sphere_slab(c2, e, r2, a - d, r2);
}

GeometricMoments union_moments_columns(const Pebbles& p, int n) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (std::size_t k = 0; k < p.size(); ++k)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p.position[k][d] - p.radius[k]);
      hi[d] = std::max(hi[d], p.position[k][d] + p.radius[k]);
    }
  // Coordinates about the box's centre o, so that the second moments do not cancel.
  const Vec3 o = (lo + hi) * 0.5;
  const double h = std::max(hi.x - lo.x, hi.y - lo.y) / n;
  const int nx = std::max(1, static_cast<int>(std::ceil((hi.x - lo.x) / h - 1e-9)));
  const int ny = std::max(1, static_cast<int>(std::ceil((hi.y - lo.y) / h - 1e-9)));
  const double area = h * h, cell_x2 = h * h / 12.0;  // ∫ over a cell of (x − x_c)² dx / h
  struct Chord {
    double z0, z1;
  };
  std::vector<Chord> chords;
  GeometricMoments g;
  double sxx = 0, syy = 0, szz = 0, sxy = 0, sxz = 0, syz = 0, v = 0, fx = 0, fy = 0, fz = 0;
  for (int i = 0; i < nx; ++i) {
    const double x = (i + 0.5 - 0.5 * nx) * h;
    for (int jj = 0; jj < ny; ++jj) {
      const double y = (jj + 0.5 - 0.5 * ny) * h;
      chords.clear();
      for (std::size_t k = 0; k < p.size(); ++k) {
        const Vec3 c = p.position[k] - o;
        const double q = p.radius[k] * p.radius[k] - (x - c.x) * (x - c.x) - (y - c.y) * (y - c.y);
        if (q > 0.0) {
          const double hz = std::sqrt(q);
          chords.push_back({c.z - hz, c.z + hz});
        }
      }
      if (chords.empty()) continue;
      std::sort(chords.begin(), chords.end(), [](const Chord& a, const Chord& b) { return a.z0 < b.z0; });
      double l = 0.0, m1 = 0.0, m2 = 0.0;  // ∫dz, ∫z dz, ∫z² dz over the union of the chords
      double z0 = chords[0].z0, z1 = chords[0].z1;
      auto close = [&] {
        l += z1 - z0;
        m1 += (z1 * z1 - z0 * z0) / 2.0;
        m2 += (z1 * z1 * z1 - z0 * z0 * z0) / 3.0;
      };
      for (std::size_t k = 1; k < chords.size(); ++k) {
        if (chords[k].z0 > z1) {
          close();
          z0 = chords[k].z0, z1 = chords[k].z1;
        } else {
          z1 = std::max(z1, chords[k].z1);
        }
      }
      close();
      v += l, fx += x * l, fy += y * l, fz += m1;
      sxx += l * (x * x + cell_x2), syy += l * (y * y + cell_x2), sxy += l * x * y;
      sxz += x * m1, syz += y * m1, szz += m2;
    }
  }
  g.volume = v * area;
  g.first = Vec3{fx, fy, fz} * area;
  g.second.m[0][0] = sxx * area, g.second.m[1][1] = syy * area, g.second.m[2][2] = szz * area;
  g.second.m[0][1] = g.second.m[1][0] = sxy * area;
  g.second.m[0][2] = g.second.m[2][0] = sxz * area;
  g.second.m[1][2] = g.second.m[2][1] = syz * area;
  return shifted(g, o);
}

Mat3 central_inertia(const GeometricMoments& g) {
  const Vec3 c = g.first / g.volume;
  const Mat3 s = g.second + outer(c, c) * -g.volume;
  const double tr = s(0, 0) + s(1, 1) + s(2, 2);
  return Mat3::identity() * tr + s * -1.0;
}

double ClumpTemplate::equal_volume_diameter() const { return std::cbrt(6.0 * volume / kPi); }

ClumpTemplate ClumpTemplate::scaled_by(double s) const {
  if (!(s > 0.0) || !std::isfinite(s)) throw InputError("clump template: scale factor must be > 0, got " + std::to_string(s));
  ClumpTemplate t = *this;
  for (Vec3& x : t.pebbles.position) x = x * s;
  for (double& r : t.pebbles.radius) r *= s;
  t.centre_of_mass = centre_of_mass * s;
  const double s3 = s * s * s;
  t.volume = volume * s3;
  t.mass = mass * s3;
  t.principal_inertia = principal_inertia * (s3 * s * s);
  return t;
}

double ClumpTemplate::size(SizeMeasure measure) const {
  switch (measure) {
    case SizeMeasure::EqualVolumeDiameter:
      return equal_volume_diameter();
    case SizeMeasure::EnclosingDiameter: {
      double r = 0.0;
      for (std::size_t k = 0; k < pebbles.size(); ++k) r = std::max(r, norm(pebbles.position[k]) + pebbles.radius[k]);
      return 2.0 * r;
    }
  }
  return equal_volume_diameter();
}

ClumpTemplate ClumpTemplate::scaled(double target, SizeMeasure measure) const {
  if (!(target > 0.0) || !std::isfinite(target))
    throw InputError("clump template: size must be > 0 m, got " + std::to_string(target));
  return scaled_by(target / size(measure));
}

ClumpTemplate ClumpTemplate::rotated(const Quat& q) const {
  ClumpTemplate t = *this;
  t.orientation = normalized(q * orientation);
  t.centre_of_mass = rotate(q, centre_of_mass);
  return t;
}

Vec3 ClumpTemplate::reference_position(std::size_t k) const {
  return centre_of_mass + rotate(orientation, pebbles.position[k]);
}

ClumpTemplate make_template(const Pebbles& p, double density, int n) {
  check_pebbles(p, density);
  if (p.size() <= 2) {
    const Vec3 o = mean_centre(p);
    ClumpTemplate t = from_moments(p, density, union_moments_exact(relative_to(p, o)), o);
    t.method = MassMethod::Exact;
    return t;
  }
  return make_template_columns(p, density, n);
}

ClumpTemplate make_template_columns(const Pebbles& p, double density, int n) {
  check_pebbles(p, density);
  if (n < 8) throw InputError("clump template: column count must be >= 8, got " + std::to_string(n));
  const Vec3 o = mean_centre(p);
  ClumpTemplate t = from_moments(p, density, union_moments_columns(relative_to(p, o), n), o);
  t.method = MassMethod::Columns;
  t.columns = n;
  return t;
}

ClumpTemplate make_template_user(const Pebbles& p, double density, double volume, const Vec3& centre_of_mass,
                                 const Mat3& inertia) {
  check_pebbles(p, density);
  if (!(volume > 0.0)) throw InputError("clump template: volume must be > 0 m^3, got " + std::to_string(volume));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < i; ++j)
      if (std::abs(inertia(i, j) - inertia(j, i)) > 1e-12 * (std::abs(inertia(i, i)) + std::abs(inertia(j, j))))
        throw InputError("clump template: the inertia tensor must be symmetric");
  ClumpTemplate t = in_principal_frame(p, density, volume, centre_of_mass, inertia);
  if (!(t.principal_inertia.x > 0.0)) throw InputError("clump template: the inertia tensor must be positive definite");
  t.method = MassMethod::User;
  return t;
}

}  // namespace hilldem
