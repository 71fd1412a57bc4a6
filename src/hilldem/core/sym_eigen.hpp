// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations (Golub & Van Loan,
// Matrix Computations, 4th ed., §8.5): each rotation zeroes one off-diagonal entry; sweeps repeat
// until the off-diagonal norm is below 1e-15 of the matrix's Frobenius norm (convergence is quadratic,
// so about 4 sweeps).
#pragma once

#include <algorithm>
#include <cmath>

#include "hilldem/core/mat3.hpp"

namespace hilldem {

struct SymEigen {
  Vec3 values;  // ascending
  Mat3 vectors;  // column k: the unit eigenvector of values[k]; a rotation (det +1)
};

inline SymEigen sym_eigen(const Mat3& a_in) {
  Mat3 a = a_in, v = Mat3::identity();
  double frob = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) frob += a(i, j) * a(i, j);
  const double tol = 1e-15 * std::sqrt(frob);
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = std::sqrt(2.0 * (a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2)));
    if (!(off > tol)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a(p, q) == 0.0) continue;
        // t = tan θ of the rotation that zeroes a(p, q), the smaller root (|θ| ≤ π/4).
        const double theta = (a(q, q) - a(p, p)) / (2.0 * a(p, q));
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A ← A J (columns p, q)
          const double akp = a(k, p), akq = a(k, q);
          a(k, p) = c * akp - s * akq, a(k, q) = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A ← Jᵀ A (rows p, q)
          const double apk = a(p, k), aqk = a(q, k);
          a(p, k) = c * apk - s * aqk, a(q, k) = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V ← V J
          const double vkp = v(k, p), vkq = v(k, q);
          v(k, p) = c * vkp - s * vkq, v(k, q) = s * vkp + c * vkq;
        }
      }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return a(i, i) < a(j, j); });
  SymEigen e;
  for (int k = 0; k < 3; ++k) {
    e.values[k] = a(order[k], order[k]);
    for (int r = 0; r < 3; ++r) e.vectors(r, k) = v(r, order[k]);
  }
  const Vec3 c2 = cross(e.vectors.column(0), e.vectors.column(1));
  if (dot(c2, e.vectors.column(2)) < 0.0)
    for (int r = 0; r < 3; ++r) e.vectors(r, 2) = -e.vectors(r, 2);
  return e;
}

}  // namespace hilldem
