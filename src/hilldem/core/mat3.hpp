// Mat3: a plain 3×3 matrix of doubles (row-major) for rotation matrices [-] and inertia tensors [kg m²].
#pragma once

#include "hilldem/core/vec3.hpp"

namespace hilldem {

struct Mat3 {
  double m[3][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};

  static constexpr Mat3 identity() { return diagonal({1.0, 1.0, 1.0}); }
  static constexpr Mat3 diagonal(const Vec3& d) {
    Mat3 a;
    a.m[0][0] = d.x, a.m[1][1] = d.y, a.m[2][2] = d.z;
    return a;
  }
  constexpr double operator()(int i, int j) const { return m[i][j]; }
  constexpr double& operator()(int i, int j) { return m[i][j]; }
  constexpr Vec3 column(int j) const { return {m[0][j], m[1][j], m[2][j]}; }
};

constexpr Vec3 operator*(const Mat3& a, const Vec3& v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z, a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}
constexpr Mat3 operator*(const Mat3& a, const Mat3& b) {
  Mat3 c;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return c;
}
constexpr Mat3 operator+(Mat3 a, const Mat3& b) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a.m[i][j] += b.m[i][j];
  return a;
}
constexpr Mat3 operator*(Mat3 a, double s) {
  for (auto& row : a.m)
    for (double& x : row) x *= s;
  return a;
}
constexpr Mat3 transpose(const Mat3& a) {
  Mat3 t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.m[i][j] = a.m[j][i];
  return t;
}
// The tensor product a bᵀ.
constexpr Mat3 outer(const Vec3& a, const Vec3& b) {
  Mat3 c;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.m[i][j] = a[i] * b[j];
  return c;
}

}  // namespace hilldem
