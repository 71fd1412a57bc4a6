// The NCHRP 1-28A universal model of the resilient modulus (docs/spec/lab-tests.md §5):
//   M_r = k₁ p_a (θ/p_a)^k₂ (τ_oct/p_a + 1)^k₃
// with θ the bulk stress [Pa], τ_oct the octahedral shear stress [Pa] and p_a = 101.325 kPa. The fit
// is nonlinear least squares on M_r itself (Levenberg–Marquardt over k₁, k₂, k₃), started from the
// log-linear fit ln(M_r/p_a) = ln k₁ + k₂ ln(θ/p_a) + k₃ ln(τ_oct/p_a + 1).
#pragma once

#include <string>
#include <vector>

namespace hilldem {

struct UniversalPoint {
  double bulk_stress = 0.0;       // θ [Pa], > 0
  double octahedral_shear = 0.0;  // τ_oct [Pa], >= 0
  double modulus = 0.0;           // M_r [Pa], > 0
};

struct UniversalFit {
  double k1 = 0.0, k2 = 0.0, k3 = 0.0;  // [-]
  // Standard errors from s² (JᵀJ)⁻¹ at the solution, s² = SS_res/(n − 3) [-].
  double se_k1 = 0.0, se_k2 = 0.0, se_k3 = 0.0;
  double r_squared = 0.0;   // 1 − SS_res/SS_tot on M_r [-]
  double rms_error = 0.0;   // √(SS_res/n) [Pa]
  int points = 0;
  int iterations = 0;       // Levenberg–Marquardt steps taken
  bool converged = false;   // relative change of the sum of squares below 1e-12
  double predict(double bulk_stress, double octahedral_shear) const;  // M_r [Pa]
  std::string text() const;  // one labelled line
  std::string csv() const;   // header with units, then one row
};

// Throws InputError with fewer than 4 points or a point outside the ranges above.
UniversalFit fit_universal_model(const std::vector<UniversalPoint>& points);

}  // namespace hilldem
