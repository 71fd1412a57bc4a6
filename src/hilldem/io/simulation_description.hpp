// SimulationDescription: what a Simulation is made of before it runs, as plain data: the settings,
// the group names, the balls, the walls and the assignment rules, each list in index order. The
// scenario reader (io/scenario.hpp) fills one from a TOML file; build_simulation turns it into a
// Simulation.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hilldem/engine/simulation.hpp"

namespace hilldem {

struct SimulationDescription {
  SimulationSettings settings;
  GroupNames groups;             // the names behind the balls' and walls' group bits
  std::vector<BallInit> balls;   // ball i becomes index i
  std::vector<Wall> walls;       // wall k becomes index k
  std::vector<ModelRule> rules;  // the assignment table (the first matching rule applies)
  // Clumps, added after the balls (their pebbles are the balls that follow): templates, and each
  // clump's template index and placement.
  std::vector<ClumpTemplate> clump_templates;
  struct Clump {
    std::size_t tmpl = 0;
    ClumpInit init;
  };
  std::vector<Clump> clumps;

  // Index of the ball with user id `id`, or -1 (the balls only: not the clumps' pebbles).
  long find_ball(std::int64_t id) const;
  // Whether `id` is a ball's or a clump's pebble's (clump c's pebbles: first_ball_id, +1, ...).
  bool has_ball_id(std::int64_t id) const;
  // Indices of the walls named `name` or in the group `name`, in index order.
  std::vector<std::size_t> walls_named(const std::string& name) const;
};

// The Simulation described, at time 0 with no contacts: its settings, group names and rules, and the
// balls and walls added in order. Nothing is validated here; read_scenario validates what it reads.
Simulation build_simulation(const SimulationDescription& d);

}  // namespace hilldem
