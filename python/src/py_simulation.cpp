#include "py_simulation.hpp"

#include <fmt/format.h>
#include <pybind11/pybind11.h>

namespace hilldem::python {

void PySimulation::check_usable(const char* what) const {
  if (!failure_.empty())
    throw RunError(fmt::format("{}: the simulation stopped at step {} with an error and cannot continue "
                               "(load a checkpoint or build it again): {}",
                               what, sim().steps, failure_));
}

void PySimulation::check_idle(const char* what) const {
  if (busy) throw std::runtime_error(fmt::format("{}: the simulation is cycling in another thread; wait for that call to return", what));
}

void PySimulation::check_no_views(const char* what) const {
  if (live_views > 0)
    throw pybind11::buffer_error(fmt::format(
        "{}: {} numpy view(s) of this simulation's ball arrays are alive, and adding balls may move the "
        "arrays in memory; delete the views (del) or take copies (numpy.array(view)) first",
        what, live_views));
}

}  // namespace hilldem::python
