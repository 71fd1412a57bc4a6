// Grain-size distributions (docs/spec/lab-tests.md §1): bins of {lower diameter, upper diameter,
// solid-volume fraction}; the memo's C5n and C5b gradings built in; user gradings from CSV files;
// seeded sampling; and the realised distribution (% passing by volume, memo Fig. 18) next to the
// target.
//
// Sampling model [practice]: bin j receives grains until their solid volume is as close as one grain
// can make it to φ_j·V_s; each diameter is uniform in [D_l, D_u]·D_mult (by number). Under this
// model the expected fraction of bin j's volume finer than s is (s⁴ − D_l⁴)/(D_u⁴ − D_l⁴), which is
// the target curve reported between the bin bounds.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hilldem/labtests/rng.hpp"

namespace hilldem {

struct GradingBin {
  double d_lower = 0.0;   // [m] > 0
  double d_upper = 0.0;   // [m] ≥ d_lower
  double fraction = 0.0;  // solid-volume (= mass) fraction [-], ≥ 0; the bins sum to 1
};

struct Grading {
  std::string name;              // "C5n", "C5b" or the file name
  std::vector<GradingBin> bins;  // non-overlapping
};

// Memo Table 7 / lab-tests.md §1.
Grading grading_c5n();  // diameters uniform in 14–20 mm
Grading grading_c5b();  // 8 bins, 4.8–23 mm

// "C5n" or "C5b" (any case), or the path of a CSV file of rows `d_lower_mm,d_upper_mm,fraction`
// ('#' comments and one header line allowed). Throws InputError naming the choices, the file and
// line, or the bad value.
Grading resolve_grading(const std::string& name_or_file);
Grading parse_grading_csv(const std::string& text, const std::string& source);
// Throws InputError unless every bound is finite and positive, d_lower ≤ d_upper, fractions are ≥ 0
// and sum to 1 within 1e-3, and bins do not overlap.
void validate_grading(const Grading& g);

// Expected number of grains for a solid volume V_s [m³] with diameters scaled by d_mult.
double expected_grain_count(const Grading& g, double d_mult, double solid_volume);

struct GrainSample {
  std::vector<double> diameters;  // [m]
  std::vector<int> bin;           // index of the bin each grain came from
  double solid_volume() const;    // Σ π D³/6 [m³]
};

// Draws grains for a solid volume V_s [m³]. Throws InputError if more than max_grains would be
// needed (estimated before drawing).
GrainSample sample_grains(const Grading& g, double d_mult, double solid_volume, Rng& rng,
                          std::size_t max_grains = 2'000'000);

// Target fraction of the solid volume finer than `size` [m] under the sampling model.
double target_passing(const Grading& g, double d_mult, double size);

struct BinReport {
  GradingBin bin;                 // scaled by d_mult [m]
  double realised_fraction = 0.0; // of the realised solid volume [-]
  std::size_t count = 0;          // grains
};
struct PassingPoint {
  double size = 0.0;      // sieve size [m]
  double target = 0.0;    // fraction passing [-]
  double realised = 0.0;  // fraction passing [-]
};
struct GradingReport {
  std::string name;
  std::vector<BinReport> bins;
  std::vector<PassingPoint> curve;  // bin bounds and 60 log-spaced sizes, ascending
  std::size_t count = 0;
  std::size_t outside = 0;  // grains in no bin (a specimen from another grading)
  double d50_target = 0.0, d50_realised = 0.0;  // [m] median by volume
  double worst_bin_error = 0.0;                 // max |realised − target| bin fraction [-]
  // CSV: `size[mm],target_passing[%],realised_passing[%]` then a blank line and the bin table.
  std::string csv() const;
  // A few lines for the console: count, D50, per-bin target vs realised.
  std::string text() const;
};
// Realised distribution of the diameters [m] against the grading (grains are counted in the bin whose
// scaled bounds hold them; the first such bin when a diameter sits on a shared bound).
GradingReport grading_report(const Grading& g, double d_mult, const std::vector<double>& diameters);

}  // namespace hilldem
