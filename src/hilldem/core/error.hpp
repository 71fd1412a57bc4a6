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

}  // namespace hilldem
