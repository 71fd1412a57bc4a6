// libFuzzer target: the checkpoint reader, as `hilldem resume` and `hilldem inspect` run it: the
// container (magic, version, sizes, checksums), every section decoder and validator, the scenario the
// checkpoint carries, the restore, and one cycle of the resumed run.
//
// Random bytes almost never pass the CRC-32 checks, so a custom mutator repairs the checksums and
// sizes of most mutants (LLVMFuzzerCustomMutator): the decoders behind the checksums get fuzzed too,
// while unrepaired mutants keep exercising the container checks.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "fuzz_common.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

constexpr std::size_t kHeader = 28, kTrailer = 8;

template <class T>
T load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

// Make the checksums (and, where the layout still parses, the sizes) of a mutant consistent.
void repair(std::uint8_t* d, std::size_t size) {
  if (size < kHeader + kTrailer || std::memcmp(d, "HDMCKPT\n", 8) != 0) return;
  const std::size_t end = size - kTrailer;
  std::memcpy(d + end, "HDMEND\n\0", kTrailer);
  std::size_t pos = kHeader;
  std::uint32_t sections = 0;
  while (end - pos >= 4 + 1 + 12 + 4) {
    const std::size_t start = pos;
    const auto name_len = load<std::uint32_t>(d + pos);
    if (name_len == 0 || name_len > 255 || end - pos < 4 + name_len + 12 + 4) break;
    pos += 4 + name_len + 4;
    std::uint64_t payload = load<std::uint64_t>(d + pos);
    if (payload > end - pos - 8 - 4) payload = end - pos - 8 - 4;  // clamp to what is there
    store<std::uint64_t>(d + pos, payload);
    pos += 8 + payload;
    store<std::uint32_t>(d + pos, hilldem::crc32(d + start, pos - start));
    pos += 4;
    ++sections;
  }
  store<std::uint32_t>(d + 12, sections);
  store<std::uint64_t>(d + 16, pos - kHeader);
  if (pos != end) return;  // trailing bytes: leave the size mismatch for the reader to find
  store<std::uint32_t>(d + 8, 1);
  store<std::uint32_t>(d + 24, hilldem::crc32(d, 24));
}

// The saved state's digest (run.meta) guards against any change of a saved value; recompute it for
// the mutant's state when that state decodes, so that mutated values reach the restore and the cycle.
void refresh_digest(std::uint8_t* d, std::size_t size) {
  try {
    const hilldem::CheckpointReader r =
        hilldem::CheckpointReader::from_bytes(std::string(reinterpret_cast<const char*>(d), size), "mutant");
    hilldem::Simulation sim;
    hilldem::read_simulation(r, sim, false);
    const std::string digest = hilldem::state_digest(sim);
    // run.meta: kind, message (strings), time (i64), digest (string of 16 hex digits).
    const std::string needle = std::string("run.meta");
    const std::string view(reinterpret_cast<const char*>(d), size);
    const std::size_t at = view.find(needle, kHeader);
    if (at == std::string::npos) return;
    std::size_t pos = at + needle.size() + 4 + 8;  // version, size
    for (int k = 0; k < 2; ++k) {
      if (pos + 8 > size) return;
      pos += 8 + load<std::uint64_t>(d + pos);
    }
    pos += 8;
    if (pos + 8 + 16 > size || load<std::uint64_t>(d + pos) != 16) return;
    std::memcpy(d + pos + 8, digest.data(), 16);
    repair(d, size);
  } catch (const std::exception&) {
  }
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned seed) {
  size = LLVMFuzzerMutate(data, size, max_size);
  if (seed % 8 != 0) repair(data, size);         // 7 in 8 mutants get valid checksums,
  if (seed % 8 >= 4) refresh_digest(data, size);  // half of them a valid state digest too
  return size;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  hilldem::fuzz::expect_clean_refusal("fuzz.hdc", [&] {
    const hilldem::CheckpointReader r = hilldem::CheckpointReader::from_bytes(bytes, "fuzz.hdc");
    hilldem::describe_checkpoint(r, 1);  // hilldem inspect --ball 1 (an unknown ball is a clean refusal too)
  });
  hilldem::fuzz::expect_clean_refusal("fuzz.hdc", [&] {
    const hilldem::CheckpointReader r = hilldem::CheckpointReader::from_bytes(bytes, "fuzz.hdc");
    hilldem::Scenario sc;
    hilldem::RunOptions o;
    o.quiet = true;
    o.write_files = false;
    o.halt_after_step = 0;  // stop after the first cycle of the resumed run
    std::ostringstream log;
    hilldem::resume_scenario(r, sc, o, log);
  });
  return 0;
}
