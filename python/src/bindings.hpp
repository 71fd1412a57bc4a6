// The parts of the hilldem._core module, one function per file (module.cpp calls them in order).
#pragma once

#include <pybind11/pybind11.h>

namespace hilldem::python {

void bind_simulation(pybind11::module_& m);  // bind_simulation.cpp: Simulation, cycling, stages, checkpoints
void bind_arrays(pybind11::class_<class PySimulation>& cls, pybind11::module_& m);  // bind_arrays.cpp: numpy views, setters, contacts
void bind_labtests(pybind11::module_& m);    // bind_labtests.cpp: grading, genesis, triaxial, verify

}  // namespace hilldem::python
