// The memory bandwidth one core gets here: the hardware limit that the bench bed's speed is measured
// against (docs/performance.md, "How far from the hardware limit"). STREAM-style copy and triad
// loops, and an update loop, over arrays far larger than any cache, one thread, best of several passes.
// STREAM counts the bytes a loop names, not the lines a store first reads for ownership (write-
// allocate): the triad moves 32 B per element, not the 24 it is credited with. The update loop
// (a = s a + b: every line it writes it has read) has no such ambiguity, and it is the figure to set
// against a count of the bytes a step moves with write-allocate included.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hilldem {

struct MemoryBandwidth {
  std::size_t array_bytes = 0;  // each of the three arrays [B]
  double copy = 0.0;            // c = a: 16 B moved per element [B/s], write-allocate not counted
  double triad = 0.0;           // a = b + s c: 24 B per element [B/s], write-allocate not counted
  double update = 0.0;          // a = s a + b: 24 B moved per element [B/s], every byte counted
  std::string line() const;     // one machine-readable line
};

// Three arrays of `array_bytes` each (default 256 MiB), `passes` timed passes of each loop.
MemoryBandwidth measure_memory_bandwidth(std::size_t array_bytes = std::size_t{256} << 20, int passes = 5);

// What one core sees at one working-set size: why a bed whose step data fit in the caches runs
// faster per particle than one whose data do not (docs/performance.md, "What limits it"). Two
// figures per size, one thread, best of several passes:
// - a streaming read-modify-write (a = s a + b over two arrays of half the size each, every byte
//   counted), the way the force pass walks its row columns;
// - the latency of a dependent load at a random line of the set (a pointer chase over one cycle
//   through all its lines), the way a neighbour's record is first met when nothing asked for it.
struct CacheLevel {
  std::size_t working_set = 0;  // [B]
  double update = 0.0;          // [B/s]
  double random_load = 0.0;     // [s] per dependent load
  std::string line() const;     // one machine-readable line
};

// The sizes of `working_sets` [B], each measured for about `seconds_per_size` [s].
std::vector<CacheLevel> measure_cache_levels(const std::vector<std::size_t>& working_sets,
                                             double seconds_per_size = 0.3);
// The default sweep: 256 KiB to 256 MiB in powers of two.
std::vector<std::size_t> default_cache_sweep();

// The chase's order: next[i] is the line after line i, one cycle through all `lines` lines in a
// random order (Sattolo's shuffle), from a fixed seed.
std::vector<std::uint32_t> random_cycle(std::size_t lines, std::uint64_t seed = 1);

}  // namespace hilldem
