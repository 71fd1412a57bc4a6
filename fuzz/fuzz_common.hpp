// Shared by the fuzz targets: what counts as a correct refusal. Input may be refused only with
// hilldem::InputError (the CLI's exit status 2) carrying a message that starts with the source name;
// any other exception, a crash, a hang or a sanitizer report is a bug.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "hilldem/core/error.hpp"

namespace hilldem::fuzz {

[[noreturn]] inline void bug(const char* what, const std::string& message) {
  std::fprintf(stderr, "hilldem fuzz: %s: %s\n", what, message.c_str());
  std::abort();
}

// Run f(); a refusal must be an InputError naming `source`.
template <class F>
void expect_clean_refusal(const std::string& source, F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.rfind(source + ": ", 0) != 0 || m.size() <= source.size() + 2) bug("an InputError that does not name the input", m);
  } catch (const RunError&) {
    // Accepted input whose run then fails (exit status 1, e.g. a blow-up): not a refusal, fine.
  } catch (const std::exception& e) {
    bug("an exception other than InputError", e.what());
  }
}

}  // namespace hilldem::fuzz
