#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hilldem/core/quaternion.hpp"

using namespace hilldem;

namespace {
constexpr double kPi = std::numbers::pi;
void expect_near(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}
}  // namespace

TEST(Quaternion, NinetyDegreesAboutZTakesXToY) {
  const Quat q = from_axis_angle({0, 0, 1}, kPi / 2);
  EXPECT_NEAR(q.w, std::sqrt(0.5), 3e-16);
  EXPECT_NEAR(q.z, std::sqrt(0.5), 3e-16);
  expect_near(rotate(q, {1, 0, 0}), {0, 1, 0}, 1e-15);
  expect_near(rotate(q, {0, 1, 0}), {-1, 0, 0}, 1e-15);
  expect_near(rotate(q, {0, 0, 1}), {0, 0, 1}, 1e-15);
  expect_near(to_matrix(q) * Vec3{1, 0, 0}, {0, 1, 0}, 1e-15);
}

TEST(Quaternion, ProductComposesFirstRightThenLeft) {
  const Quat qz = from_axis_angle({0, 0, 1}, kPi / 2), qx = from_axis_angle({1, 0, 0}, kPi / 2);
  // x →(qz) y →(qx) z
  expect_near(rotate(qx * qz, {1, 0, 0}), {0, 0, 1}, 1e-15);
  expect_near(rotate(qx, rotate(qz, {0.3, -0.7, 1.1})), rotate(qx * qz, {0.3, -0.7, 1.1}), 1e-15);
  // the conjugate undoes the rotation
  const Vec3 v{0.3, -0.7, 1.1};
  expect_near(rotate(conjugate(qx * qz), rotate(qx * qz, v)), v, 1e-15);
  // three quarter turns about z and one more is a full turn: −1, the same rotation
  const Quat full = qz * qz * qz * qz;
  EXPECT_NEAR(full.w, -1.0, 1e-15);
  EXPECT_NEAR(normalized(full).w, 1.0, 1e-15);
}

TEST(Quaternion, MatrixIsOrthonormalAndRoundTrips) {
  for (const Vec3 theta : {Vec3{0.3, -1.2, 2.0}, Vec3{3.1, 0.0, 0.0}, Vec3{0.0, -3.0, 0.1}, Vec3{0.1, 0.2, -3.1}}) {
    const Quat q = from_rotation_vector(theta);
    const Mat3 r = to_matrix(q);
    const Mat3 rtr = transpose(r) * r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(rtr(i, j), i == j ? 1.0 : 0.0, 1e-15);
    const double det = dot(r.column(0), cross(r.column(1), r.column(2)));
    EXPECT_NEAR(det, 1.0, 1e-15);
    const Quat back = from_matrix(r), qn = normalized(q);
    EXPECT_NEAR(back.w, qn.w, 1e-15);
    EXPECT_NEAR(back.x, qn.x, 1e-15);
    EXPECT_NEAR(back.y, qn.y, 1e-15);
    EXPECT_NEAR(back.z, qn.z, 1e-15);
    // R v equals q v q*
    expect_near(r * Vec3{0.4, 0.5, -0.6}, rotate(q, {0.4, 0.5, -0.6}), 1e-15);
  }
}

TEST(Quaternion, ExponentialMapSmallAndZero) {
  const Quat id = from_rotation_vector({0, 0, 0});
  EXPECT_EQ(id.w, 1.0);
  EXPECT_EQ(id.x, 0.0);
  EXPECT_EQ(id.y, 0.0);
  EXPECT_EQ(id.z, 0.0);
  // Small angles on both sides of the series switch (1e-4 rad) against sin/cos in long double.
  for (const double a : {1e-12, 1e-7, 9.99e-5, 1.01e-4, 1e-2}) {
    const Vec3 k = unit_or_zero(Vec3{1, -2, 0.5});
    const Quat q = from_rotation_vector(k * a);
    const long double h = 0.5L * a;
    EXPECT_NEAR(q.w, static_cast<double>(std::cos(h)), 1e-16);
    EXPECT_NEAR(q.x / k.x, static_cast<double>(std::sin(h)), 1e-16 * a + 1e-300);
    EXPECT_NEAR(norm2(q), 1.0, 5e-16);
  }
  // Integrating a constant spin: n steps of ω Δt about z make the angle n ω Δt.
  Quat q;
  const Vec3 omega{0, 0, 2.0};  // [rad/s]
  for (int i = 0; i < 1000; ++i) q = integrate_global(q, omega, 1e-3);
  expect_near(rotate(q, {1, 0, 0}), {std::cos(2.0), std::sin(2.0), 0.0}, 1e-13);
  Quat qb;
  for (int i = 0; i < 1000; ++i) qb = integrate_body(qb, omega, 1e-3);
  expect_near(rotate(qb, {1, 0, 0}), {std::cos(2.0), std::sin(2.0), 0.0}, 1e-13);
}
