#include "hilldem/labtests/universal_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "hilldem/core/error.hpp"
#include "hilldem/labtests/t307_sequences.hpp"

namespace hilldem {

namespace {

using Vec = std::array<double, 3>;
using Mat = std::array<Vec, 3>;

// Solves A x = b for a symmetric positive definite 3×3 A (Cholesky); false if A is not.
bool solve3(const Mat& a, const Vec& b, Vec& x) {
  Mat l{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) {
      double s = a[i][j];
      for (int k = 0; k < j; ++k) s -= l[i][k] * l[j][k];
      if (i == j) {
        if (!(s > 0.0)) return false;
        l[i][i] = std::sqrt(s);
      } else {
        l[i][j] = s / l[j][j];
      }
    }
  Vec y{};
  for (int i = 0; i < 3; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= l[i][k] * y[k];
    y[i] = s / l[i][i];
  }
  for (int i = 2; i >= 0; --i) {
    double s = y[i];
    for (int k = i + 1; k < 3; ++k) s -= l[k][i] * x[k];
    x[i] = s / l[i][i];
  }
  return true;
}

struct Logs {
  double lx, ly;  // ln(θ/p_a), ln(τ_oct/p_a + 1)
};

double model(const Vec& k, const Logs& g) { return k[0] * kAtmosphericPressure * std::exp(k[1] * g.lx + k[2] * g.ly); }

}  // namespace

double UniversalFit::predict(double bulk_stress, double octahedral_shear) const {
  const Logs g{std::log(bulk_stress / kAtmosphericPressure), std::log(octahedral_shear / kAtmosphericPressure + 1.0)};
  return model({k1, k2, k3}, g);
}

UniversalFit fit_universal_model(const std::vector<UniversalPoint>& points) {
  const std::size_t n = points.size();
  if (n < 4) throw InputError(fmt::format("universal model fit: needs at least 4 points (3 coefficients), got {}", n));
  std::vector<Logs> g(n);
  std::vector<double> m(n);
  for (std::size_t i = 0; i < n; ++i) {
    const UniversalPoint& p = points[i];
    if (!(p.bulk_stress > 0) || !std::isfinite(p.bulk_stress) || !(p.octahedral_shear >= 0) ||
        !std::isfinite(p.octahedral_shear) || !(p.modulus > 0) || !std::isfinite(p.modulus))
      throw InputError(fmt::format("universal model fit: point {} must have theta > 0 Pa, tau_oct >= 0 Pa and M_r > 0 Pa, "
                                   "got theta {:g} Pa, tau_oct {:g} Pa, M_r {:g} Pa",
                                   i + 1, p.bulk_stress, p.octahedral_shear, p.modulus));
    g[i] = {std::log(p.bulk_stress / kAtmosphericPressure), std::log(p.octahedral_shear / kAtmosphericPressure + 1.0)};
    m[i] = p.modulus;
  }
  // Start: the log-linear least squares, basis (1, ln x, ln y).
  Mat a{};
  Vec b{}, c{};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec f{1.0, g[i].lx, g[i].ly};
    const double y = std::log(m[i] / kAtmosphericPressure);
    for (int r = 0; r < 3; ++r) {
      b[r] += f[r] * y;
      for (int s = 0; s < 3; ++s) a[r][s] += f[r] * f[s];
    }
  }
  if (!solve3(a, b, c))
    throw InputError("universal model fit: the points do not determine k1, k2, k3 (theta and tau_oct too few or collinear)");
  Vec k{std::exp(c[0]), c[1], c[2]};

  auto sum_sq = [&](const Vec& kk) {
    double s = 0.0;
    for (std::size_t i = 0; i < n; ++i) s += (m[i] - model(kk, g[i])) * (m[i] - model(kk, g[i]));
    return s;
  };
  // Normal equations JᵀJ and Jᵀr at k: ∂M/∂k₁ = M/k₁, ∂M/∂k₂ = M ln x, ∂M/∂k₃ = M ln y.
  auto normal = [&](const Vec& kk, Mat& jtj, Vec& jtr) {
    jtj = Mat{};
    jtr = Vec{};
    for (std::size_t i = 0; i < n; ++i) {
      const double mi = model(kk, g[i]);
      const Vec j{mi / kk[0], mi * g[i].lx, mi * g[i].ly};
      const double r = m[i] - mi;
      for (int p = 0; p < 3; ++p) {
        jtr[p] += j[p] * r;
        for (int q = 0; q < 3; ++q) jtj[p][q] += j[p] * j[q];
      }
    }
  };
  UniversalFit fit;
  double s = sum_sq(k), lambda = 1e-3;
  Mat jtj;
  Vec jtr;
  for (int it = 0; it < 200; ++it) {
    normal(k, jtj, jtr);
    bool improved = false;
    while (lambda < 1e12) {
      Mat aug = jtj;
      for (int p = 0; p < 3; ++p) aug[p][p] *= 1.0 + lambda;
      Vec dk{};
      if (solve3(aug, jtr, dk)) {
        const Vec trial{k[0] + dk[0], k[1] + dk[1], k[2] + dk[2]};
        const double st = trial[0] > 0 ? sum_sq(trial) : INFINITY;
        if (st <= s) {
          const double change = (s - st) / std::max(s, 1e-300);
          k = trial, s = st, lambda = std::max(lambda / 10.0, 1e-12);
          improved = true;
          fit.iterations = it + 1;
          if (change < 1e-12) fit.converged = true;
          break;
        }
      }
      lambda *= 10.0;
    }
    if (!improved) fit.converged = true;  // no step lowers the sum: at the minimum (to rounding)
    if (fit.converged) break;
  }
  fit.k1 = k[0], fit.k2 = k[1], fit.k3 = k[2];
  fit.points = static_cast<int>(n);
  double mean = 0.0;
  for (double v : m) mean += v / static_cast<double>(n);
  double tot = 0.0;
  for (double v : m) tot += (v - mean) * (v - mean);
  fit.r_squared = tot > 0 ? 1.0 - s / tot : (s == 0 ? 1.0 : 0.0);
  fit.rms_error = std::sqrt(s / static_cast<double>(n));
  normal(k, jtj, jtr);
  const double s2 = n > 3 ? s / static_cast<double>(n - 3) : 0.0;
  for (int p = 0; p < 3; ++p) {  // diagonal of (JᵀJ)⁻¹: column p of the inverse
    Vec e{}, col{};
    e[p] = 1.0;
    const double var = solve3(jtj, e, col) ? s2 * col[p] : NAN;
    (p == 0 ? fit.se_k1 : p == 1 ? fit.se_k2 : fit.se_k3) = std::sqrt(var);
  }
  return fit;
}

std::string UniversalFit::text() const {
  return fmt::format("universal model M_r = k1 p_a (theta/p_a)^k2 (tau_oct/p_a + 1)^k3: k1 {:.4g} +- {:.2g}, k2 {:.4f} +- {:.2g}, "
                     "k3 {:.4f} +- {:.2g}; R^2 {:.4f}; rms error {:.3g} MPa over {} points{}",
                     k1, se_k1, k2, se_k2, k3, se_k3, r_squared, rms_error / 1e6, points, converged ? "" : " (not converged)");
}

std::string UniversalFit::csv() const {
  return "k1[-],k2[-],k3[-],se_k1[-],se_k2[-],se_k3[-],r_squared[-],rms_error[Pa],points,p_a[Pa]\n" +
         fmt::format("{:.9g},{:.9g},{:.9g},{:.6g},{:.6g},{:.6g},{:.6f},{:.6g},{},{:g}\n", k1, k2, k3, se_k1, se_k2, se_k3, r_squared,
                     rms_error, points, kAtmosphericPressure);
}

}  // namespace hilldem
