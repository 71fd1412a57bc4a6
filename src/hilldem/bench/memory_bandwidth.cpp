#include "hilldem/bench/memory_bandwidth.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace hilldem {

std::string MemoryBandwidth::line() const {
  // triad_moved: the triad with its write-allocate reads (32 B per element).
  return fmt::format("array_mib={} copy_gb_per_s={:.1f} triad_gb_per_s={:.1f} triad_moved_gb_per_s={:.1f} "
                     "update_gb_per_s={:.1f}",
                     array_bytes >> 20, copy / 1e9, triad / 1e9, triad * (32.0 / 24.0) / 1e9, update / 1e9);
}

MemoryBandwidth measure_memory_bandwidth(std::size_t array_bytes, int passes) {
  const std::size_t n = array_bytes / sizeof(double);
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 0.5);  // (touched once here: the pages are mapped)
  MemoryBandwidth r;
  r.array_bytes = n * sizeof(double);
  auto rate = [](double bytes, auto t0, auto t1) { return bytes / std::chrono::duration<double>(t1 - t0).count(); };
  const double s = 3.0;
  for (int p = 0; p < passes; ++p) {
    double* __restrict pa = a.data();
    double* __restrict pb = b.data();
    double* __restrict pc = c.data();
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) pc[i] = pa[i];
    const auto t1 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    const auto t2 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) pc[i] = s * pc[i] + pb[i];
    const auto t3 = std::chrono::steady_clock::now();
    r.copy = std::max(r.copy, rate(16.0 * static_cast<double>(n), t0, t1));
    r.triad = std::max(r.triad, rate(24.0 * static_cast<double>(n), t1, t2));
    r.update = std::max(r.update, rate(24.0 * static_cast<double>(n), t2, t3));
  }
  // (a and c are read back, so the loops cannot be dropped)
  if (a[n / 2] < 0.0 || c[n / 3] < 0.0) r.copy = 0.0;
  return r;
}

}  // namespace hilldem
