#include "hilldem/io/simulation_description.hpp"

namespace hilldem {

long SimulationDescription::find_ball(std::int64_t id) const {
  for (std::size_t i = 0; i < balls.size(); ++i)
    if (balls[i].id == id) return static_cast<long>(i);
  return -1;
}

bool SimulationDescription::has_ball_id(std::int64_t id) const {
  if (find_ball(id) >= 0) return true;
  for (const Clump& c : clumps) {
    const auto n = static_cast<std::int64_t>(clump_templates[c.tmpl].pebbles.size());
    if (id >= c.init.first_ball_id && id - c.init.first_ball_id < n) return true;
  }
  return false;
}

std::vector<std::size_t> SimulationDescription::walls_named(const std::string& name) const {
  std::vector<std::size_t> out;
  const std::uint64_t bit = groups.find(name);
  for (std::size_t k = 0; k < walls.size(); ++k)
    if (walls[k].name == name || (bit && (walls[k].groups & bit))) out.push_back(k);
  return out;
}

Simulation build_simulation(const SimulationDescription& d) {
  Simulation sim;
  sim.settings = d.settings;
  sim.groups = d.groups;
  for (const BallInit& b : d.balls) sim.balls.add(b);
  for (const SimulationDescription::Clump& c : d.clumps) sim.clumps.add(sim.balls, d.clump_templates[c.tmpl], c.init);
  for (const Wall& w : d.walls) sim.walls.add(w);
  sim.table.rules = d.rules;
  return sim;
}

}  // namespace hilldem
