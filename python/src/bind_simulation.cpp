// hilldem.Simulation: building one (from TOML text or a file), cycling it with the GIL released
// (callbacks, progress, Ctrl-C between cycles), the scenario's stages, wetting, settings and
// checkpoints.
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>

#include "bindings.hpp"
#include "hilldem/bench/bed_bench.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/progress.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/io/toml_reader.hpp"
#include "py_simulation.hpp"

namespace py = pybind11;

namespace hilldem::python {

namespace {

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// C++ cycles without the GIL; Python runs between engine calls (the callback, progress) and, every
// kPollSeconds, inside one: the engine asks StopHook before each cycle, and the hook then takes the
// GIL and runs Python's signal handlers. An exception from one (Ctrl-C's KeyboardInterrupt) makes
// the coming cycle the call's last, and is raised once the engine has returned, the simulation at
// that cycle boundary. So a long cycle(n) is one engine call (each call rebuilds the cycle's
// records and writes the contact results at its end: about one cycle's work), and Ctrl-C is
// answered within about kPollSeconds. How a run is cut into calls changes no result (test
// test_cycling.py::test_chunking_changes_no_bit).
constexpr double kPollSeconds = 0.05;  // [s]

class StopHook {
 public:
  // progress_seconds > 0: also end the engine call every that many seconds [s], for a progress line.
  explicit StopHook(double progress_seconds = 0.0) : progress_(progress_seconds) {
    const double now = seconds_now();
    next_poll_ = now + kPollSeconds;
    next_progress_ = now + progress_;
  }
  // Called by the engine (without the GIL) before each cycle: true ends the call after it.
  bool operator()() {
    const double now = seconds_now();
    if (now < next_poll_) return false;
    next_poll_ = now + kPollSeconds;
    if (progress_ > 0.0 && now >= next_progress_) {
      next_progress_ = now + progress_;
      return true;
    }
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return false;
    error_.emplace();  // takes the pending Python exception
    return true;
  }
  // With the GIL: raise what a signal handler raised, if one did.
  void rethrow() {
    if (error_) {
      py::error_already_set e = std::move(*error_);
      error_.reset();
      throw e;
    }
  }

 private:
  double progress_, next_poll_, next_progress_;
  std::optional<py::error_already_set> error_;
};

void require_count(const char* what, const char* name, std::int64_t v, std::int64_t lo) {
  if (v < lo) throw InputError(fmt::format("{}: {} must be an integer >= {}; got {}", what, name, lo, v));
}

// step(k, hook, ran) runs at most k cycles (asking hook between them, or running k cycles at most
// and returning), sets `ran` and returns true when the run is over (solve converged). Returns the
// cycles run. every > 0: callback(sim) after every `every` cycles; a callback that returns False
// ends the run there. grow: the calls start at 1 cycle and double until one takes kPollSeconds
// (for a step that does not ask the hook).
template <class Step>
std::int64_t run_chunked(py::object self, PySimulation& ps, const char* what, std::int64_t total,
                         const py::object& callback, std::int64_t every, Progress* progress, double progress_seconds,
                         bool grow, Step&& step) {
  ps.check_usable(what);
  ps.check_idle(what);
  StopHook hook(progress ? progress_seconds : 0.0);
  std::int64_t done = 0, chunk = grow ? 1 : total;
  while (done < total) {
    std::int64_t k = std::min(total - done, chunk);
    if (every > 0) k = std::min(k, every - done % every);
    std::int64_t ran = 0;
    bool over = false;
    const double t0 = seconds_now();
    {
      BusyScope busy(ps);
      py::gil_scoped_release release;
      over = ps.stepping(what, [&] { return step(k, hook, ran); });
    }
    if (grow && seconds_now() - t0 < kPollSeconds && chunk < (std::int64_t{1} << 20)) chunk *= 2;
    done += ran;
    if (progress) progress->tick(ps.sim(), done);
    hook.rethrow();  // KeyboardInterrupt: the state is that after `done` cycles
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (every > 0 && !callback.is_none() && (done % every == 0 || over)) {
      const py::object r = callback(self);
      if (py::isinstance<py::bool_>(r) && !r.cast<bool>()) break;
    }
    if (over) break;
  }
  if (progress) progress->clear();
  return done;
}

// Progress on stderr (io/progress.hpp), a line every `seconds` [s] (0: none; in place on a terminal).
std::optional<Progress> make_progress(double seconds, const char* type, std::int64_t steps, double ratio, std::int64_t max_steps) {
  std::optional<Progress> p;
  if (!(seconds >= 0.0) || !std::isfinite(seconds))
    throw InputError(fmt::format("{}: progress must be the seconds between progress lines, >= 0 (0: none); got {}", type, seconds));
  if (seconds == 0.0) return p;
  p.emplace(std::cerr, ProgressMode::Auto, ::isatty(STDERR_FILENO) == 1, seconds);
  ProgressStage st;
  st.index = st.count = 1;
  st.type = type;
  st.name = "Simulation";
  st.total_steps = steps;
  st.target_ratio = ratio;
  st.max_steps = max_steps;
  p->begin_stage(st, 0);
  return p;
}

void check_every(const char* what, const py::object& callback, std::int64_t every) {
  require_count(what, "every", every, 0);
  if (!callback.is_none() && every == 0) throw InputError(std::string(what) + ": a callback needs every >= 1 [cycles]");
  if (!callback.is_none() && !PyCallable_Check(callback.ptr()))
    throw InputError(std::string(what) + ": callback must be callable as callback(sim)");
}

std::int64_t cycle(py::object self, std::int64_t n, const py::object& callback, std::int64_t every, double progress) {
  PySimulation& ps = self.cast<PySimulation&>();
  require_count("cycle", "n", n, 0);
  check_every("cycle", callback, every);
  auto prog = make_progress(progress, "cycle", n, 0.0, 0);
  return run_chunked(self, ps, "cycle", n, callback, every, prog ? &*prog : nullptr, progress, false,
                     [&](std::int64_t k, StopHook& hook, std::int64_t& ran) {
                       ran = ps.sim().cycle(k, std::ref(hook));
                       return false;
                     });
}

std::int64_t solve(py::object self, double ratio, std::int64_t max_steps, const py::object& callback, std::int64_t every,
                   double progress) {
  PySimulation& ps = self.cast<PySimulation&>();
  if (!(ratio > 0.0) || !std::isfinite(ratio))
    throw InputError(fmt::format("solve: ratio must be a finite number in (0, inf) [-]; got {}", ratio));
  require_count("solve", "max_steps", max_steps, 1);
  check_every("solve", callback, every);
  auto prog = make_progress(progress, "solve", -1, ratio, max_steps);
  bool converged = false;
  const std::int64_t done =
      run_chunked(self, ps, "solve", max_steps, callback, every, prog ? &*prog : nullptr, progress, true,
                  [&](std::int64_t k, StopHook&, std::int64_t& ran) {
        const std::int64_t used = ps.sim().solve(ratio, k);
        converged = used >= 0;
        ran = converged ? used : k;
        return converged;
      });
  if (!converged && done == max_steps)
    throw RunError(fmt::format("solve: no equilibrium within max_steps = {} (mean unbalanced-force ratio {:.4g} > {:.4g})",
                               max_steps, ps.sim().mean_unbalanced_ratio(), ratio));
  return done;
}

PySimulation from_text(const std::string& text, const std::string& name) { return PySimulation(load_scenario(text, name)); }

PySimulation from_file(const std::string& path) { return PySimulation(load_scenario_file(path)); }

PySimulation from_checkpoint(const std::string& path) {
  const CheckpointReader r = CheckpointReader::from_file(path);
  Scenario sc;
  read_simulation(r, sc.sim);
  return PySimulation(std::move(sc));
}

void save_checkpoint(PySimulation& ps, const std::filesystem::path& path) {
  CheckpointWriter w;
  write_simulation(w, ps.sim());
  w.write_file(path.string());
}

// The scenario's stages (run_scenario), with its histories and probes; files only into output_dir.
py::dict run_stages(PySimulation& ps, const std::optional<std::filesystem::path>& output_dir, bool quiet) {
  ps.check_usable("run_stages");
  ps.check_idle("run_stages");
  RunOptions opt;
  opt.quiet = quiet;
  opt.output_dir = output_dir ? output_dir->string() : "";
  opt.write_files = output_dir.has_value();
  opt.progress = quiet ? ProgressMode::Off : ProgressMode::Auto;
  StopHook hook;  // Ctrl-C: the run ends at a cycle boundary (no stage-end outputs)
  opt.stop_requested = std::ref(hook);
  std::ostringstream log;
  RunResult res;
  {
    BusyScope busy(ps);
    py::gil_scoped_release release;
    res = ps.stepping("run_stages", [&] { return run_scenario(ps.scenario(), opt, log); });
  }
  hook.rethrow();
  py::dict probes;
  for (const ProbeValue& p : res.probes) {
    py::dict d;
    d["value"] = p.value;
    d["unit"] = p.unit;
    d["quantity"] = p.quantity;
    d["target"] = p.target;
    probes[py::str(p.label)] = d;
  }
  py::dict out;
  out["probes"] = probes;
  out["log"] = log.str();
  out["history_path"] = res.history_path;
  out["last_checkpoint"] = res.last_checkpoint;
  return out;
}

// The bench bed of `hilldem bench` (bench/bed_bench.hpp): the LAMMPS data file, copied rep × rep in x, y.
PySimulation bench_bed(const std::filesystem::path& data, int replicate_xy) {
  if (replicate_xy < 1 || replicate_xy > 20)
    throw InputError(fmt::format("bench_bed: replicate must be in [1, 20]; got {}", replicate_xy));
  Packing packing = read_packing(data.string(), PackingFormat::Lammps);
  const int rep[3] = {replicate_xy, replicate_xy, 1};
  replicate(packing, rep);
  Scenario sc;
  sc.sim = make_bed(packing);
  return PySimulation(std::move(sc));
}

void set_gravity(PySimulation& ps, const std::array<double, 3>& g) {
  ps.check_idle("gravity");
  for (double v : g)
    if (!std::isfinite(v)) throw InputError(fmt::format("gravity: components must be finite [m/s^2]; got {}", v));
  ps.sim().settings.gravity = {g[0], g[1], g[2]};
}

void set_local_damping(PySimulation& ps, double a) {
  ps.check_idle("local_damping");
  const Range r = Range::closed_open(0.0, 1.0);
  if (!r.contains(a)) throw InputError(fmt::format("local_damping: must be in {} [-]; got {}", r.text(), a));
  ps.sim().settings.local_damping = a;
}

void set_timestep(PySimulation& ps, const std::optional<double>& dt) {
  ps.check_idle("timestep");
  SimulationSettings& s = ps.sim().settings;
  if (!dt) {
    if (s.density_scaling) throw InputError("timestep: density scaling needs a fixed timestep [s], not None (auto)");
    s.auto_timestep = true;
    return;
  }
  const Range r = Range::open(0.0, 1.0);
  if (!r.contains(*dt)) throw InputError(fmt::format("timestep: must be in {} [s] or None (auto); got {}", r.text(), *dt));
  s.auto_timestep = false;
  s.timestep = *dt;
}

}  // namespace

void bind_simulation(py::module_& m) {
  py::class_<PySimulation> cls(m, "Simulation", R"(A hilldem simulation: balls, walls, contacts, the assignment table and the
clock, with the scenario's stages when it came from a TOML file. Build one with
hilldem.load_scenario(path), hilldem.scenario_from_text(text), hilldem.ScenarioBuilder or
hilldem.load_checkpoint(path). Units are SI throughout (docs/python.md).)");
  cls.def_static("_from_text", &from_text, py::arg("text"), py::arg("name"),
                 "Build from TOML scenario text; `name` stands for the file in error messages.")
      .def_static("_from_file", &from_file, py::arg("path"), "Build from a TOML scenario file.")
      .def_static("_from_checkpoint", &from_checkpoint, py::arg("path"),
                  "The engine state saved in a checkpoint (by save_checkpoint or the CLI), ready to cycle on.")
      .def("cycle", &cycle, py::arg("n"), py::arg("callback") = py::none(), py::arg("every") = 0,
           py::arg("progress") = 0.0,
           R"(Run n cycles; returns the cycles run. callback(sim) runs after every `every` cycles
(returning False stops the run there); progress: seconds between progress lines on stderr (0: none;
True: every second). The GIL is released while C++ cycles, in one engine call unless a callback
or progress asks for more; Ctrl-C raises KeyboardInterrupt within about 0.05 s, the simulation left
at a cycle boundary (sim.steps says which).)")
      .def("solve", &solve, py::arg("ratio"), py::arg("max_steps"), py::arg("callback") = py::none(),
           py::arg("every") = 0, py::arg("progress") = 0.0,
           R"(Cycle (at least once) until the mean unbalanced-force ratio [-] is <= ratio; returns the
cycles used. RunError if max_steps pass first. callback, every, progress: as cycle().)")
      .def("update_forces", [](PySimulation& ps) {
             ps.check_idle("update_forces");
             ps.stepping("update_forces", [&] { ps.sim().update_forces(); });
           },
           "Detect contacts and compute forces at the current state without moving anything.")
      .def("make_wet", [](PySimulation& ps, double suction, double gap) {
             ps.check_usable("make_wet");
             ps.check_idle("make_wet");
             if (!(suction >= 0.0) || !std::isfinite(suction))
               throw InputError(fmt::format("make_wet: suction must be in [0, inf) [Pa]; got {}", suction));
             if (!(gap >= 0.0) || !std::isfinite(gap))
               throw InputError(fmt::format("make_wet: gap must be in [0, inf) [m]; got {}", gap));
             return ps.sim().make_wet(suction, gap);
           },
           py::arg("suction"), py::arg("gap"),
           R"(Wet the material (spec §2.7): contacts for every ball pair within gap [m], suction [Pa] on
their hill contacts, each made wet. Returns the number of wet contacts.)")
      .def("make_dry", [](PySimulation& ps) {
             ps.check_idle("make_dry");
             return ps.sim().make_dry();
           },
           "Dry every hill contact; returns how many were wet.")
      .def("run_stages", &run_stages, py::arg("output_dir") = py::none(), py::arg("quiet") = true,
           R"(Run the scenario's stages (as `hilldem run`). Ctrl-C raises KeyboardInterrupt with the simulation at the
cycle boundary where it stopped (no stage-end outputs are written; sim.steps says where). Returns {'probes': {label: {'value', 'unit',
'quantity', 'target'}}, 'log': text, 'history_path': str, 'last_checkpoint': str}. Files (history,
snapshots, checkpoints) are written only when output_dir is given.)")
      .def("save_checkpoint", [](PySimulation& ps, const std::filesystem::path& path) {
             ps.check_idle("save_checkpoint");
             save_checkpoint(ps, path);
           },
           py::arg("path"), "Write the engine state (sections sim.*) to a checkpoint file, atomically.")
      .def("state_digest", [](const PySimulation& ps) { return state_digest(ps.sim()); },
           "64-bit FNV-1a digest of the physical state (16 hex digits): equal digests, equal bits.")
      .def("state_difference", [](const PySimulation& a, const PySimulation& b) { return state_difference(a.sim(), b.sim()); },
           py::arg("other"), "Where this state first differs from other's, in words ('' when bitwise equal).")
      .def("contact_listing", [](const PySimulation& ps) { return contact_listing(ps.sim()); },
           "Every contact, its model and the rule that assigned it, as `hilldem contacts` prints.")
      .def_property_readonly("time", [](const PySimulation& ps) { return ps.sim().time; }, "Simulated time [s].")
      .def_property_readonly("steps", [](const PySimulation& ps) { return ps.sim().steps; }, "Cycles done [-].")
      .def_property_readonly("last_timestep", [](const PySimulation& ps) { return ps.sim().last_dt; },
                             "Δt of the last cycle [s].")
      .def_property_readonly("next_timestep", [](const PySimulation& ps) { return ps.sim().next_timestep(); },
                             "Δt the next cycle will use [s].")
      .def_property("timestep",
                    [](const PySimulation& ps) -> std::optional<double> {
                      const auto& s = ps.sim().settings;
                      return s.auto_timestep ? std::nullopt : std::optional<double>(s.timestep);
                    },
                    &set_timestep, "Fixed Δt [s], or None for the automatic one (spec §4).")
      .def_property("gravity",
                    [](const PySimulation& ps) {
                      const Vec3& g = ps.sim().settings.gravity;
                      return std::array<double, 3>{g.x, g.y, g.z};
                    },
                    &set_gravity, "Gravitational acceleration [m/s^2].")
      .def_property("local_damping", [](const PySimulation& ps) { return ps.sim().settings.local_damping; },
                    &set_local_damping, "Local damping α [-], in [0, 1).")
      .def_property_readonly("mean_unbalanced_ratio", [](const PySimulation& ps) { return ps.sim().mean_unbalanced_ratio(); },
                             "Mean unbalanced force over mean contact force [-].")
      .def_property_readonly("ball_count", [](const PySimulation& ps) { return ps.sim().balls.size(); }, "Balls [-].")
      .def_property_readonly("wall_count", [](const PySimulation& ps) { return ps.sim().walls.size(); }, "Walls [-].")
      .def_property_readonly("contact_count", [](const PySimulation& ps) { return ps.sim().contact_count(); },
                             "Contacts that exist [-].")
      .def_property_readonly("rebuilds", [](const PySimulation& ps) { return ps.sim().rebuilds(); },
                             "Neighbour-list rebuilds so far [-].")
      .def_property_readonly("title", [](PySimulation& ps) { return ps.scenario().title; }, "The scenario's title.")
      .def_property_readonly("stage_names", [](PySimulation& ps) {
             std::vector<std::string> names;
             for (const Stage& s : ps.scenario().stages) names.push_back(fmt::format("{} '{}'", to_string(s.type), s.name));
             return names;
           },
           "The scenario's stages, as 'type \\'name\\''.")
      .def_property_readonly("failure", [](const PySimulation& ps) { return ps.failure(); },
                             "The error that stopped a step ('' while none has).")
      .def_property_readonly("live_views", [](const PySimulation& ps) { return ps.live_views; },
                             "numpy views of the ball arrays alive now [-].");
  bind_arrays(cls, m);
  m.def("bench_bed", &bench_bed, py::arg("data"), py::arg("replicate") = 1,
        R"(The bed `hilldem bench` times, as a Simulation ready to cycle: the LAMMPS data file `data`
(bench/bed_settled.data) copied replicate × replicate times in x and y (3: 100,800 spheres).)");
}

}  // namespace hilldem::python
