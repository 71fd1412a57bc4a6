#include "hilldem/labtests/gsd.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {
constexpr double kMm = 1e-3;

double grain_volume(double d) { return std::numbers::pi / 6.0 * d * d * d; }

// E[D³] for D uniform in [lo, hi].
double mean_cube(double lo, double hi) {
  if (hi <= lo) return lo * lo * lo;
  return (std::pow(hi, 4) - std::pow(lo, 4)) / (4.0 * (hi - lo));
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Diameter below which a fraction p of the volume lies, by bisection on a monotone curve.
template <class F>
double quantile(F passing, double lo, double hi, double p) {
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (passing(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
}  // namespace

Grading grading_c5n() { return {"C5n", {{14.0 * kMm, 20.0 * kMm, 1.0}}}; }

Grading grading_c5b() {
  return {"C5b",
          {{19.0 * kMm, 23.0 * kMm, 0.07},
           {16.5 * kMm, 19.0 * kMm, 0.10},
           {14.0 * kMm, 16.5 * kMm, 0.09},
           {12.0 * kMm, 14.0 * kMm, 0.09},
           {9.5 * kMm, 12.0 * kMm, 0.09},
           {7.0 * kMm, 9.5 * kMm, 0.07},
           {6.0 * kMm, 7.0 * kMm, 0.10},
           {4.8 * kMm, 6.0 * kMm, 0.39}}};
}

void validate_grading(const Grading& g) {
  const std::string where = "grading '" + g.name + "'";
  if (g.bins.empty()) throw InputError(where + ": no bins");
  double sum = 0.0;
  for (std::size_t j = 0; j < g.bins.size(); ++j) {
    const GradingBin& b = g.bins[j];
    const std::string at = fmt::format("{} bin {} ({:g}-{:g} mm)", where, j + 1, b.d_lower / kMm, b.d_upper / kMm);
    if (!std::isfinite(b.d_lower) || !std::isfinite(b.d_upper) || b.d_lower <= 0.0)
      throw InputError(at + ": diameters must be finite and > 0");
    if (b.d_upper < b.d_lower) throw InputError(at + ": upper diameter below the lower one");
    if (!std::isfinite(b.fraction) || b.fraction < 0.0)
      throw InputError(fmt::format("{}: volume fraction must be in [0, 1], got {:g}", at, b.fraction));
    sum += b.fraction;
  }
  if (std::abs(sum - 1.0) > 1e-3)
    throw InputError(fmt::format("{}: volume fractions sum to {:.6g}, expected 1 (within 1e-3)", where, sum));
  for (std::size_t i = 0; i < g.bins.size(); ++i)
    for (std::size_t j = i + 1; j < g.bins.size(); ++j) {
      const GradingBin &a = g.bins[i], &b = g.bins[j];
      if (std::max(a.d_lower, b.d_lower) < std::min(a.d_upper, b.d_upper))
        throw InputError(fmt::format("{}: bins {} and {} overlap", where, i + 1, j + 1));
    }
}

Grading parse_grading_csv(const std::string& text, const std::string& source) {
  Grading g;
  g.name = std::filesystem::path(source).stem().string();
  std::istringstream in(text);
  std::string line;
  int lineno = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++lineno;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    line = trim(line);
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(trim(cell));
    auto number = [&](const std::string& c, double& v) {
      char* end = nullptr;
      v = std::strtod(c.c_str(), &end);
      return !c.empty() && end && *end == '\0';
    };
    double v[3];
    const bool numeric = cells.size() == 3 && number(cells[0], v[0]) && number(cells[1], v[1]) && number(cells[2], v[2]);
    if (!numeric) {
      if (!header_seen && g.bins.empty() && cells.size() == 3 && !number(cells[0], v[0])) {
        header_seen = true;  // a header line such as d_lower_mm,d_upper_mm,fraction
        continue;
      }
      throw InputError(fmt::format("{}:{}: expected `d_lower_mm,d_upper_mm,fraction`, got '{}'", source, lineno, line));
    }
    g.bins.push_back({v[0] * kMm, v[1] * kMm, v[2]});
  }
  if (g.bins.empty()) throw InputError(source + ": no grading bins (rows `d_lower_mm,d_upper_mm,fraction`)");
  validate_grading(g);
  return g;
}

Grading resolve_grading(const std::string& name_or_file) {
  const std::string key = lower(name_or_file);
  if (key == "c5n") return grading_c5n();
  if (key == "c5b") return grading_c5b();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(name_or_file, ec))
    throw InputError("unknown grading '" + name_or_file +
                     "': choose C5n, C5b, or give a CSV file of `d_lower_mm,d_upper_mm,fraction` rows");
  std::ifstream f(name_or_file, std::ios::binary);
  if (!f) throw InputError(name_or_file + ": cannot open");
  std::stringstream buf;
  buf << f.rdbuf();
  return parse_grading_csv(buf.str(), name_or_file);
}

double expected_grain_count(const Grading& g, double d_mult, double solid_volume) {
  double n = 0.0;
  for (const GradingBin& b : g.bins)
    if (b.fraction > 0.0)
      n += b.fraction * solid_volume / (std::numbers::pi / 6.0 * mean_cube(b.d_lower * d_mult, b.d_upper * d_mult));
  return n;
}

double GrainSample::solid_volume() const {
  double v = 0.0;
  for (double d : diameters) v += grain_volume(d);
  return v;
}

GrainSample sample_grains(const Grading& g, double d_mult, double solid_volume, Rng& rng, std::size_t max_grains) {
  validate_grading(g);
  if (!(d_mult > 0.0) || !std::isfinite(d_mult)) throw InputError(fmt::format("diameter multiplier must be > 0, got {:g}", d_mult));
  if (!(solid_volume > 0.0) || !std::isfinite(solid_volume))
    throw InputError(fmt::format("solid volume must be > 0, got {:g} m^3", solid_volume));
  const double expected = expected_grain_count(g, d_mult, solid_volume);
  if (expected > static_cast<double>(max_grains))
    throw InputError(fmt::format("grading '{}' needs about {:.0f} grains here, more than the limit of {}", g.name,
                                 expected, max_grains));
  GrainSample s;
  s.diameters.reserve(static_cast<std::size_t>(expected * 1.05) + 16);
  for (std::size_t j = 0; j < g.bins.size(); ++j) {
    const GradingBin& b = g.bins[j];
    const double target = b.fraction * solid_volume;
    double placed = 0.0;
    for (;;) {
      const double d = rng.uniform(b.d_lower, b.d_upper) * d_mult;
      const double v = grain_volume(d);
      // Keep the grain when it brings the bin's volume closer to its target.
      if (placed + 0.5 * v > target) break;
      s.diameters.push_back(d);
      s.bin.push_back(static_cast<int>(j));
      placed += v;
    }
  }
  return s;
}

double target_passing(const Grading& g, double d_mult, double size) {
  double p = 0.0;
  for (const GradingBin& b : g.bins) {
    const double lo = b.d_lower * d_mult, hi = b.d_upper * d_mult;
    if (size >= hi) p += b.fraction;
    else if (size > lo) p += b.fraction * (std::pow(size, 4) - std::pow(lo, 4)) / (std::pow(hi, 4) - std::pow(lo, 4));
  }
  return std::min(p, 1.0);
}

GradingReport grading_report(const Grading& g, double d_mult, const std::vector<double>& diameters) {
  GradingReport r;
  r.name = g.name;
  r.count = diameters.size();
  double total = 0.0;
  for (const GradingBin& b : g.bins) r.bins.push_back({{b.d_lower * d_mult, b.d_upper * d_mult, b.fraction}, 0.0, 0});
  std::vector<double> sorted = diameters;
  std::sort(sorted.begin(), sorted.end());
  for (double d : sorted) {
    const double v = grain_volume(d);
    total += v;
    bool placed = false;
    for (BinReport& b : r.bins)
      if (d >= b.bin.d_lower * (1 - 1e-12) && d <= b.bin.d_upper * (1 + 1e-12)) {
        b.realised_fraction += v;
        ++b.count;
        placed = true;
        break;
      }
    if (!placed) ++r.outside;
  }
  for (BinReport& b : r.bins) {
    if (total > 0.0) b.realised_fraction /= total;
    r.worst_bin_error = std::max(r.worst_bin_error, std::abs(b.realised_fraction - b.bin.fraction));
  }
  // Cumulative volume of the sorted diameters: passing(s) = volume of grains with D ≤ s / total.
  std::vector<double> cum(sorted.size());
  double acc = 0.0;
  for (std::size_t i = 0; i < sorted.size(); ++i) cum[i] = (acc += grain_volume(sorted[i]));
  auto realised = [&](double s) {
    if (total <= 0.0) return 0.0;
    const auto it = std::upper_bound(sorted.begin(), sorted.end(), s);
    const std::size_t k = static_cast<std::size_t>(it - sorted.begin());
    return k == 0 ? 0.0 : cum[k - 1] / total;
  };
  double lo = 1e300, hi = 0.0;
  std::vector<double> sizes;
  for (const BinReport& b : r.bins) {
    lo = std::min(lo, b.bin.d_lower), hi = std::max(hi, b.bin.d_upper);
    sizes.push_back(b.bin.d_lower), sizes.push_back(b.bin.d_upper);
  }
  if (!sorted.empty()) lo = std::min(lo, sorted.front()), hi = std::max(hi, sorted.back());
  constexpr int kPoints = 60;
  for (int k = 0; k <= kPoints; ++k) sizes.push_back(lo * std::pow(hi / lo, static_cast<double>(k) / kPoints));
  std::sort(sizes.begin(), sizes.end());
  sizes.erase(std::unique(sizes.begin(), sizes.end(), [](double a, double b) { return std::abs(a - b) <= 1e-12 * b; }),
              sizes.end());
  for (double s : sizes) r.curve.push_back({s, target_passing(g, d_mult, s), realised(s)});
  r.d50_target = quantile([&](double s) { return target_passing(g, d_mult, s); }, lo, hi, 0.5);
  if (total > 0.0) r.d50_realised = quantile(realised, lo, hi, 0.5);
  return r;
}

std::string GradingReport::csv() const {
  std::string out = "size[mm],target_passing[%],realised_passing[%]\n";
  for (const PassingPoint& p : curve)
    out += fmt::format("{:.6g},{:.6g},{:.6g}\n", p.size / kMm, 100.0 * p.target, 100.0 * p.realised);
  out += "\nbin,d_lower[mm],d_upper[mm],target_fraction[-],realised_fraction[-],grains\n";
  for (std::size_t j = 0; j < bins.size(); ++j)
    out += fmt::format("{},{:.6g},{:.6g},{:.6g},{:.6g},{}\n", j + 1, bins[j].bin.d_lower / kMm, bins[j].bin.d_upper / kMm,
                       bins[j].bin.fraction, bins[j].realised_fraction, bins[j].count);
  return out;
}

std::string GradingReport::text() const {
  std::string out = fmt::format("grading {}: {} grains, D50 {:.2f} mm realised / {:.2f} mm target, worst bin error {:.4f}\n",
                                name, count, d50_realised / kMm, d50_target / kMm, worst_bin_error);
  out += fmt::format("  {:>13}  {:>8}  {:>9}  {:>7}\n", "bin [mm]", "target", "realised", "grains");
  for (const BinReport& b : bins)
    out += fmt::format("  {:>6.2f}-{:<6.2f}  {:>8.4f}  {:>9.4f}  {:>7}\n", b.bin.d_lower / kMm, b.bin.d_upper / kMm,
                       b.bin.fraction, b.realised_fraction, b.count);
  if (outside > 0) out += fmt::format("  {} grains lie outside every bin\n", outside);
  return out;
}

}  // namespace hilldem
