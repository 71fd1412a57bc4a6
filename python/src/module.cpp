// hilldem._core: the engine's C++ API for Python (docs/python.md). The package hilldem
// (python/hilldem/__init__.py) re-exports it with the scenario builder written in Python.
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "hilldem/core/error.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() = "hilldem's engine: simulations, numpy views of their balls, checkpoints and the lab tests";
  // The engine's two error kinds, with the engine's message unchanged: bad input (the CLI's exit
  // status 2) is a ValueError, a run that cannot go on (exit status 1) a RuntimeError.
  py::register_exception<hilldem::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<hilldem::RunError>(m, "RunError", PyExc_RuntimeError);
  hilldem::python::bind_simulation(m);
  hilldem::python::bind_labtests(m);
}
