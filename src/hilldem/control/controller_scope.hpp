// ControllerScope: removes the controllers (Simulation::controllers) added while it lives when it
// goes out of scope, also on exceptions, so that a lab test's servos do not outlive the test.
#pragma once

#include <cstddef>

#include "hilldem/engine/simulation.hpp"

namespace hilldem {

struct ControllerScope {
  Simulation& sim;
  std::size_t before;
  explicit ControllerScope(Simulation& s) : sim(s), before(s.controllers.size()) {}
  ~ControllerScope() { sim.controllers.resize(before); }
  ControllerScope(const ControllerScope&) = delete;
  ControllerScope& operator=(const ControllerScope&) = delete;
};

}  // namespace hilldem
