#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/core/sym_eigen.hpp"

using namespace hilldem;

namespace {

constexpr double kPi = std::numbers::pi;

double max_rel(const Vec3& a, const Vec3& b) {
  double e = 0.0;
  for (int d = 0; d < 3; ++d) e = std::max(e, std::abs(a[d] - b[d]) / std::max(std::abs(a[d]), std::abs(b[d])));
  return e;
}

// A 3-pebble asymmetric clump [m].
Pebbles three_pebbles() { return {{{0.0, 0.0, 0.0}, {0.9e-3, 0.2e-3, 0.0}, {0.1e-3, 0.8e-3, 0.5e-3}}, {0.6e-3, 0.5e-3, 0.4e-3}}; }

// The lens of two spheres by direct integration along the axis (z from centre 1, axis to centre 2):
// for z in the lens the disc radius is the smaller of the two spheres' discs. Simpson, 20000 panels.
struct LensCheck {
  double volume, z_first, zz, xx;  // ∫dV, ∫z dV, ∫z² dV, ∫x² dV
};
LensCheck lens_by_quadrature(double r1, double r2, double d) {
  auto disc2 = [&](double z) {
    const double a = r1 * r1 - z * z, b = r2 * r2 - (z - d) * (z - d);
    return std::max(0.0, std::min(a, b));
  };
  const double lo = d - r2, hi = r1;
  const int n = 20000;
  const double h = (hi - lo) / n;
  LensCheck s{0, 0, 0, 0};
  for (int i = 0; i <= n; ++i) {
    const double z = lo + i * h, w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    const double q = disc2(z);
    s.volume += w * kPi * q, s.z_first += w * kPi * q * z, s.zz += w * kPi * q * z * z, s.xx += w * kPi * q * q / 4.0;
  }
  for (double* x : {&s.volume, &s.z_first, &s.zz, &s.xx}) *x *= h / 3.0;
  return s;
}

}  // namespace

TEST(SymEigen, DiagonalisesAndIsARotation) {
  Mat3 a;
  const double v[3][3] = {{4.0, 1.0, -2.0}, {1.0, 2.0, 0.5}, {-2.0, 0.5, 3.0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a(i, j) = v[i][j];
  const SymEigen e = sym_eigen(a);
  EXPECT_LT(e.values.x, e.values.y);
  EXPECT_LT(e.values.y, e.values.z);
  EXPECT_NEAR(e.values.x + e.values.y + e.values.z, 9.0, 1e-14);  // the trace
  const Mat3 d = transpose(e.vectors) * a * e.vectors;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(d(i, j), i == j ? e.values[i] : 0.0, 1e-14);
  EXPECT_NEAR(dot(e.vectors.column(0), cross(e.vectors.column(1), e.vectors.column(2))), 1.0, 1e-14);
  // characteristic polynomial: det(A − λ1) = 0 for each value
  for (int k = 0; k < 3; ++k) {
    Mat3 m = a + Mat3::identity() * -e.values[k];
    EXPECT_NEAR(dot(m.column(0), cross(m.column(1), m.column(2))), 0.0, 1e-12);
  }
}

TEST(ClumpTemplate, OnePebbleIsTheSphereExactly) {
  const double r = 2.5e-3, rho = 2650.0;  // [m], [kg/m³]
  const ClumpTemplate t = make_template({{{1e-3, -2e-3, 3e-3}}, {r}}, rho);
  const double m = rho * 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_EQ(t.method, MassMethod::Exact);
  EXPECT_NEAR(t.mass, m, 1e-15 * m);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(t.principal_inertia[d], 0.4 * m * r * r, 1e-13 * m * r * r);
  EXPECT_NEAR(t.centre_of_mass.x, 1e-3, 1e-18);
  EXPECT_NEAR(norm(t.pebbles.position[0]), 0.0, 1e-18);
  EXPECT_NEAR(t.equal_volume_diameter(), 2 * r, 1e-15);
  // Isotropic to the bit at any radius and scale, so that its clumps take the ball's spin update.
  for (const double radius : {1.0, 0.3, 2.5e-3, 4e-3, 4.37e-3, 5.1e-3}) {
    const ClumpTemplate u = make_template({{{0.2, -0.1, 0.05}}, {radius}}, rho);
    for (const ClumpTemplate& v : {u, u.scaled(8.74e-3, SizeMeasure::EnclosingDiameter), u.scaled(1.02e-2)}) {
      EXPECT_EQ(v.principal_inertia.x, v.principal_inertia.y) << radius;
      EXPECT_EQ(v.principal_inertia.y, v.principal_inertia.z) << radius;
    }
  }
}

TEST(ClumpTemplate, TwoOverlappingPebblesMatchTheLensByQuadrature) {
  // Union = V1 + V2 − lens; its axial moments against an independent quadrature of the lens.
  const double r1 = 1.0e-3, r2 = 0.7e-3, d = 1.2e-3, rho = 2000.0;
  const Vec3 e = unit_or_zero(Vec3{1.0, 2.0, -0.5}), c1{0.3e-3, 0.1e-3, -0.2e-3};
  const GeometricMoments g = union_moments_exact({{c1, c1 + e * d}, {r1, r2}});
  const LensCheck lens = lens_by_quadrature(r1, r2, d);
  const double v1 = 4.0 / 3.0 * kPi * r1 * r1 * r1, v2 = 4.0 / 3.0 * kPi * r2 * r2 * r2;
  const double volume = v1 + v2 - lens.volume;
  EXPECT_NEAR(g.volume, volume, 1e-10 * volume);
  // axial first moment about centre 1: V2 d − ∫_lens z
  const double first_axial = v2 * d - lens.z_first;
  EXPECT_NEAR(dot(g.first - c1 * g.volume, e), first_axial, 1e-10 * std::abs(first_axial));
  // inertia about the axis through the centres (centre 1): ∫(x²+y²) = 2∫x², spheres (2/5)V r² each
  const double i_axis = 0.4 * v1 * r1 * r1 + 0.4 * v2 * r2 * r2 - 2.0 * lens.xx;
  const Mat3 j = central_inertia(g);
  EXPECT_NEAR(dot(e, j * e), i_axis, 1e-10 * i_axis);
  // transverse, about centre 1: ∫(x² + z²) = sphere 1 + sphere 2 about centre 1 − lens
  const double i_perp_c1 = 0.4 * v1 * r1 * r1 + (0.4 * v2 * r2 * r2 + v2 * d * d) - (lens.xx + lens.zz);
  const double c_axial = first_axial / volume;
  const double i_perp = i_perp_c1 - volume * c_axial * c_axial;  // parallel axis to the centroid
  const ClumpTemplate t = make_template({{c1, c1 + e * d}, {r1, r2}}, rho);
  EXPECT_NEAR(t.mass, rho * volume, 1e-10 * rho * volume);
  // axisymmetric: I1 about the axis, I2 = I3 transverse
  EXPECT_NEAR(t.principal_inertia.x, rho * i_axis, 1e-10 * rho * i_axis);
  EXPECT_NEAR(t.principal_inertia.y, rho * i_perp, 1e-10 * rho * i_perp);
  EXPECT_NEAR(t.principal_inertia.z, rho * i_perp, 1e-10 * rho * i_perp);
  // the principal axis of I1 is the line of centres
  EXPECT_NEAR(std::abs(dot(to_matrix(t.orientation).column(0), e)), 1.0, 1e-12);
}

TEST(ClumpTemplate, TwoPebblesApartOrNested) {
  const Pebbles apart{{{0, 0, 0}, {3e-3, 0, 0}}, {1e-3, 1e-3}};
  const GeometricMoments g = union_moments_exact(apart);
  const double v = 4.0 / 3.0 * kPi * 1e-9;
  EXPECT_NEAR(g.volume, 2 * v, 1e-15 * v);
  const Pebbles nested{{{0, 0, 0}, {0.2e-3, 0, 0}}, {1e-3, 0.5e-3}};
  EXPECT_NEAR(union_moments_exact(nested).volume, v, 1e-15 * v);
  EXPECT_NEAR(union_moments_exact(nested).first.x, 0.0, 1e-25);
}

TEST(ClumpTemplate, ColumnsOnASphereWithinTheStatedAccuracy) {
  const double r = 0.7e-3;
  const Pebbles one{{{0.12e-3, -0.05e-3, 0.3e-3}}, {r}};
  const GeometricMoments exact = sphere_moments(one.position[0], r);
  const Vec3 i_exact = Vec3{1, 1, 1} * (0.4 * exact.volume * r * r);
  double err_32 = 0.0, err_512 = 0.0;
  for (int n : {32, kDefaultColumns, 512}) {
    const GeometricMoments g = union_moments_columns(one, n);
    const Mat3 j = central_inertia(g);
    const double err = std::max(std::abs(g.volume / exact.volume - 1.0),
                                max_rel({j(0, 0), j(1, 1), j(2, 2)}, i_exact));
    EXPECT_LT(norm(g.first / g.volume - one.position[0]), 1e-9 * r) << n;
    if (n == kDefaultColumns) {
      EXPECT_LE(err, 1e-3);
    }
    if (n == 32) err_32 = err;
    if (n == 512) err_512 = err;
  }
  EXPECT_LT(err_512, err_32 / 256.0);  // falls at least as n^-2 from 32 to 512
}

TEST(ClumpTemplate, ColumnsAgreeWithTheClosedFormForTwoPebbles) {
  const Pebbles two{{{0, 0, 0}, {0.6e-3, 0.3e-3, -0.2e-3}}, {0.5e-3, 0.4e-3}};
  const ClumpTemplate ex = make_template(two, 2650.0), col = make_template_columns(two, 2650.0, kDefaultColumns);
  EXPECT_EQ(col.method, MassMethod::Columns);
  EXPECT_NEAR(col.volume, ex.volume, 1e-3 * ex.volume);
  EXPECT_LT(max_rel(col.principal_inertia, ex.principal_inertia), 1e-3);
  EXPECT_LT(norm(col.centre_of_mass - ex.centre_of_mass), 1e-3 * 0.5e-3);
}

TEST(ClumpTemplate, ThreePebblesAgainstFinerColumnsAndInvariance) {
  const Pebbles p = three_pebbles();
  const ClumpTemplate t = make_template(p, 2650.0);
  const ClumpTemplate fine = make_template_columns(p, 2650.0, 1024);
  EXPECT_EQ(t.method, MassMethod::Columns);
  EXPECT_LT(max_rel(t.principal_inertia, fine.principal_inertia), 1e-3);
  EXPECT_NEAR(t.volume, fine.volume, 1e-3 * fine.volume);
  // asymmetric: three distinct moments
  EXPECT_GT(t.principal_inertia.y / t.principal_inertia.x, 1.05);
  EXPECT_GT(t.principal_inertia.z / t.principal_inertia.y, 1.05);
  // the union is less than the sum of the spheres
  double sum = 0.0;
  for (double r : p.radius) sum += 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_LT(t.volume, sum);
  // principal frame: the pebbles' centroid weighting is centred, the reference positions come back
  for (std::size_t k = 0; k < p.size(); ++k) EXPECT_LT(norm(t.reference_position(k) - p.position[k]), 1e-15);
  // translated and rotated pebbles: the same mass properties (at fine resolution the grid's own
  // orientation error is small)
  const Quat q = from_rotation_vector({0.4, -1.1, 0.7});
  Pebbles moved = p;
  for (Vec3& x : moved.position) x = rotate(q, x) + Vec3{5e-3, -2e-3, 1e-3};
  const ClumpTemplate fine_moved = make_template_columns(moved, 2650.0, 1024);
  EXPECT_LT(max_rel(fine_moved.principal_inertia, fine.principal_inertia), 2e-4);
  EXPECT_NEAR(fine_moved.volume, fine.volume, 2e-4 * fine.volume);
  EXPECT_LT(norm(fine_moved.centre_of_mass - (rotate(q, fine.centre_of_mass) + Vec3{5e-3, -2e-3, 1e-3})), 1e-8);  // 1e-5 of a pebble radius
  // the principal-frame pebbles are those of the unmoved template up to axis signs
  for (std::size_t k = 0; k < p.size(); ++k)
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(std::abs(fine_moved.pebbles.position[k][d]), std::abs(fine.pebbles.position[k][d]), 2e-7);
}

TEST(ClumpTemplate, TranslationAndRotationExactForTwoPebbles) {
  const Pebbles p{{{0, 0, 0}, {0.6e-3, 0.3e-3, -0.2e-3}}, {0.5e-3, 0.4e-3}};
  const ClumpTemplate t = make_template(p, 2650.0);
  const Quat q = from_rotation_vector({-0.3, 0.8, 2.0});
  Pebbles moved = p;
  for (Vec3& x : moved.position) x = rotate(q, x) + Vec3{1.0, 2.0, 3.0};
  const ClumpTemplate tm = make_template(moved, 2650.0);
  EXPECT_LT(max_rel(tm.principal_inertia, t.principal_inertia), 1e-12);
  EXPECT_NEAR(tm.volume, t.volume, 1e-13 * t.volume);
}

TEST(ClumpTemplate, UserMassProperties) {
  const Pebbles p = three_pebbles();
  // a tensor with a known decomposition: R diag(1, 2, 3)·1e-12 Rᵀ
  const Quat q = from_rotation_vector({0.2, 0.5, -0.9});
  const Mat3 r = to_matrix(q);
  const Mat3 j = r * Mat3::diagonal(Vec3{1e-12, 2e-12, 3e-12}) * transpose(r);
  const ClumpTemplate t = make_template_user(p, 2650.0, 1e-9, {1e-4, 0, 0}, j);
  EXPECT_EQ(t.method, MassMethod::User);
  EXPECT_NEAR(t.mass, 2650.0 * 1e-9, 1e-20);
  EXPECT_LT(max_rel(t.principal_inertia, {1e-12, 2e-12, 3e-12}), 1e-12);
  const Mat3 back = to_matrix(t.orientation) * Mat3::diagonal(t.principal_inertia) * transpose(to_matrix(t.orientation));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(back(a, b), j(a, b), 1e-24);
  Mat3 bad = j;
  bad(0, 1) += 1e-13;
  EXPECT_THROW(make_template_user(p, 2650.0, 1e-9, {}, bad), InputError);
  EXPECT_THROW(make_template_user(p, 2650.0, 1e-9, {}, j * -1.0), InputError);
}

TEST(ClumpTemplate, ScaledAndRotated) {
  const ClumpTemplate t = make_template(three_pebbles(), 2650.0);
  const ClumpTemplate s = t.scaled(10e-3);  // equal-volume diameter 10 mm
  EXPECT_NEAR(s.equal_volume_diameter(), 10e-3, 1e-15);
  const double f = 10e-3 / t.equal_volume_diameter();
  EXPECT_NEAR(s.mass, t.mass * f * f * f, 1e-12 * s.mass);
  EXPECT_LT(max_rel(s.principal_inertia, t.principal_inertia * std::pow(f, 5)), 1e-13);
  EXPECT_NEAR(s.pebbles.radius[1], t.pebbles.radius[1] * f, 1e-18);
  // scaled equals recomputed from scaled pebbles (to the column accuracy; both at the same n)
  Pebbles big = three_pebbles();
  for (Vec3& x : big.position) x = x * f;
  for (double& r : big.radius) r *= f;
  const ClumpTemplate direct = make_template(big, 2650.0);
  EXPECT_LT(max_rel(direct.principal_inertia, s.principal_inertia), 1e-12);
  // the other size measure: the enclosing diameter about the centre of mass
  const ClumpTemplate e = t.scaled(10e-3, SizeMeasure::EnclosingDiameter);
  EXPECT_NEAR(e.size(SizeMeasure::EnclosingDiameter), 10e-3, 1e-15);
  double reach = 0.0;
  for (std::size_t k = 0; k < 3; ++k) reach = std::max(reach, norm(e.pebbles.position[k]) + e.pebbles.radius[k]);
  EXPECT_NEAR(2.0 * reach, 10e-3, 1e-15);
  EXPECT_GT(e.size(SizeMeasure::EnclosingDiameter), e.size(SizeMeasure::EqualVolumeDiameter));
  EXPECT_LT(e.mass, s.mass);  // the same size by a larger measure is a smaller clump
  // rotated: reference positions turn by q about the origin of the pebbles' frame, mass unchanged
  const Quat q = from_axis_angle({0, 0, 1}, kPi / 3);
  const ClumpTemplate r = t.rotated(q);
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_LT(norm(r.reference_position(k) - rotate(q, t.reference_position(k))), 1e-18);
  EXPECT_EQ(r.principal_inertia, t.principal_inertia);
  EXPECT_THROW(make_template({{}, {}}, 2650.0), InputError);
  EXPECT_THROW(make_template({{{0, 0, 0}}, {-1.0}}, 2650.0), InputError);
  EXPECT_THROW(make_template({{{0, 0, 0}}, {1.0}}, 0.0), InputError);
}
