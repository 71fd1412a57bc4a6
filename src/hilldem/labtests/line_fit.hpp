// Least-squares straight line through a branch of a q–ε_a path, with a standard error of the slope
// that holds for serially correlated residuals (the signal rings after each reversal, so neighbouring
// residuals are not independent and the textbook standard error is far too small).
#pragma once

#include <cstddef>
#include <vector>

namespace hilldem {

struct LineFit {
  double slope = 0.0;      // dy/dx [units of y per unit of x]
  double intercept = 0.0;  // y at x = 0
  // Standard error of the slope: the delete-one-block jackknife over m = min(20, n/3) contiguous
  // blocks of the points in path order, s² = (m − 1)/m Σ_j (b_(j) − b̄)², b_(j) the slope without
  // block j. Blocks longer than the ringing's period make it honest for correlated residuals.
  double slope_se = 0.0;
  // The textbook standard error sqrt(Σ r² / (n − 2) / Σ (x − x̄)²), right for independent residuals
  // only; reported to show how much the correlation matters.
  double ols_se = 0.0;
  std::size_t points = 0;   // points fitted
  int blocks = 0;           // m
  bool valid = false;       // at least 9 points (3 blocks of 3), x not all equal
};

// Fits y = a + b x to the points in the order given (the path's order: ρ is taken along it).
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace hilldem
