// PySimulation: what a Python hilldem.Simulation holds: a Scenario (its Simulation and, when it came
// from a TOML file, the stages, histories and servos), whether a step has failed, and how many numpy
// views of its ball columns are alive.
//
// Two rules keep Python from reaching freed or inconsistent memory:
//   * a failed step (RunError from the engine: a non-finite force, a blow-up) leaves the state where
//     it stopped, for inspection; every later call that would cycle raises RunError naming the
//     first failure (the state is not one to continue from);
//   * a ball column's view points into the column's std::vector: anything that could reallocate the
//     columns (adding balls) is refused with BufferError while any view is alive, as Python refuses
//     to resize a bytearray with live exports;
//   * while C++ cycles with the GIL released, another Python thread's call that would change or
//     cycle the simulation is refused (RuntimeError) instead of racing it.
#pragma once

#include <memory>
#include <string>

#include "hilldem/core/error.hpp"
#include "hilldem/io/scenario.hpp"

namespace hilldem::python {

class PySimulation {
 public:
  explicit PySimulation(Scenario sc) : scenario_(std::make_unique<Scenario>(std::move(sc))) {}

  Scenario& scenario() { return *scenario_; }
  Simulation& sim() { return scenario_->sim; }
  const Simulation& sim() const { return scenario_->sim; }

  // RunError if an earlier step failed; `what` names the call refused.
  void check_usable(const char* what) const;
  // Run f (which may cycle); a RunError it throws marks the simulation failed and propagates.
  template <class F>
  auto stepping(const char* what, F&& f) {
    check_usable(what);
    try {
      return f();
    } catch (const RunError& e) {
      failure_ = e.what();
      throw;
    }
  }
  const std::string& failure() const { return failure_; }

  // RuntimeError while another thread cycles this simulation; `what` names the refused call.
  void check_idle(const char* what) const;
  bool busy = false;  // set by BusyScope, read and written with the GIL held

  // Live numpy views of ball columns (see ViewToken in bind_arrays.cpp).
  int live_views = 0;
  // BufferError (pybind11::buffer_error) while views are alive; `what` names the refused call.
  void check_no_views(const char* what) const;

 private:
  std::unique_ptr<Scenario> scenario_;
  std::string failure_;
};

// Marks the simulation busy for its lifetime (taken with the GIL held, before releasing it).
class BusyScope {
 public:
  explicit BusyScope(PySimulation& ps) : ps_(ps) { ps_.busy = true; }
  ~BusyScope() { ps_.busy = false; }
  BusyScope(const BusyScope&) = delete;
  BusyScope& operator=(const BusyScope&) = delete;

 private:
  PySimulation& ps_;
};

}  // namespace hilldem::python
