// Scenario: a TOML file read into a ready Simulation plus the stages to run on it. Everything is
// validated here, before any cycle runs (docs/scenario-format.md lists every key).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/quantity.hpp"

namespace hilldem {

// Bodies a stage acts on.
struct Selection {
  std::vector<std::size_t> balls;  // indices
  std::vector<std::size_t> walls;  // indices
  std::string text;                // "ball 2", "group top", "wall floor"
};

enum class StageType { Cycle, Solve, Translate, Rotate, Set, SetContacts, SetSimulation, MakeWet, MakeDry, Probe, ListContacts };

struct Stage {
  StageType type = StageType::Cycle;
  std::string name;
  std::int64_t steps = 0;            // cycle, translate, rotate
  double ratio = 1e-5;               // solve: mean unbalanced-force ratio limit [-]
  std::int64_t max_steps = 0;        // solve
  Selection sel;                     // translate, rotate, set
  Vec3 by;                           // translate [m], rotate [rad] (rotation vector)
  std::optional<Vec3> velocity, spin, position, applied_force;  // set
  std::optional<double> radial_velocity;                        // set (cylinder walls) [m/s]
  FixityMask fix = 0, free = 0;                                 // set
  // set_contacts: filter and new values
  std::optional<ModelKind> model_filter;
  std::optional<double> fric, damp_con, suction, emod, kratio;
  // set_simulation
  std::optional<Vec3> gravity;
  std::optional<double> local_damping, timestep;  // timestep 0 = auto
  // make_wet
  double wet_suction = 0.0, wet_gap = 0.0;  // [Pa], [m]
  // probe
  std::string label;
  Quantity quantity;
  std::string ratio_to;
  double scale = 1.0;
};

struct History {
  std::string name;
  Quantity quantity;
};

struct Scenario {
  std::string file;
  std::string title;
  Simulation sim;
  std::vector<Stage> stages;
  std::vector<History> histories;
  std::int64_t history_every = 1;
  std::string output_dir;    // "" = no files written
  std::string history_file = "history.csv";
};

// Parse and validate; `file` names the source in error messages. Throws InputError.
Scenario load_scenario(const std::string& text, const std::string& file);
Scenario load_scenario_file(const std::string& path);

const char* to_string(StageType t);

}  // namespace hilldem
