// Scenario: a TOML file read into plain data (ScenarioDescription: the bodies, settings and rules as
// a SimulationDescription, plus the stages, histories, servos and outputs), then built into a ready
// Simulation (Scenario). Everything is validated by the reader, before anything is built or any
// cycle runs (docs/scenario-format.md lists every key).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hilldem/control/servo.hpp"
#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/quantity.hpp"
#include "hilldem/io/simulation_description.hpp"

namespace hilldem {

// Bodies a stage acts on.
struct Selection {
  std::vector<std::size_t> balls;  // indices
  std::vector<std::size_t> walls;  // indices
  std::string text;                // "ball 2", "group top", "wall floor"
};

enum class StageType { Cycle, Solve, Translate, Rotate, Set, SetContacts, SetSimulation, MakeWet, MakeDry, Probe, ListContacts, SetServo };

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
  std::optional<double> fric, damp_con, suction, emod, kratio, rolling_fric;
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
  // set_servo: the servo (index into Scenario::servos) and what changes; probe of a servo.* quantity:
  // the servo it reads (-1: an engine quantity)
  int servo = -1;
  std::optional<double> target_stress, gain_factor, max_speed;
  std::optional<bool> enabled;
};

struct History {
  std::string name;
  Quantity quantity;
  int servo = -1;  // servo.* quantities: index into Scenario::servos (quantity.field names the value)
};

// A scenario-level servo ([[servo]]): control/servo.hpp's Servo driving walls to a target stress,
// registered as a Simulation controller by the runner.
struct ScenarioServo {
  std::string name;
  std::string wall_text;  // the wall name or group it drives
  Servo servo;
  std::vector<std::size_t> walls;  // the walls it drives (indices)
};

// [snapshots]: VTK files for ParaView (io/vtk_writer.hpp), into <output dir>/<folder>.
struct SnapshotSettings {
  bool enabled = false;        // on when the table is present
  std::int64_t every = 0;      // every N steps (0: only at stage ends)
  bool at_stage_ends = true;   // after every stage that cycles or changes the state
  bool contacts = true, walls = true;
  bool binary = true;          // "binary" (appended raw) or "ascii"
  std::string folder = "snapshots";
};

// [checkpoints]: restart files into <output dir>/checkpoints (io/checkpoint.hpp).
struct CheckpointSettings {
  bool enabled = true;          // whenever there is an output folder, unless disabled
  std::int64_t every = 0;       // every N steps (0: not by steps)
  double every_seconds = 600;   // every S seconds of wall-clock time (0: not by time)
  bool at_stage_ends = true;    // after every stage that cycles or changes the state
  double stage_end_min_seconds = 60;  // [s] no stage-end checkpoint within this long of the last one
  int keep = 2;                 // newest checkpoints kept (older ones are deleted)
};

// Limits that keep hostile or mistaken input from exhausting memory.
struct ScenarioLimits {
  std::uint64_t max_balls = 50'000'000;  // as the reader's own guard
};

// What a scenario does with its bodies: the stages, histories, servos and outputs.
struct ScenarioPlan {
  std::string file;
  std::string text;  // the TOML source (checkpoints carry it, so a run resumes without the file)
  std::string title;
  std::vector<Stage> stages;
  std::vector<History> histories;
  std::int64_t history_every = 1;
  std::string output_dir;    // "" = no files written
  std::string history_file = "history.csv";
  std::vector<ScenarioServo> servos;
  SnapshotSettings snapshots;
  CheckpointSettings checkpoints;
  double blowup_fraction = 0.5;  // a free ball moving more than this × its radius in one step stops the run (0: off)
  // Index of the servo named `name`, or -1.
  int find_servo(const std::string& name) const;
};

// A scenario as read: its plan and the description of its Simulation, nothing built yet.
struct ScenarioDescription : ScenarioPlan {
  SimulationDescription sim;
};

// A scenario ready to run: its plan and the Simulation built from its description.
struct Scenario : ScenarioPlan {
  Simulation sim;
};

// Parse and validate; `file` names the source in error messages. Throws InputError.
ScenarioDescription read_scenario(const std::string& text, const std::string& file, const ScenarioLimits& limits = {});
ScenarioDescription read_scenario_file(const std::string& path);
// The plan as it is and the Simulation built from the description (build_simulation).
Scenario build_scenario(ScenarioDescription d);
// read_scenario (or read_scenario_file), then build_scenario.
Scenario load_scenario(const std::string& text, const std::string& file, const ScenarioLimits& limits = {});
Scenario load_scenario_file(const std::string& path);

const char* to_string(StageType t);

}  // namespace hilldem
