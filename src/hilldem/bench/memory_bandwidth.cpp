#include "hilldem/bench/memory_bandwidth.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <vector>

namespace hilldem {

std::string MemoryBandwidth::line() const {
  // triad_moved: the triad with its write-allocate reads (32 B per element).
  return fmt::format("array_mib={} copy_gb_per_s={:.1f} triad_gb_per_s={:.1f} triad_moved_gb_per_s={:.1f} "
                     "update_gb_per_s={:.1f}",
                     array_bytes >> 20, copy / 1e9, triad / 1e9, triad * (32.0 / 24.0) / 1e9, update / 1e9);
}

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
// One pass of the update a = s a + b over n elements; returns its time [s] (24 B moved per element,
// every byte counted: each line written was read).
double timed_update(double* __restrict a, const double* __restrict b, std::size_t n, double s) {
  const auto t0 = Clock::now();
  for (std::size_t i = 0; i < n; ++i) a[i] = s * a[i] + b[i];
  return seconds_since(t0);
}
}  // namespace

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
    const double t_update = timed_update(pc, pb, n, s);
    r.copy = std::max(r.copy, rate(16.0 * static_cast<double>(n), t0, t1));
    r.triad = std::max(r.triad, rate(24.0 * static_cast<double>(n), t1, t2));
    if (t_update > 0.0) r.update = std::max(r.update, 24.0 * static_cast<double>(n) / t_update);
  }
  // (a and c are read back, so the loops cannot be dropped)
  if (a[n / 2] < 0.0 || c[n / 3] < 0.0) r.copy = 0.0;
  return r;
}

std::string CacheLevel::line() const {
  return fmt::format("working_set_kib={} update_gb_per_s={:.1f} random_load_ns={:.1f}", working_set >> 10,
                     update / 1e9, random_load * 1e9);
}

std::vector<std::size_t> default_cache_sweep() {
  std::vector<std::size_t> sizes;
  for (std::size_t kib = 256; kib <= (std::size_t{256} << 10); kib *= 2) sizes.push_back(kib << 10);
  return sizes;
}

std::vector<std::uint32_t> random_cycle(std::size_t lines, std::uint64_t seed) {
  // Sattolo's shuffle of 0..lines-1 (each element swapped with one strictly before it) gives a
  // permutation with a single cycle: following next[i] visits every line once before it returns, so
  // no short loop of lines stays in a small cache. (With the swap partner drawn up to i itself, the
  // Fisher-Yates shuffle, the permutation has several cycles: test CacheSweep.*.)
  std::vector<std::uint32_t> next(lines);
  for (std::size_t i = 0; i < lines; ++i) next[i] = static_cast<std::uint32_t>(i);
  std::mt19937_64 rng(seed);
  for (std::size_t i = lines; i-- > 1;) {
    std::uniform_int_distribution<std::size_t> pick(0, i - 1);
    std::swap(next[i], next[pick(rng)]);
  }
  return next;
}

std::vector<CacheLevel> measure_cache_levels(const std::vector<std::size_t>& working_sets, double seconds_per_size) {
  constexpr std::size_t kLine = 64;
  constexpr std::size_t kStride = kLine / sizeof(std::uint32_t);  // indices a line
  std::vector<CacheLevel> out;
  for (const std::size_t bytes : working_sets) {
    CacheLevel level;
    const std::size_t lines = std::max<std::size_t>(2, bytes / kLine);
    level.working_set = lines * kLine;
    // Streaming: two arrays of half the set each.
    {
      const std::size_t n = level.working_set / 2 / sizeof(double);
      std::vector<double> a(n, 1.0), b(n, 0.5);
      const double s = 0.999;
      const auto t_all = Clock::now();
      for (int pass = 0; pass < 3 || seconds_since(t_all) < 0.5 * seconds_per_size; ++pass) {
        const double t = timed_update(a.data(), b.data(), n, s);
        if (t > 0.0) level.update = std::max(level.update, 24.0 * static_cast<double>(n) / t);
      }
      if (a[n / 2] < 0.0) level.update = 0.0;  // (read back, so the loop cannot be dropped)
    }
    // Latency: one index per line, the next line of the cycle in the line's first four bytes.
    {
      const std::vector<std::uint32_t> next = random_cycle(lines);
      std::vector<std::uint32_t> mem(lines * kStride);
      for (std::size_t i = 0; i < lines; ++i) mem[i * kStride] = next[i];
      const std::uint32_t* m = mem.data();
      std::uint32_t p = 0;
      for (std::size_t k = 0; k < lines; ++k) p = m[std::size_t{p} * kStride];  // (warm)
      const std::size_t hops = 1u << 20;
      const auto t_all = Clock::now();
      level.random_load = 1.0;
      for (int pass = 0; pass < 2 || seconds_since(t_all) < 0.5 * seconds_per_size; ++pass) {
        const auto t0 = Clock::now();
        for (std::size_t k = 0; k < hops; ++k) p = m[std::size_t{p} * kStride];
        level.random_load = std::min(level.random_load, seconds_since(t0) / static_cast<double>(hops));
      }
      if (p == lines) level.random_load = 0.0;  // (never: p is a line index; keeps the chase)
    }
    out.push_back(level);
  }
  return out;
}

}  // namespace hilldem
