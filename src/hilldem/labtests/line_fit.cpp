#include "hilldem/labtests/line_fit.hpp"

#include <algorithm>
#include <cmath>

namespace hilldem {

namespace {
// The sums of a least-squares fit (of centred x and y).
struct Sums {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  void add(double x, double y, double w) { n += w, sx += w * x, sy += w * y, sxx += w * x * x, sxy += w * x * y; }
  double slope() const {
    const double d = n * sxx - sx * sx;
    return d > 0.0 ? (n * sxy - sx * sy) / d : 0.0;
  }
};
}  // namespace

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  LineFit f;
  const std::size_t n = std::min(x.size(), y.size());
  f.points = n;
  f.blocks = static_cast<int>(std::min<std::size_t>(20, n / 3));
  if (f.blocks < 3) return f;
  // Centred sums (the strains are ~1e-4 with spans ~1e-5: centring keeps the digits).
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(n), my /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (!(sxx > 0.0)) return f;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  double ss = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = y[i] - f.intercept - f.slope * x[i];
    ss += r * r;
  }
  f.ols_se = std::sqrt(ss / static_cast<double>(n - 2) / sxx);
  // Jackknife: the whole sums minus each block's.
  const int m = f.blocks;
  Sums all;
  std::vector<Sums> block(static_cast<std::size_t>(m));
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = i * static_cast<std::size_t>(m) / n;
    all.add(x[i] - mx, y[i] - my, 1.0);
    block[j].add(x[i] - mx, y[i] - my, 1.0);
  }
  std::vector<double> b(static_cast<std::size_t>(m));
  double mean = 0.0;
  for (int j = 0; j < m; ++j) {
    const Sums& s = block[static_cast<std::size_t>(j)];
    Sums rest{all.n - s.n, all.sx - s.sx, all.sy - s.sy, all.sxx - s.sxx, all.sxy - s.sxy};
    b[static_cast<std::size_t>(j)] = rest.slope();
    mean += b[static_cast<std::size_t>(j)];
  }
  mean /= m;
  double var = 0.0;
  for (double v : b) var += (v - mean) * (v - mean);
  f.slope_se = std::sqrt(static_cast<double>(m - 1) / m * var);
  f.valid = true;
  return f;
}

}  // namespace hilldem
