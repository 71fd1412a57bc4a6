// Runner: executes a scenario's stages on its Simulation, writes the CSV history and collects probes.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "hilldem/io/scenario.hpp"

namespace hilldem {

struct ProbeValue {
  std::string label;
  std::string quantity;  // "contact.normal_force"
  std::string target;    // "balls 1-2"
  std::string unit;
  double value = 0.0;
};

struct RunOptions {
  bool quiet = false;             // no progress lines
  std::string output_dir;         // overrides the scenario's [output] dir when not empty
  bool write_files = true;        // false: never write the history (verify, tests)
};

struct RunResult {
  std::vector<ProbeValue> probes;
  std::string history_path;  // "" when none was written
  const ProbeValue* find(const std::string& label) const;
};

// Runs every stage in order. Progress and listings go to `log`. Throws RunError when a stage fails.
RunResult run_scenario(Scenario& sc, const RunOptions& options, std::ostream& log);

// One line per contact: pieces, model, rule and why, state. The "contacts" CLI command and the
// list_contacts stage print it.
std::string contact_listing(const Simulation& sim);

}  // namespace hilldem
