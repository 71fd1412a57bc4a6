// The lab commands' graceful stop (triaxial, t307): the first SIGINT, SIGTERM or SIGHUP ends the test
// after the cycle it is in (Simulation::interrupt, Interrupted); a second one stops the process at
// once (io/stop_signal.hpp). A lab test writes no checkpoint: what is kept are the packed specimens
// it finished, which `--specimen` reads to skip their packing (the dearest part of a test).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/stop_signal.hpp"

namespace hilldem::cli {

std::function<bool()> lab_stop_check(RunDecomposition* ranks) {
  install_stop_handlers();
  if (ranks) return [ranks] { return ranks->max(stop_requested()) != 0; };
  return [] { return stop_requested() != 0; };
}

OutputLock lab_output_lock(const std::string& dir, RunDecomposition* ranks) {
  if (!ranks) return OutputLock(dir, "-o");
  OutputLock lock;
  std::string error;
  if (ranks->rank() == 0) try {
      lock = OutputLock(dir, "-o");
    } catch (const InputError& e) {
      error = e.what();
    }
  error = ranks->from_root(error);
  if (!error.empty()) throw InputError(error);
  return lock;
}

int report_lab_stop(const Interrupted& e, const std::string& output_dir, const std::string& command) {
  namespace fs = std::filesystem;
  const int sig = stop_requested();
  std::vector<std::string> saved;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(output_dir) / "specimens", ec))
    if (entry.path().extension() == ".csv" && entry.path().stem().string().ends_with("_packed"))
      saved.push_back(entry.path().string());
  std::sort(saved.begin(), saved.end());
  std::cerr << "hilldem " << command << ": stopped by " << signal_name(sig) << " (" << e.what()
            << "); a lab test keeps no checkpoint, its results were not written.\n";
  if (saved.empty()) {
    std::cerr << "No packed specimen was saved in " << (fs::path(output_dir) / "specimens").string()
              << "; run the command again.\n";
  } else {
    std::cerr << "Packed specimens finished (run again with --specimen FILE to skip the packing):\n";
    for (const std::string& f : saved) std::cerr << "  " << f << "\n";
  }
  return 128 + sig;
}

}  // namespace hilldem::cli
