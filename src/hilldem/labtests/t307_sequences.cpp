#include "hilldem/labtests/t307_sequences.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "hilldem/core/error.hpp"

namespace hilldem {

double T307Sequence::bulk_stress() const { return 3.0 * confining + max_stress; }
double T307Sequence::octahedral_shear() const { return std::numbers::sqrt2 / 3.0 * max_stress; }

std::vector<T307Sequence> t307_base_sequences() {
  // {seq, σ₃, σ_max, σ_cyclic, σ_contact} [kPa]: AASHTO T 307, base/subbase (spec lab-tests.md §5).
  struct Row {
    int seq;
    double s3, smax, scyc, scon;
  };
  static constexpr Row rows[] = {
      {0, 103.4, 103.4, 93.1, 10.3},                                                       // conditioning
      {1, 20.7, 20.7, 18.6, 2.1},    {2, 20.7, 41.4, 37.3, 4.1},    {3, 20.7, 62.1, 55.9, 6.2},
      {4, 34.5, 34.5, 31.0, 3.5},    {5, 34.5, 68.9, 62.0, 6.9},    {6, 34.5, 103.4, 93.1, 10.3},
      {7, 68.9, 68.9, 62.0, 6.9},    {8, 68.9, 137.9, 124.1, 13.8}, {9, 68.9, 206.8, 186.1, 20.7},
      {10, 103.4, 68.9, 62.0, 6.9},  {11, 103.4, 103.4, 93.1, 10.3}, {12, 103.4, 206.8, 186.1, 20.7},
      {13, 137.9, 103.4, 93.1, 10.3}, {14, 137.9, 137.9, 124.1, 13.8}, {15, 137.9, 275.8, 248.2, 27.6},
  };
  std::vector<T307Sequence> out;
  for (const Row& r : rows)
    out.push_back({r.seq, r.s3 * 1e3, r.smax * 1e3, r.scyc * 1e3, r.scon * 1e3, r.seq == 0 ? 500 : 100});
  return out;
}

void validate(const T307Timing& t) {
  auto range = [](const char* what, double v, double lo, double hi, bool lo_open) {
    const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
    if (!ok) throw InputError(fmt::format("{} must be in {}{:g}, {:g}], got {:g}", what, lo_open ? "(" : "[", lo, hi, v));
  };
  range("pulse duration [s]", t.pulse_duration, 1e-5, 1.0, false);
  range("rest duration [s]", t.rest_duration, 0.0, 10.0, false);
  range("settle duration [s]", t.settle_duration, 0.0, 10.0, false);
  range("cycles per sequence", t.cycles, 1, 100, false);
  range("conditioning cycles", t.conditioning_cycles, 0, 1000, false);
  range("averaged cycles", t.averaged_cycles, 1, t.cycles, false);
  range("servo gain [-]", t.servo_gain, 0.0, 1.0, true);
  range("wall speed limit [m/s]", t.wall_speed_limit, 0.0, 100.0, true);
}

double haversine(double t, double duration) {
  if (t <= 0.0 || t >= duration) return 0.0;
  return 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * t / duration));
}

}  // namespace hilldem
