#include "hilldem/io/output_folder.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/file.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace fs = std::filesystem;

namespace {

// The command line of this process, for the lock file (Linux: /proc/self/cmdline, NUL-separated).
std::string command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (char& c : raw)
    if (c == '\0' || c == '\n') c = ' ';
  while (!raw.empty() && raw.back() == ' ') raw.pop_back();
  return raw.empty() ? "hilldem" : raw.substr(0, 1000);
}

std::string host_name() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) return "?";
  return host;
}

}  // namespace

std::string output_folder_problem(const std::string& dir) {
  if (dir.empty()) return "the folder name is empty";
  std::error_code ec;
  const fs::path p(dir);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) return "\"" + dir + "\" exists and is not a folder";
    if (::access(p.c_str(), W_OK | X_OK) != 0) return "the folder \"" + dir + "\" is not writable";
  } else {
    // The nearest existing parent must be a writable folder on a writable file system.
    fs::path parent = fs::absolute(p, ec).parent_path();
    while (!parent.empty() && !fs::exists(parent, ec) && parent != parent.root_path()) parent = parent.parent_path();
    if (!fs::is_directory(parent, ec))
      return "\"" + dir + "\" cannot be created: \"" + parent.string() + "\" is not a folder";
    struct statvfs vfs {};
    if (::access(parent.c_str(), W_OK | X_OK) != 0 || (::statvfs(parent.c_str(), &vfs) == 0 && (vfs.f_flag & ST_RDONLY)))
      return "\"" + dir + "\" cannot be created: \"" + parent.string() + "\" is not writable";
  }
  return "";
}

namespace {
std::string lock_file_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string holder = ss.str();
  for (char& c : holder)
    if (c == '\n') c = ';';
  while (!holder.empty() && (holder.back() == ';' || holder.back() == ' ')) holder.pop_back();
  return holder.empty() ? "holder unknown" : holder;
}
}  // namespace

std::string OutputLock::holder(const std::string& dir) {
  const std::string path = (fs::path(dir) / kLockFileName).string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "";
  std::string who;
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK) who = lock_file_text(path);
  ::close(fd);
  return who;
}

OutputLock::OutputLock(const std::string& dir, const std::string& what) : dir_(dir) {
  if (dir.empty()) throw InputError(what + ": the output folder name is empty");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw InputError(what + ": \"" + dir + "\": cannot create the output folder: " + (ec ? ec.message() : "not a folder"));
  const std::string path = (fs::path(dir) / kLockFileName).string();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw InputError(what + ": \"" + dir + "\": cannot write in the output folder (" + path + ": " + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    const std::string holder = lock_file_text(path);
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK)
      throw InputError(what + ": the output folder \"" + dir + "\" is in use by another hilldem process (" +
                       holder + "; lock file " + path +
                       "); wait for it to end or choose another folder");
    throw InputError(what + ": \"" + dir + "\": cannot lock the output folder (" + path + ": " + std::strerror(err) + ")");
  }
  const std::string text = "pid " + std::to_string(::getpid()) + "\nhost " + host_name() + "\ncommand " + command_line() + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, text.data(), text.size(), 0) != static_cast<ssize_t>(text.size())) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    fd_ = -1;
    throw InputError(what + ": \"" + dir + "\": cannot write in the output folder (" + path + ": " + why + ")");
  }
}

OutputLock& OutputLock::operator=(OutputLock&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = o.fd_;
    dir_ = std::move(o.dir_);
    o.fd_ = -1;
  }
  return *this;
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

}  // namespace hilldem
