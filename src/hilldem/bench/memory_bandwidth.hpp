// The memory bandwidth one core gets here: the hardware limit that the bench bed's speed is measured
// against (docs/performance.md, "How far from the hardware limit"). STREAM-style copy and triad
// loops, and an update loop, over arrays far larger than any cache, one thread, best of several passes.
// STREAM counts the bytes a loop names, not the lines a store first reads for ownership (write-
// allocate): the triad moves 32 B per element, not the 24 it is credited with. The update loop
// (a = s a + b: every line it writes it has read) has no such ambiguity, and it is the figure to set
// against a count of the bytes a step moves with write-allocate included.
#pragma once

#include <cstddef>
#include <string>

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

}  // namespace hilldem
