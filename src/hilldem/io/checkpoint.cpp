#include "hilldem/io/checkpoint.hpp"

#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <fcntl.h>
#include <ostream>
#include <sys/stat.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "hilldem/io/fault_injection.hpp"

namespace hilldem {

static_assert(std::endian::native == std::endian::little, "checkpoints are written little-endian");

namespace {

constexpr char kMagic[8] = {'H', 'D', 'M', 'C', 'K', 'P', 'T', '\n'};
constexpr char kTrailer[8] = {'H', 'D', 'M', 'E', 'N', 'D', '\n', '\0'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + 4;
constexpr std::size_t kMaxSectionName = 255;

// Slicing-by-8 tables: t[0] is the byte-wise table of the reflected polynomial 0xEDB88320 (zlib's
// CRC-32); t[k][n] is the CRC of byte n followed by k zero bytes, so 8 bytes are folded per step.
std::array<std::array<std::uint32_t, 256>, 8> make_crc_tables() {
  std::array<std::array<std::uint32_t, 256>, 8> t{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][n] = c;
  }
  for (std::uint32_t n = 0; n < 256; ++n)
    for (int k = 1; k < 8; ++k) t[k][n] = (t[k - 1][n] >> 8) ^ t[0][t[k - 1][n] & 0xFFu];
  return t;
}

template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
T get_at(const std::string& in, std::size_t offset) {
  T v;
  std::memcpy(&v, in.data() + offset, sizeof(T));
  return v;
}

std::string errno_text() { return std::strerror(errno); }

std::ostream* g_io_log = nullptr;

// Lines on g_io_log for a read or write of at least kLargeStateBytes: when it starts, every ~5 s,
// and when it ends, with the size [MB] and the time taken [s].
class LargeIoReport {
 public:
  LargeIoReport(const char* verb, const std::string& path, std::size_t total)
      : verb_(verb), path_(path), total_(total), on_(g_io_log && total >= kLargeStateBytes) {
    if (on_) *g_io_log << "checkpoint: " << verb_ << " " << path_ << " (" << mb(total_) << " MB)\n" << std::flush;
  }
  void at(std::size_t done) {
    if (!on_) return;
    const double t = seconds();
    if (done < total_ && t - last_ < 5.0) return;
    last_ = t;
    if (done < total_)
      *g_io_log << "checkpoint: " << verb_ << " " << path_ << ": " << mb(done) << " of " << mb(total_) << " MB (" << t << " s)\n"
                << std::flush;
    else
      *g_io_log << "checkpoint: " << verb_ << " " << path_ << ": done, " << mb(total_) << " MB in " << t << " s\n" << std::flush;
  }

 private:
  static long long mb(std::size_t b) { return static_cast<long long>(b >> 20); }
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
  const char* verb_;
  std::string path_;
  std::size_t total_;
  bool on_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  double last_ = 0.0;
};

}  // namespace

std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc) {
  static const auto t = make_crc_tables();
  const auto* p = static_cast<const unsigned char*>(data);
  crc = ~crc;
  for (; size >= 8; size -= 8, p += 8) {
    std::uint32_t lo, hi;
    std::memcpy(&lo, p, 4);  // (little-endian, checked above)
    std::memcpy(&hi, p + 4, 4);
    lo ^= crc;
    crc = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^ t[3][hi & 0xFFu] ^
          t[2][(hi >> 8) & 0xFFu] ^ t[1][(hi >> 16) & 0xFFu] ^ t[0][hi >> 24];
  }
  for (; size > 0; --size) crc = t[0][(crc ^ *p++) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

void set_state_io_log(std::ostream* out) { g_io_log = out; }

// ---- SectionReader ----

bool SectionReader::boolean() {
  const std::uint8_t v = u8();
  if (v > 1) fail("a boolean holds " + std::to_string(v));
  return v == 1;
}

std::string SectionReader::str(std::size_t max_len) {
  const std::uint64_t n = u64();
  if (n > remaining()) fail("a string of " + std::to_string(n) + " bytes is truncated");
  if (n > max_len) fail("a string of " + std::to_string(n) + " bytes is longer than " + std::to_string(max_len));
  std::string s(data_.substr(pos_, n));
  pos_ += n;
  return s;
}

std::uint64_t SectionReader::count(std::size_t min_item_bytes, std::uint64_t max_count) {
  const std::uint64_t n = u64();
  if (n > max_count) fail("a count of " + std::to_string(n) + " exceeds the limit " + std::to_string(max_count));
  if (min_item_bytes > 0 && n > remaining() / min_item_bytes)
    fail("a count of " + std::to_string(n) + " items does not fit in the " + std::to_string(remaining()) +
         " bytes left");
  return n;
}

void SectionReader::finish() const {
  if (remaining() != 0) fail(std::to_string(remaining()) + " unexpected bytes at the end");
}

void SectionReader::fail(const std::string& message) const { throw InputError(context_ + ": " + message); }

// ---- CheckpointWriter ----

SectionWriter& CheckpointWriter::section(const std::string& name, std::uint32_t version) {
  if (name.empty() || name.size() > kMaxSectionName) throw RunError("checkpoint section names are 1-255 bytes: '" + name + "'");
  for (const Section& s : sections_)
    if (s.name == name) throw RunError("checkpoint section '" + name + "' written twice");
  sections_.push_back({name, version, {}});
  return sections_.back().data;
}

namespace {
// A file's bytes as consecutive pieces (the sections' payloads are not copied into one string).
using Pieces = std::vector<std::string_view>;
void write_atomically(const std::string& path, const Pieces& pieces, bool checkpoint, bool durable);
}  // namespace

// The file as pieces: `frames` holds the header, each section's header and CRC and the trailer;
// the pieces point into it and into the sections' payloads.
static Pieces layout(const std::vector<CheckpointWriter::SectionView>& sections, std::vector<std::string>& frames) {
  frames.clear();
  frames.reserve(2 * sections.size() + 1);
  std::uint64_t body = 0;
  std::vector<std::size_t> head_of;
  for (const auto& s : sections) {
    std::string head;
    put<std::uint32_t>(head, static_cast<std::uint32_t>(s.name->size()));
    head += *s.name;
    put<std::uint32_t>(head, s.version);
    put<std::uint64_t>(head, s.payload->size());
    std::string tail;
    put<std::uint32_t>(tail, crc32(s.payload->data(), s.payload->size(), crc32(head.data(), head.size())));
    body += head.size() + s.payload->size() + tail.size();
    frames.push_back(std::move(head));
    frames.push_back(std::move(tail));
  }
  std::string header(kMagic, sizeof kMagic);
  put<std::uint32_t>(header, kCheckpointFormatVersion);
  put<std::uint32_t>(header, static_cast<std::uint32_t>(sections.size()));
  put<std::uint64_t>(header, body);
  put<std::uint32_t>(header, crc32(header.data(), header.size()));
  frames.push_back(std::move(header));
  Pieces out;
  out.push_back(frames.back());
  for (std::size_t k = 0; k < sections.size(); ++k) {
    out.push_back(frames[2 * k]);
    out.push_back(*sections[k].payload);
    out.push_back(frames[2 * k + 1]);
  }
  out.push_back(std::string_view(kTrailer, sizeof kTrailer));
  return out;
}

std::vector<CheckpointWriter::SectionView> CheckpointWriter::views() const {
  std::vector<SectionView> v;
  for (const Section& s : sections_) v.push_back({&s.name, s.version, &s.data.bytes()});
  return v;
}

std::string CheckpointWriter::bytes() const {
  std::vector<std::string> frames;
  std::string out;
  for (std::string_view p : layout(views(), frames)) out += p;
  return out;
}

void CheckpointWriter::write_file(const std::string& path) const {
  std::vector<std::string> frames;
  write_atomically(path, layout(views(), frames), true, true);
}

void write_file_atomically(const std::string& path, std::string_view bytes, bool durable) {
  write_atomically(path, Pieces{bytes}, false, durable);
}

namespace {
void write_all(int fd, const char* data, std::size_t size, const std::string& tmp) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = errno_text();
      ::close(fd);
      ::unlink(tmp.c_str());
      throw RunError(tmp + ": write failed: " + why);
    }
    done += static_cast<std::size_t>(n);
  }
}

void write_atomically(const std::string& path, const Pieces& pieces, bool checkpoint, bool durable) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = target.string() + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw RunError(tmp.string() + ": cannot create: " + errno_text());
  std::size_t total = 0;
  for (std::string_view p : pieces) total += p.size();
  LargeIoReport report("writing", path, total);
  const std::size_t half = total / 2;
  std::size_t done = 0;
  constexpr std::size_t kChunk = std::size_t{64} << 20;
  for (std::string_view p : pieces) {
    for (std::size_t at = 0; at < p.size();) {
      // Pieces are cut at the half (fault injection) and into chunks (progress lines).
      std::size_t n = std::min(p.size() - at, kChunk);
      if (done < half && done + n > half) n = half - done;
      write_all(fd, p.data() + at, n, tmp.string());
      at += n;
      done += n;
      if (done < total) report.at(done);
      // Fault injection (tests only): die by SIGKILL with the temporary file half written.
      if (checkpoint && done == half) fault_injection().on_checkpoint_half_written();
    }
  }
  if (durable && ::fsync(fd) != 0) {
    const std::string why = errno_text();
    ::close(fd);
    ::unlink(tmp.c_str());
    throw RunError(tmp.string() + ": fsync failed: " + why);
  }
  if (::close(fd) != 0) {
    ::unlink(tmp.c_str());
    throw RunError(tmp.string() + ": close failed: " + errno_text());
  }
  if (::rename(tmp.c_str(), target.c_str()) != 0) {
    const std::string why = errno_text();
    ::unlink(tmp.c_str());
    throw RunError(target.string() + ": rename from the temporary file failed: " + why);
  }
  if (durable) {
    // The rename is durable only once the folder entry is on disk.
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      ::fsync(dfd);
      ::close(dfd);
    }
  }
  report.at(total);  // (the time includes the fsyncs)
}

}  // namespace

// ---- CheckpointReader ----

CheckpointReader CheckpointReader::from_file(const std::string& path) {
  // stat before opening: a FIFO would block the open, a device (/dev/zero) would read forever.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path + ": cannot open the checkpoint file: " + errno_text());
  if (S_ISDIR(st.st_mode)) throw InputError(path + ": is a folder, not a checkpoint file");
  if (!S_ISREG(st.st_mode))
    throw InputError(path + ": is not a regular file (" +
                     (S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "a special file") +
                     "), not a checkpoint file");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw InputError(path + ": cannot open the checkpoint file: " + errno_text());
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) throw InputError(path + ": is not a regular file, not a checkpoint file");
  const auto size = static_cast<std::size_t>(st.st_size);
  auto read_exactly = [&](char* into, std::size_t n, std::size_t at) {
    std::size_t done = 0;
    while (done < n) {
      const ssize_t got = ::pread(fd, into + done, n - done, static_cast<off_t>(at + done));
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) throw InputError(path + ": cannot read the checkpoint file: " + errno_text());
      if (got == 0) throw InputError(path + ": the checkpoint file shrank while it was read");
      done += static_cast<std::size_t>(got);
    }
  };
  // The magic first: a foreign file is refused without reading it whole.
  std::string bytes(std::min(size, sizeof kMagic), '\0');
  read_exactly(bytes.data(), bytes.size(), 0);
  if (bytes.size() == sizeof kMagic && std::memcmp(bytes.data(), kMagic, sizeof kMagic) == 0 && size > sizeof kMagic) {
    LargeIoReport report("reading", path, size);
    try {
      bytes.resize(size);
    } catch (const std::bad_alloc&) {
      throw OutOfMemory("reading the checkpoint " + path, static_cast<double>(size));
    }
    constexpr std::size_t kChunk = std::size_t{64} << 20;
    for (std::size_t at = sizeof kMagic; at < size; at += kChunk) {
      read_exactly(bytes.data() + at, std::min(kChunk, size - at), at);
      report.at(at + std::min(kChunk, size - at));
    }
  }
  return from_bytes(std::move(bytes), path);
}

CheckpointReader CheckpointReader::from_bytes(std::string bytes, const std::string& source) {
  auto fail = [&](const std::string& m) -> void { throw InputError(source + ": " + m); };
  const std::size_t total = bytes.size();
  if (total == 0) fail("empty file: not a hilldem checkpoint");
  if (total < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    fail("not a hilldem checkpoint (the file does not start with the checkpoint magic)");
  if (total < kHeaderBytes) fail("truncated checkpoint: " + std::to_string(total) + " bytes, shorter than the header");
  const auto version = get_at<std::uint32_t>(bytes, 8);
  const auto n_sections = get_at<std::uint32_t>(bytes, 12);
  const auto body = get_at<std::uint64_t>(bytes, 16);
  const auto header_crc = get_at<std::uint32_t>(bytes, 24);
  if (crc32(bytes.data(), 24) != header_crc) fail("corrupt checkpoint: header checksum mismatch");
  if (version != kCheckpointFormatVersion)
    fail("checkpoint format version " + std::to_string(version) + "; this hilldem reads version " +
         std::to_string(kCheckpointFormatVersion));
  const std::size_t expected = kHeaderBytes + sizeof kTrailer;
  if (body > total || total - std::min<std::size_t>(total, expected) < body) {
    fail("truncated checkpoint: the header announces " + std::to_string(body + expected) + " bytes, the file has " +
         std::to_string(total));
  }
  if (total != expected + body)
    fail("checkpoint size mismatch: the header announces " + std::to_string(body + expected) + " bytes, the file has " +
         std::to_string(total) + " (trailing data)");
  if (std::memcmp(bytes.data() + total - sizeof kTrailer, kTrailer, sizeof kTrailer) != 0)
    fail("corrupt checkpoint: the end marker is missing");

  CheckpointReader r;
  r.source_ = source;
  std::size_t pos = kHeaderBytes;
  const std::size_t end = kHeaderBytes + body;
  for (std::uint32_t k = 0; k < n_sections; ++k) {
    const std::size_t start = pos;
    const std::string where = "section " + std::to_string(k + 1) + " of " + std::to_string(n_sections);
    if (end - pos < 4) fail("truncated checkpoint: " + where + " has no header");
    const auto name_len = get_at<std::uint32_t>(bytes, pos);
    pos += 4;
    if (name_len == 0 || name_len > kMaxSectionName) fail("corrupt checkpoint: " + where + " has a name of " + std::to_string(name_len) + " bytes");
    if (end - pos < name_len + 4 + 8) fail("truncated checkpoint: " + where + " has no header");
    std::string name = bytes.substr(pos, name_len);
    pos += name_len;
    const auto sversion = get_at<std::uint32_t>(bytes, pos);
    pos += 4;
    const auto size = get_at<std::uint64_t>(bytes, pos);
    pos += 8;
    if (size > end - pos || end - pos - size < 4)
      fail("corrupt or truncated checkpoint: " + where + " ('" + name + "', " + std::to_string(size) + " bytes) runs past the end");
    const std::size_t payload = pos;
    pos += size;
    const auto crc = get_at<std::uint32_t>(bytes, pos);
    if (crc32(bytes.data() + start, pos - start) != crc)
      fail("corrupt checkpoint: section '" + name + "' fails its checksum");
    pos += 4;
    for (const Entry& e : r.entries_)
      if (e.name == name) fail("corrupt checkpoint: section '" + name + "' appears twice");
    r.entries_.push_back({std::move(name), sversion, payload, static_cast<std::size_t>(size)});
  }
  if (pos != end) fail("corrupt checkpoint: " + std::to_string(end - pos) + " bytes after the last section");
  r.bytes_ = std::move(bytes);
  return r;
}

bool CheckpointReader::has(const std::string& name) const {
  for (const Entry& e : entries_)
    if (e.name == name) return true;
  return false;
}

SectionReader CheckpointReader::section(const std::string& name, std::uint32_t max_version) const {
  for (const Entry& e : entries_)
    if (e.name == name) {
      if (e.version > max_version || e.version == 0)
        throw InputError(source_ + ": section '" + name + "' has version " + std::to_string(e.version) +
                         "; this hilldem reads up to version " + std::to_string(max_version));
      return SectionReader(std::string_view(bytes_).substr(e.offset, e.size), source_ + ": section '" + name + "'",
                           e.version);
    }
  throw InputError(source_ + ": the checkpoint has no section '" + name + "'");
}

std::vector<std::string> CheckpointReader::names() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.name);
  return out;
}

std::size_t CheckpointReader::section_size(const std::string& name) const {
  for (const Entry& e : entries_)
    if (e.name == name) return e.size;
  return 0;
}

}  // namespace hilldem
