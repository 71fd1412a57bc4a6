#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "commands.hpp"

namespace hilldem::cli {

namespace {

// The argument as one shell word.
std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

void run_plot_script(const std::string& script, const std::string& folder, const std::string& what) {
  std::string path;
  for (const std::string p : {script, std::string(HILLDEM_SOURCE_DIR) + "/" + script})
    if (std::filesystem::exists(p)) {
      path = p;
      break;
    }
  if (path.empty()) {
    std::cout << what << ": " << script << " not found; skipped\n";
    return;
  }
  // Debian's interpreter is the one python3-matplotlib serves (a python3 earlier on PATH may lack it).
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = python + " " + quote(path) + " " + quote(folder);
  std::cout.flush();
  if (std::system(cmd.c_str()) != 0)
    std::cout << what << ": `" << cmd << "` failed (python3-matplotlib missing?); the CSV results stand\n";
}

}  // namespace hilldem::cli
