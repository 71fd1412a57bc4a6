// Errors that reach users. InputError is bad input (exit status 2); RunError is a run that cannot
// go on (exit status 1). Both carry a message that names what went wrong and where.
#pragma once

#include <stdexcept>
#include <string>

namespace hilldem {

// Bad input: a file, a key, a value outside its allowed range. The CLI exits with status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A run that cannot continue (no equilibrium within the step limit, a blow-up). Exit status 1.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A run stopped on request (Simulation::interrupt answered true: the CLI caught SIGINT, SIGTERM or
// SIGHUP) after a complete cycle; the message says at which step. The CLI exits with 128 + the
// signal number.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Out of memory, caught where a phase begins or ends (std::bad_alloc): what was being allocated and
// roughly how much, so that the user can size the machine or the job. Exit status 1.
class OutOfMemory : public std::runtime_error {
 public:
  // "out of memory while <phase> (about <bytes> MB needed)"; bytes <= 0: size unknown.
  OutOfMemory(const std::string& phase, double bytes)
      : std::runtime_error("out of memory while " + phase +
                           (bytes > 0 ? " (about " + std::to_string(static_cast<long long>(bytes / 1048576.0 + 0.5)) +
                                            " MB needed)"
                                      : std::string())) {}
};

}  // namespace hilldem
