// An output folder and its owner. A run (or resume, or lab test) holds an advisory lock (flock) on
// <folder>/.hilldem.lock for as long as it writes there, so that two processes can never write into
// the same folder at once (their history files would splice). The lock file names its holder: pid,
// host and command line. The kernel drops the lock when the process ends, however it ends (kill -9
// included), so a stale lock file never blocks a later run.
#pragma once

#include <string>

namespace hilldem {

inline constexpr const char* kLockFileName = ".hilldem.lock";

// What is wrong with `dir` as an output folder, without creating anything ("" when nothing is
// found): empty, an existing file that is not a folder, or a place where it cannot be created or
// written (the nearest existing parent is not a writable folder). `hilldem check` uses it; creating
// the folder can still fail later (run: InputError, exit status 2).
std::string output_folder_problem(const std::string& dir);

class OutputLock {
 public:
  OutputLock() = default;
  // Creates `dir` if needed and takes its lock. InputError (exit status 2) naming `what` (the key or
  // option that gave the folder) when the folder cannot be created or written, and naming the holder
  // when another process holds the lock.
  OutputLock(const std::string& dir, const std::string& what);
  OutputLock(OutputLock&& o) noexcept : fd_(o.fd_), dir_(std::move(o.dir_)) { o.fd_ = -1; }
  OutputLock& operator=(OutputLock&& o) noexcept;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  ~OutputLock();
  bool held() const { return fd_ >= 0; }
  // Who holds the lock of `dir` now, as the lock file names it ("" when no process holds it).
  // Creates nothing.
  static std::string holder(const std::string& dir);
  const std::string& dir() const { return dir_; }

 private:
  int fd_ = -1;
  std::string dir_;
};

}  // namespace hilldem
