// Quantity: a named, measurable value of a simulation (a ball's position, a contact's normal force, a
// wall's force sum, the time...). Histories and probes are both lists of Quantity.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/simulation_description.hpp"
#include "hilldem/io/toml_reader.hpp"

namespace hilldem {

enum class QuantityTarget { Global, Ball, Wall, BallBall, BallWall };

struct Quantity {
  QuantityTarget target = QuantityTarget::Global;
  std::string field;           // e.g. "normal_force"
  std::string name;            // "contact.normal_force", as written
  std::string unit;            // "N"
  std::int64_t ball = 0;       // user ids
  std::int64_t ball2 = 0;
  std::vector<std::size_t> walls;  // wall indices (a name or a group may select several; sums)
  std::string target_text;     // "balls 1-2", for listings
};

// Read `quantity` plus its target keys (`ball`, `balls`, `wall`) from a table; the targets must
// exist in `sim`.
Quantity read_quantity(TableReader& t, const SimulationDescription& sim);
// Value in SI units; NaN when the target does not exist now (e.g. a deleted contact).
double evaluate(const Simulation& sim, const Quantity& q);
// The list of known quantities with their units, for --help and docs.
std::string quantity_catalogue();

}  // namespace hilldem
