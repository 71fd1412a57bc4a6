// Checkpoint container: a binary file of named, versioned sections, each with its own CRC-32, behind
// a header with a format version and a trailer. Writing is atomic (temporary file in the same
// folder, flush, fsync, rename, fsync of the folder), so a crash leaves the previous checkpoint or
// the new one, never a torn file. Reading checks everything before anything is used: a corrupt,
// truncated or foreign file is an InputError naming the file and the problem (CLI exit status 2).
//
// Layout (little-endian):
//   header   magic "HDMCKPT\n" | u32 format version | u32 section count | u64 body bytes | u32 CRC of the header
//   section  u32 name length | name | u32 section version | u64 payload bytes | payload | u32 CRC of all before it in the section
//   trailer  magic "HDMEND\n\0"
//
// Sections are how the state is organised: the engine's state ("sim.*", io/state_io.hpp), the
// scenario runner's position ("run.*", io/runner.cpp), and anything a driver adds (lab tests:
// "labtest.<name>"). A reader asks for the sections it knows; unknown sections are skipped, so a
// driver can add sections without touching this file. Inside a section, SectionWriter/SectionReader
// encode numbers, strings and columns; every read is bounds-checked.
#pragma once

#include <cstdint>
#include <cstring>
#include <iosfwd>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "hilldem/core/error.hpp"
#include "hilldem/core/vec3.hpp"

namespace hilldem {

inline constexpr std::uint32_t kCheckpointFormatVersion = 1;

// Reads and writes of checkpoint files of at least this size report on the stream given to
// set_state_io_log (start, every ~5 s, end with the time taken); none when it is null (the default).
inline constexpr std::size_t kLargeStateBytes = std::size_t{100} << 20;
void set_state_io_log(std::ostream* out);

// CRC-32 (IEEE 802.3, as zlib), continuing from `crc` (0 to start).
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

// Encoder for one section's payload.
class SectionWriter {
 public:
  void u8(std::uint8_t v) { raw(&v, 1); }
  void u32(std::uint32_t v) { raw(&v, 4); }
  void u64(std::uint64_t v) { raw(&v, 8); }
  void i64(std::int64_t v) { raw(&v, 8); }
  void f64(double v) { raw(&v, 8); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void vec3(const Vec3& v) { f64(v.x), f64(v.y), f64(v.z); }
  void str(std::string_view s) {
    u64(s.size());
    raw(s.data(), s.size());
  }
  // A column of plain values (numbers, enums with a fixed underlying type, or structs of doubles
  // without padding): count, element size, then the bytes.
  template <class T>
  void column(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    u64(v.size());
    u32(static_cast<std::uint32_t>(sizeof(T)));
    raw(v.data(), v.size() * sizeof(T));
  }
  void raw(const void* p, std::size_t n) {
    const auto* b = static_cast<const char*>(p);
    bytes_.append(b, n);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// Decoder for one section's payload. Every read checks the remaining size; failures throw
// InputError("<file>: section '<name>': ...").
class SectionReader {
 public:
  SectionReader(std::string_view payload, std::string context, std::uint32_t version)
      : data_(payload), context_(std::move(context)), version_(version) {}

  std::uint32_t version() const { return version_; }
  std::uint8_t u8() { return get<std::uint8_t>(); }
  std::uint32_t u32() { return get<std::uint32_t>(); }
  std::uint64_t u64() { return get<std::uint64_t>(); }
  std::int64_t i64() { return get<std::int64_t>(); }
  double f64() { return get<double>(); }
  bool boolean();
  Vec3 vec3() { return {f64(), f64(), f64()}; }
  std::string str(std::size_t max_len = 1u << 26);
  // A count of items each at least min_item_bytes long, checked against what remains (so a corrupt
  // count can never make a huge allocation) and against max_count.
  std::uint64_t count(std::size_t min_item_bytes, std::uint64_t max_count = UINT64_MAX);
  template <class T>
  void column(std::vector<T>& v, const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (remaining() < 12) fail(std::string("column '") + what + "' is truncated");
    const std::uint64_t n = u64();
    const std::uint32_t size = u32();
    if (size != sizeof(T))
      fail(std::string("column '") + what + "' has " + std::to_string(size) + "-byte elements, this build uses " +
           std::to_string(sizeof(T)) + " (written by an incompatible hilldem build)");
    if (n > remaining() / sizeof(T)) fail(std::string("column '") + what + "' is truncated");
    v.resize(n);
    if (n) std::memcpy(v.data(), data_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
  }
  std::size_t remaining() const { return data_.size() - pos_; }
  // Every byte must have been read.
  void finish() const;
  [[noreturn]] void fail(const std::string& message) const;
  const std::string& context() const { return context_; }

 private:
  template <class T>
  T get() {
    if (remaining() < sizeof(T)) fail("truncated (needs " + std::to_string(sizeof(T)) + " more bytes at offset " + std::to_string(pos_) + ")");
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string_view data_;
  std::size_t pos_ = 0;
  std::string context_;
  std::uint32_t version_;
};

// Builds a checkpoint: add sections in any order (names unique), then write it.
class CheckpointWriter {
 public:
  // Start a section; the returned writer stays valid until the next call to section().
  SectionWriter& section(const std::string& name, std::uint32_t version = 1);
  // The whole file as bytes.
  std::string bytes() const;
  // Atomic write to path (tmp file, fsync, rename, fsync of the folder), streamed from the sections
  // (the file is never assembled in memory). Throws RunError on I/O failure.
  void write_file(const std::string& path) const;

  struct SectionView {
    const std::string* name;
    std::uint32_t version;
    const std::string* payload;
  };

 private:
  std::vector<SectionView> views() const;
  struct Section {
    std::string name;
    std::uint32_t version;
    SectionWriter data;
  };
  std::vector<Section> sections_;
};

// A checkpoint read and verified as a whole (magic, version, sizes, every checksum) on construction.
class CheckpointReader {
 public:
  // Throws InputError naming `source` (usually the file path) when anything is wrong.
  static CheckpointReader from_bytes(std::string bytes, const std::string& source);
  static CheckpointReader from_file(const std::string& path);

  bool has(const std::string& name) const;
  // The section's decoder; InputError if it is missing or newer than max_version.
  SectionReader section(const std::string& name, std::uint32_t max_version = 1) const;
  std::vector<std::string> names() const;
  std::size_t section_size(const std::string& name) const;
  const std::string& source() const { return source_; }

 private:
  struct Entry {
    std::string name;
    std::uint32_t version;
    std::size_t offset, size;
  };
  std::string bytes_;
  std::string source_;
  std::vector<Entry> entries_;
};

// Write `bytes` to `path` atomically: a temporary file in the same folder, renamed over `path`, so
// readers never see a half-written file. With `durable` the data and the rename are also fsync'ed
// (checkpoints); without, a power failure may lose the newest version (snapshots, which a rerun or a
// resume rewrites).
void write_file_atomically(const std::string& path, std::string_view bytes, bool durable = true);

}  // namespace hilldem
