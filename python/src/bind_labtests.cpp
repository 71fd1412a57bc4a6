// The memo's checks (hilldem verify) and the lab tests of src/hilldem/labtests/ (grading, genesis,
// triaxial test, study) for Python, in the submodule hilldem.lab: the settings structs as classes
// with one attribute per C++ field (defaults and units those of the headers), the drivers as
// functions, and their results as dicts and numpy arrays. A field added to a settings struct is one
// .def_readwrite line here; one added to a result struct, one PUT line.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>

#include "bindings.hpp"
#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"
#include "hilldem/labtests/t307.hpp"
#include "hilldem/verify/verify.hpp"
#include "py_simulation.hpp"

namespace py = pybind11;

namespace hilldem::python {

namespace {

// hilldem verify's rows: {id: {'quantity', 'unit', 'memo', 'computed', 'tolerance', 'relative', 'pass',
// 'scenario', 'produced'}}.
py::dict verify() {
  std::ostringstream log;
  VerifyReport report;
  {
    py::gil_scoped_release release;
    report = run_verify(log, true);
  }
  py::dict out;
  for (const VerifyRow& r : report.rows) {
    py::dict d;
    d["quantity"] = r.ref.quantity;
    d["unit"] = r.ref.unit;
    d["memo"] = r.ref.memo_value;
    d["computed"] = r.computed;
    d["tolerance"] = r.ref.tolerance;
    d["relative"] = r.ref.relative;
    d["pass"] = r.pass;
    d["produced"] = r.produced;
    d["scenario"] = r.scenario;
    out[py::str(r.ref.id)] = d;
  }
  return out;
}

// d["field"] = object.field: result structs to dicts, one line per field (units: the struct's header).
#define PUT(d, obj, field) d[#field] = (obj).field

// A numpy column of a row vector: out[k] = rows[k].*member.
template <class Row, class T>
py::array_t<T> column(const std::vector<Row>& rows, T Row::*member) {
  py::array_t<T> a(static_cast<py::ssize_t>(rows.size()));
  auto m = a.template mutable_unchecked<1>();
  for (std::size_t k = 0; k < rows.size(); ++k) m(static_cast<py::ssize_t>(k)) = rows[k].*member;
  return a;
}

const char* margin_name(SpecimenState::Margin m) {
  switch (m) {
    case SpecimenState::Margin::DMax: return "d_max";
    case SpecimenState::Margin::D50: return "d50";
    case SpecimenState::Margin::None: return "none";
  }
  return "?";
}

py::dict state_dict(const SpecimenState& s) {
  py::dict d;
  PUT(d, s, grains);
  PUT(d, s, porosity);
  PUT(d, s, interior_porosity);
  d["interior_margin"] = margin_name(s.interior_margin);
  PUT(d, s, interior_margin_length);
  PUT(d, s, coordination);
  PUT(d, s, mech_coordination);
  PUT(d, s, radial_stress);
  PUT(d, s, bottom_stress);
  PUT(d, s, top_stress);
  PUT(d, s, radius);
  PUT(d, s, height);
  PUT(d, s, ratio);
  PUT(d, s, wet_contacts);
  PUT(d, s, timestep);
  return d;
}

py::dict phase_dict(const PhaseReport& p) {
  py::dict d;
  PUT(d, p, name);
  PUT(d, p, steps);
  PUT(d, p, seconds);
  PUT(d, p, porosity_change);
  d["state"] = state_dict(p.state);
  d["line"] = p.line();
  return d;
}

py::list phase_list(const std::vector<PhaseReport>& phases) {
  py::list out;
  for (const PhaseReport& p : phases) out.append(phase_dict(p));
  return out;
}

py::dict grading_report_dict(const GradingReport& g) {
  py::dict d;
  PUT(d, g, name);
  PUT(d, g, count);
  PUT(d, g, outside);
  PUT(d, g, d50_target);
  PUT(d, g, d50_realised);
  PUT(d, g, worst_bin_error);
  py::dict bins;
  std::vector<GradingBin> b;
  for (const BinReport& r : g.bins) b.push_back(r.bin);
  bins["d_lower"] = column(b, &GradingBin::d_lower);
  bins["d_upper"] = column(b, &GradingBin::d_upper);
  bins["target_fraction"] = column(b, &GradingBin::fraction);
  bins["realised_fraction"] = column(g.bins, &BinReport::realised_fraction);
  bins["count"] = column(g.bins, &BinReport::count);
  d["bins"] = bins;
  py::dict curve;
  curve["size"] = column(g.curve, &PassingPoint::size);
  curve["target"] = column(g.curve, &PassingPoint::target);
  curve["realised"] = column(g.curve, &PassingPoint::realised);
  d["curve"] = curve;
  d["csv"] = g.csv();
  d["text"] = g.text();
  return d;
}

py::dict line_fit_dict(const LineFit& f) {
  py::dict d;
  PUT(d, f, slope);
  PUT(d, f, intercept);
  PUT(d, f, slope_se);
  PUT(d, f, ols_se);
  PUT(d, f, points);
  PUT(d, f, blocks);
  PUT(d, f, valid);
  return d;
}

py::dict loop_dict(const LoopResult& l) {
  py::dict d;
  d["unload"] = line_fit_dict(l.unload);  // M_r: the fit's slope [Pa] and its standard error
  d["reload"] = line_fit_dict(l.reload);
  PUT(d, l, cycle);
  PUT(d, l, target_strain);
  PUT(d, l, eps_a);
  PUT(d, l, q_a);
  PUT(d, l, eps_b);
  PUT(d, l, q_b);
  PUT(d, l, q_c);
  PUT(d, l, closed);
  PUT(d, l, unload_secant);
  PUT(d, l, reload_secant);
  PUT(d, l, loop_area);
  PUT(d, l, damping_ratio);
  return d;
}

py::dict triaxial_dict(const TriaxialResult& t) {
  py::dict h;
  h["step"] = column(t.history, &TriaxialRow::step);
  h["time"] = column(t.history, &TriaxialRow::time);
  py::list phase;
  for (const TriaxialRow& r : t.history) phase.append(to_string(r.phase));
  h["phase"] = py::module_::import("numpy").attr("array")(phase);
  h["cycle"] = column(t.history, &TriaxialRow::cycle);
  h["eps_a"] = column(t.history, &TriaxialRow::eps_a);
  h["eps_r"] = column(t.history, &TriaxialRow::eps_r);
  h["eps_v"] = column(t.history, &TriaxialRow::eps_v);
  h["sigma_a"] = column(t.history, &TriaxialRow::sigma_a);
  h["sigma_r"] = column(t.history, &TriaxialRow::sigma_r);
  h["q"] = column(t.history, &TriaxialRow::q);
  h["sigma_top"] = column(t.history, &TriaxialRow::sigma_top);
  h["sigma_bottom"] = column(t.history, &TriaxialRow::sigma_bottom);
  h["porosity"] = column(t.history, &TriaxialRow::porosity);
  h["coordination"] = column(t.history, &TriaxialRow::coordination);
  h["platen_mismatch"] = column(t.history, &TriaxialRow::platen_mismatch);
  py::dict d;
  d["history"] = h;
  py::list loops;
  for (const LoopResult& l : t.loops) loops.append(loop_dict(l));
  d["loops"] = loops;
  PUT(d, t, height0);
  PUT(d, t, radius0);
  PUT(d, t, peak_q);
  PUT(d, t, peak_strain);
  PUT(d, t, peak_radial_strain);
  PUT(d, t, peak_volumetric_strain);
  PUT(d, t, worst_confinement_error);
  PUT(d, t, worst_confinement_strain);
  PUT(d, t, worst_platen_mismatch);
  PUT(d, t, worst_mismatch_strain);
  PUT(d, t, steps);
  PUT(d, t, seconds);
  d["history_csv"] = t.history_csv();
  d["loops_text"] = t.loops_text();
  return d;
}

// A numpy column of T 307 rows or cycles through an accessor: out[k] = get(rows[k]).
template <class Row, class F>
py::array_t<double> column_of(const std::vector<Row>& rows, F get) {
  py::array_t<double> a(static_cast<py::ssize_t>(rows.size()));
  auto m = a.template mutable_unchecked<1>();
  for (std::size_t k = 0; k < rows.size(); ++k) m(static_cast<py::ssize_t>(k)) = static_cast<double>(get(rows[k]));
  return a;
}

py::dict t307_dict(const T307Result& r) {
  py::dict rows;  // one entry per sequence run, the conditioning (sequence 0) first if it ran
  const auto& q = r.rows;
  rows["sequence"] = column_of(q, [](const T307Row& x) { return x.nominal.number; });
  rows["sigma3"] = column_of(q, [](const T307Row& x) { return x.nominal.confining; });
  rows["sigma_max"] = column_of(q, [](const T307Row& x) { return x.nominal.max_stress; });
  rows["sigma_cyclic"] = column_of(q, [](const T307Row& x) { return x.nominal.cyclic; });
  rows["sigma_contact"] = column_of(q, [](const T307Row& x) { return x.nominal.contact; });
  rows["cycles"] = column_of(q, [](const T307Row& x) { return x.cycles; });
  rows["averaged"] = column_of(q, [](const T307Row& x) { return x.averaged; });
  rows["cyclic_stress"] = column_of(q, [](const T307Row& x) { return x.cyclic_stress; });
  rows["max_deviator"] = column_of(q, [](const T307Row& x) { return x.max_deviator; });
  rows["confining"] = column_of(q, [](const T307Row& x) { return x.confining; });
  rows["bulk_stress"] = column_of(q, [](const T307Row& x) { return x.bulk_stress; });
  rows["octahedral_shear"] = column_of(q, [](const T307Row& x) { return x.octahedral_shear; });
  rows["recoverable_axial"] = column_of(q, [](const T307Row& x) { return x.recoverable_axial; });
  rows["modulus"] = column_of(q, [](const T307Row& x) { return x.modulus; });
  rows["poisson"] = column_of(q, [](const T307Row& x) { return x.poisson; });
  rows["permanent_strain"] = column_of(q, [](const T307Row& x) { return x.permanent_strain; });
  rows["total_permanent_strain"] = column_of(q, [](const T307Row& x) { return x.total_permanent_strain; });
  rows["amplitude_error"] = column_of(q, [](const T307Row& x) { return x.amplitude_error; });
  rows["steps"] = column_of(q, [](const T307Row& x) { return x.steps; });
  py::dict cycles;
  const auto& c = r.cycles;
  cycles["sequence"] = column_of(c, [](const T307Cycle& x) { return x.sequence; });
  cycles["cycle"] = column_of(c, [](const T307Cycle& x) { return x.cycle; });
  cycles["q_peak"] = column_of(c, [](const T307Cycle& x) { return x.q_peak; });
  cycles["q_end"] = column_of(c, [](const T307Cycle& x) { return x.q_end; });
  cycles["sigma_r_peak"] = column_of(c, [](const T307Cycle& x) { return x.sigma_r_peak; });
  cycles["recoverable_axial"] = column_of(c, [](const T307Cycle& x) { return x.recoverable_axial; });
  cycles["recoverable_radial"] = column_of(c, [](const T307Cycle& x) { return x.recoverable_radial; });
  cycles["eps_a_end"] = column_of(c, [](const T307Cycle& x) { return x.eps_a_end; });
  cycles["modulus"] = column_of(c, [](const T307Cycle& x) { return x.modulus; });
  cycles["command"] = column_of(c, [](const T307Cycle& x) { return x.command; });
  cycles["amplitude_error"] = column_of(c, [](const T307Cycle& x) { return x.amplitude_error; });
  py::dict d;
  d["rows"] = rows;
  d["cycles"] = cycles;
  PUT(d, r, fitted);
  if (r.fitted) {
    py::dict f;
    PUT(f, r.fit, k1);
    PUT(f, r.fit, k2);
    PUT(f, r.fit, k3);
    PUT(f, r.fit, se_k1);
    PUT(f, r.fit, se_k2);
    PUT(f, r.fit, se_k3);
    PUT(f, r.fit, r_squared);
    PUT(f, r.fit, rms_error);
    PUT(f, r.fit, points);
    PUT(f, r.fit, iterations);
    PUT(f, r.fit, converged);
    d["fit"] = f;
  } else {
    d["fit"] = py::none();
  }
  PUT(d, r, fit_error);
  PUT(d, r, stopped);
  PUT(d, r, stop_reason);
  PUT(d, r, height0);
  PUT(d, r, radius0);
  PUT(d, r, timestep);
  PUT(d, r, steps);
  PUT(d, r, seconds);
  d["sequences_csv"] = r.sequences_csv();
  d["cycles_csv"] = r.cycles_csv();
  d["text"] = r.text();
  return d;
}

py::dict case_dict(const CaseResult& c) {
  py::dict d;
  d["name"] = c.spec.name();
  PUT(d, c, spec);
  d["grading"] = grading_report_dict(c.grading);
  PUT(d, c, packed_with);
  PUT(d, c, confinement);
  d["packed"] = state_dict(c.packed);
  d["initial"] = state_dict(c.initial);
  d["phases"] = phase_list(c.phases);
  d["test"] = triaxial_dict(c.test);
  PUT(d, c, seconds);
  PUT(d, c, packing_seconds);
  PUT(d, c, dir);
  PUT(d, c, packing_file);
  return d;
}

py::dict study_dict(const StudyResult& s) {
  py::dict d;
  py::list cases;
  for (const CaseResult& c : s.cases) cases.append(case_dict(c));
  d["cases"] = cases;
  PUT(d, s, seconds);
  PUT(d, s, cpu_seconds);
  PUT(d, s, criterion);
  d["summary_csv"] = s.summary_csv();
  d["summary_markdown"] = s.summary_markdown();
  d["findings"] = s.findings();
  return d;
}
#undef PUT

// A driver's log: the console (as the CLI prints it) or nothing.
std::ostream* log_stream(bool log) { return log ? &std::cout : nullptr; }

// Ctrl-C in a lab call. The drivers' Simulations ask the hook before every cycle
// (Simulation::interrupt), from the calling thread or from a study's job threads; every 0.05 s one
// of them takes the GIL and runs Python's signal handlers. Once a handler raised, every driver stops
// at its next cycle (Interrupted) and the call raises what the handler raised (KeyboardInterrupt).
class LabStopHook {
 public:
  bool operator()() {
    if (stop_.load()) return true;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);  // (one thread polls; the others go on)
    if (!lock) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now < next_poll_) return false;
    next_poll_ = now + std::chrono::milliseconds(50);
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return false;
    error_.emplace();  // takes the pending Python exception
    stop_ = true;
    return true;
  }
  // With the GIL, after an Interrupted: raise what the signal handler raised.
  [[noreturn]] void rethrow() {
    if (error_) {
      py::error_already_set e = std::move(*error_);
      error_.reset();
      throw e;
    }
    throw;  // (an Interrupted that this hook did not ask for)
  }

 private:
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point next_poll_ = std::chrono::steady_clock::now();
  std::optional<py::error_already_set> error_;
};

// Runs f(stop) with the GIL released (the drivers run for seconds to hours; Python threads go on),
// stop being the hook for Simulation::interrupt and GenesisSpec::interrupt: Ctrl-C raises
// KeyboardInterrupt with the specimen at a cycle boundary.
template <class F>
auto released(F&& f) {
  LabStopHook hook;
  try {
    py::gil_scoped_release release;
    return f(std::function<bool()>(std::ref(hook)));
  } catch (const Interrupted&) {
    hook.rethrow();
  }
}

// A specimen's Simulation asks `stop` while a driver runs on it, and nothing after.
class SpecimenStop {
 public:
  SpecimenStop(Specimen& s, std::function<bool()> stop) : s_(s), before_(std::move(s.sim.interrupt)) {
    s_.sim.interrupt = std::move(stop);
  }
  ~SpecimenStop() { s_.sim.interrupt = std::move(before_); }
  SpecimenStop(const SpecimenStop&) = delete;
  SpecimenStop& operator=(const SpecimenStop&) = delete;

 private:
  Specimen& s_;
  std::function<bool()> before_;
};

// released() for a driver on specimen s: f() runs with s answering Ctrl-C.
template <class F>
auto released_on(Specimen& s, F&& f) {
  return released([&](std::function<bool()> stop) {
    const SpecimenStop scope(s, std::move(stop));
    return f();
  });
}

py::array_t<double> diameters(const Specimen& s) {
  const std::vector<double> d = s.diameters();
  return py::array_t<double>(static_cast<py::ssize_t>(d.size()), d.data());
}

// The specimen's simulation, copied into a hilldem.Simulation (numpy views, contacts(), checkpoints).
PySimulation specimen_simulation(const Specimen& s) {
  Scenario sc;
  sc.sim = s.sim;
  return PySimulation(std::move(sc));
}

}  // namespace

void bind_labtests(py::module_& m) {
  m.def("verify", &verify,
        R"(Run the memo's test problems (as `hilldem verify`). Returns {id: {'quantity', 'unit', 'memo',
'computed', 'tolerance', 'relative', 'pass', 'produced', 'scenario'}}, values in the row's unit.)");

  py::module_ lab = m.def_submodule("lab", R"(The lab tests (docs/lab-tests.md): gradings, material genesis, the
servo-controlled triaxial test and the Class 5 study, as `hilldem triaxial` runs them. Settings are
classes with one attribute per setting (SI units: [m], [Pa], [1/s]; strains as fractions [-], not %);
results are dicts of numbers, strings and numpy arrays (docs/python.md lists them with units).)");

  py::enum_<SizeMeasure>(lab, "SizeMeasure", "What a clump's size [m] is (docs/clumps.md).")
      .value("EqualVolumeDiameter", SizeMeasure::EqualVolumeDiameter, "the diameter of the sphere of equal volume (the default)")
      .value("EnclosingDiameter", SizeMeasure::EnclosingDiameter,
             "the diameter of the smallest sphere about the centre of mass that holds every pebble");
  py::enum_<GrainModel>(lab, "GrainModel", "Grain-grain contact model of a Class 5 material.")
      .value("Linear", GrainModel::Linear)
      .value("Hill", GrainModel::Hill);

  py::class_<GradingBin>(lab, "GradingBin", "One bin of a grading: diameters [m] and solid-volume fraction [-].")
      .def(py::init([](double lo, double hi, double f) { return GradingBin{lo, hi, f}; }), py::arg("d_lower"),
           py::arg("d_upper"), py::arg("fraction"))
      .def_readwrite("d_lower", &GradingBin::d_lower, "Lower diameter [m].")
      .def_readwrite("d_upper", &GradingBin::d_upper, "Upper diameter [m].")
      .def_readwrite("fraction", &GradingBin::fraction, "Solid-volume (mass) fraction [-]; the bins sum to 1.")
      .def("__repr__", [](const GradingBin& b) {
             return fmt::format("GradingBin({:g} mm - {:g} mm, {:g})", 1e3 * b.d_lower, 1e3 * b.d_upper, b.fraction);
           },
           "The bin, diameters in mm.");
  py::class_<Grading>(lab, "Grading", "A grain-size distribution: a name and non-overlapping bins (lab-tests.md §1).")
      .def(py::init([](std::string name, std::vector<GradingBin> bins) {
             Grading g{std::move(name), std::move(bins)};
             validate_grading(g);
             return g;
           }),
           py::arg("name"), py::arg("bins"), "A grading from bins; InputError unless they are a valid grading.")
      .def_readwrite("name", &Grading::name, "C5n, C5b or the file name.")
      .def_readwrite("bins", &Grading::bins, "The bins (a list of GradingBin; assign a new list to change them).")
      .def("__repr__", [](const Grading& g) { return fmt::format("Grading('{}', {} bins)", g.name, g.bins.size()); },
           "Its name and bin count.");
  lab.def("grading", &resolve_grading, py::arg("name_or_file"),
          R"(A grading: "C5n" or "C5b" (the memo's Table 7), or a CSV file of d_lower_mm,d_upper_mm,fraction
rows. InputError naming the file, line and value on bad input.)");
  lab.def("expected_grain_count", &expected_grain_count, py::arg("grading"), py::arg("d_mult"), py::arg("solid_volume"),
          "Expected number of grains [-] for a solid volume [m^3] with diameters scaled by d_mult [-].");
  lab.def("sample_grains",
          [](const Grading& g, double solid_volume, std::uint64_t seed, double d_mult) {
            validate_grading(g);
            if (!(solid_volume > 0.0) || !std::isfinite(solid_volume))
              throw InputError(fmt::format("sample_grains: solid_volume must be in (0, inf) [m^3]; got {}", solid_volume));
            if (!(d_mult > 0.0) || !std::isfinite(d_mult))
              throw InputError(fmt::format("sample_grains: d_mult must be in (0, inf) [-]; got {}", d_mult));
            Rng rng(seed);
            const GrainSample s = sample_grains(g, d_mult, solid_volume, rng);
            py::dict d;
            d["diameters"] = py::array_t<double>(static_cast<py::ssize_t>(s.diameters.size()), s.diameters.data());
            d["bin"] = py::array_t<int>(static_cast<py::ssize_t>(s.bin.size()), s.bin.data());
            return d;
          },
          py::arg("grading"), py::arg("solid_volume"), py::arg("seed") = PackingSettings{}.seed, py::arg("d_mult") = 1.0,
          R"(Grains drawn from the grading for a solid volume [m^3] with the seeded generator genesis uses:
{'diameters': [m], 'bin': bin index of each grain}.)");
  lab.def("grading_report",
          [](const Grading& g, const py::array_t<double, py::array::c_style | py::array::forcecast>& d, double d_mult) {
            return grading_report_dict(grading_report(g, d_mult, std::vector<double>(d.data(), d.data() + d.size())));
          },
          py::arg("grading"), py::arg("diameters"), py::arg("d_mult") = 1.0,
          R"(The realised distribution of diameters [m] against the grading (memo Fig. 18): {'name', 'count',
'outside', 'd50_target', 'd50_realised' [m], 'worst_bin_error' [-], 'bins': {'d_lower', 'd_upper' [m],
'target_fraction', 'realised_fraction' [-], 'count'}, 'curve': {'size' [m], 'target', 'realised'
(fractions passing [-])}, 'csv', 'text'}.)");

  py::class_<Class5Material>(lab, "Class5Material", "Grain-grain properties of a Class 5 material (memo Table 7).")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("model", &Class5Material::model, "GrainModel.Hill or GrainModel.Linear.")
      .def_readwrite("density", &Class5Material::density, "Grain density [kg/m^3].")
      .def_readwrite("young_mod", &Class5Material::young_mod, "Grain Young's modulus [Pa] (hill).")
      .def_readwrite("pois_ratio", &Class5Material::pois_ratio, "Grain Poisson's ratio [-] (hill).")
      .def_readwrite("damp_con", &Class5Material::damp_con, "Damping constant gamma_h [-] (hill).")
      .def_readwrite("suction", &Class5Material::suction, "Suction [Pa] of the hill contacts (wet contacts only).")
      .def_readwrite("linear_emod", &Class5Material::linear_emod, "Effective modulus E* [Pa] (linear).")
      .def_readwrite("linear_kratio", &Class5Material::linear_kratio, "Stiffness ratio kappa* [-] (linear).")
      .def_readwrite("fric", &Class5Material::fric, "Friction coefficient mu [-].");
  py::class_<WallContact>(lab, "WallContact", "Grain-wall contacts: linear (lab-tests.md §2).")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("emod", &WallContact::emod, "Effective modulus E* [Pa].")
      .def_readwrite("kratio", &WallContact::kratio, "Stiffness ratio kappa* [-].")
      .def_readwrite("fric", &WallContact::fric, "Friction coefficient [-].");
  py::class_<PackingContact>(lab, "PackingContact", "Grain-grain contacts during packing (lab-tests.md §3.2).")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("model", &PackingContact::model, "GrainModel of the packing contacts.")
      .def_readwrite("emod", &PackingContact::emod, "E* [Pa] (linear).")
      .def_readwrite("kratio", &PackingContact::kratio, "kappa* [-] (linear).")
      .def_readwrite("damp_con", &PackingContact::damp_con, "gamma_h [-] (hill).")
      .def_readwrite("fric", &PackingContact::fric, "Packing friction mu_CA [-].");
  py::class_<EquilibriumSettings>(lab, "EquilibriumSettings", "Servo-controlled equilibrium of the three vessel walls.")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("pressure", &EquilibriumSettings::pressure, "Target wall pressure [Pa].")
      .def_readwrite("pressure_tolerance", &EquilibriumSettings::pressure_tolerance, "Every wall within this x pressure [-].")
      .def_readwrite("ratio", &EquilibriumSettings::ratio, "Mean unbalanced-force ratio to reach [-].")
      .def_readwrite("servo_gain", &EquilibriumSettings::servo_gain, "Servo gain alpha_s [-].")
      .def_readwrite("wall_speed_limit", &EquilibriumSettings::wall_speed_limit, "Wall speed cap [m/s].")
      .def_readwrite("check_every", &EquilibriumSettings::check_every, "Cycles between convergence checks [-].")
      .def_readwrite("porosity_change", &EquilibriumSettings::porosity_change,
                     "Converged when the vessel porosity changes by at most this per 1,000 steps [-].")
      .def_readwrite("porosity_window", &EquilibriumSettings::porosity_window, "Steps that change is taken over [-].")
      .def_readwrite("max_steps", &EquilibriumSettings::max_steps, "RunError after this many cycles [-].");
  py::class_<PackingSettings>(lab, "PackingSettings", "The grain cloud and its frictionless packing (lab-tests.md §3).")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("seed", &PackingSettings::seed, "Random seed N_RS of the cloud [-].")
      .def_readwrite("cloud_porosity", &PackingSettings::cloud_porosity, "Cloud porosity n_c [-].")
      .def_readwrite("local_damping", &PackingSettings::local_damping, "Local damping alpha [-].")
      .def_readwrite("placement_tries", &PackingSettings::placement_tries, "Random positions tried per grain [-].")
      .def_readwrite("cloud_speed_limit", &PackingSettings::cloud_speed_limit, "Grain speed cap in the relaxation [m/s].")
      .def_readwrite("cloud_overlap", &PackingSettings::cloud_overlap, "Relaxation ends at overlaps <= this x smallest diameter [-].")
      .def_readwrite("cloud_max_steps", &PackingSettings::cloud_max_steps, "Cycles allowed for the relaxation [-].")
      .def_readwrite("equilibrium", &PackingSettings::equilibrium, "EquilibriumSettings of packing (P_m).")
      .def_readwrite("contact", &PackingSettings::contact, "PackingContact.")
      .def_readwrite("walls", &PackingSettings::walls, "WallContact during packing.");
  py::class_<GenesisSpec>(lab, "GenesisSpec", "What pack_specimen makes: grading, vessel, grains, packing.")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("grading", &GenesisSpec::grading, "Grading (default C5b).")
      .def_readwrite("d_mult", &GenesisSpec::d_mult, "Diameter multiplier D_mult [-].")
      .def_readwrite("vessel_radius", &GenesisSpec::vessel_radius, "Vessel radius [m] (default the memo's 0.085; StudySettings' default 0.0425).")
      .def_readwrite("vessel_height", &GenesisSpec::vessel_height, "Vessel height [m] (default the memo's 0.240; StudySettings' default 0.120).")
      .def_readwrite("grain", &GenesisSpec::grain, "Class5Material whose density, E and nu the grains take.")
      .def_readwrite("packing", &GenesisSpec::packing, "PackingSettings.")
      .def_property(
          "clump_mix", [](const GenesisSpec& g) { return g.clump_mix; },
          [](GenesisSpec& g, const py::object& v) {
            // A list of (name, fraction) pairs or a dict {name: fraction}; checked as --clump-template is.
            ClumpMix mix;
            if (py::isinstance<py::dict>(v)) {
              for (const auto& [k, f] : v.cast<py::dict>()) mix.emplace_back(k.cast<std::string>(), f.cast<double>());
            } else {
              mix = v.cast<ClumpMix>();
            }
            check_clump_mix(mix, "GenesisSpec.clump_mix");
            g.clump_mix = std::move(mix);
          },
          "Grains as clumps of named templates (sphere, elongated2, elongated3, ellipsoid, cube, prism, slab, rock; "
          "docs/clumps.md) at solid volume fractions [-]: a list of (name, fraction) tuples or a dict, the fractions in "
          "(0, 1] summing to 1; each grain's template drawn from the seed, the grain scaled to its drawn size and turned "
          "at random; [] (the default): balls. InputError naming the bad name or fraction.")
      .def_property(
          "clump_template", [](const GenesisSpec& g) { return clump_mix_text(g.clump_mix); },
          [](GenesisSpec& g, const std::string& text) {
            ClumpMix mix = parse_clump_mix(text, "GenesisSpec.clump_template");
            check_clump_mix(mix, "GenesisSpec.clump_template");
            g.clump_mix = std::move(mix);
          },
          "clump_mix as the CLI's --clump-template text: 'elongated2' (one template) or 'elongated2:0.6,sphere:0.4'; "
          "'' (the default): balls.")
      .def_readwrite("clump_size", &GenesisSpec::clump_size, "SizeMeasure: what a clump's drawn size [m] is.");
  py::class_<TriaxialSettings>(lab, "TriaxialSettings", "The servo-controlled triaxial test (lab-tests.md §4).")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("confinement", &TriaxialSettings::confinement, "Confining pressure sigma_c [Pa].")
      .def_readwrite("cycle_strains", &TriaxialSettings::cycle_strains,
                     "Axial strains [-] (fractions, not %) at which each unloading starts, increasing.")
      .def_readwrite("unload_fraction", &TriaxialSettings::unload_fraction, "Unload until q <= this x q at the reversal [-].")
      .def_readwrite("final_strain", &TriaxialSettings::final_strain, "Final axial strain [-].")
      .def_readwrite("strain_rate", &TriaxialSettings::strain_rate, "Axial strain rate during the cycles [1/s].")
      .def_readwrite("final_strain_rate", &TriaxialSettings::final_strain_rate, "Axial strain rate after them [1/s].")
      .def_readwrite("servo_gain", &TriaxialSettings::servo_gain, "Radial servo gain [-].")
      .def_readwrite("wall_speed_limit", &TriaxialSettings::wall_speed_limit, "Radial servo speed cap [m/s].")
      .def_readwrite("cycle_record_strain", &TriaxialSettings::cycle_record_strain,
                     "History row every this much axial strain in the cycles [-] (0: 1/100 of the first cycle strain).")
      .def_readwrite("final_records", &TriaxialSettings::final_records, "History rows of the final loading [-].")
      .def_readwrite("density_scaling", &TriaxialSettings::density_scaling, "Density scaling factor F [-]: 0 (off) or [1, 50].")
      .def_readwrite("max_steps", &TriaxialSettings::max_steps, "RunError after this many cycles [-].");
  py::class_<T307Sequence>(lab, "T307Sequence", "One row of the T 307 table (sequence 0: the conditioning).")
      .def(py::init<>(), "Zeros.")
      .def_readwrite("number", &T307Sequence::number, "0: conditioning, 1..15 [-].")
      .def_readwrite("confining", &T307Sequence::confining, "sigma_3 [Pa].")
      .def_readwrite("max_stress", &T307Sequence::max_stress, "sigma_max, the peak deviator [Pa].")
      .def_readwrite("cyclic", &T307Sequence::cyclic, "sigma_cyclic, the haversine amplitude [Pa].")
      .def_readwrite("contact", &T307Sequence::contact, "sigma_contact, the deviator between pulses [Pa].")
      .def_readwrite("standard_cycles", &T307Sequence::standard_cycles, "Load repetitions in the standard [-].")
      .def_property_readonly("bulk_stress", &T307Sequence::bulk_stress, "theta = 3 sigma_3 + sigma_max [Pa].")
      .def_property_readonly("octahedral_shear", &T307Sequence::octahedral_shear, "tau_oct = (sqrt 2/3) sigma_max [Pa].");
  lab.def("t307_base_sequences", &t307_base_sequences, "The standard's table for base materials: sequences 0..15.");
  py::class_<T307Timing>(lab, "T307Timing", "The time-scaled variant of T 307 (docs/t307.md).")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("pulse_duration", &T307Timing::pulse_duration, "Haversine pulse [s].")
      .def_readwrite("rest_duration", &T307Timing::rest_duration, "Rest after each pulse [s].")
      .def_readwrite("settle_duration", &T307Timing::settle_duration, "Hold before a sequence's first pulse [s].")
      .def_readwrite("cycles", &T307Timing::cycles, "Pulses per sequence [-].")
      .def_readwrite("conditioning_cycles", &T307Timing::conditioning_cycles, "Pulses of the conditioning [-].")
      .def_readwrite("averaged_cycles", &T307Timing::averaged_cycles, "M_r and nu over the last this many [-].")
      .def_readwrite("servo_gain", &T307Timing::servo_gain, "alpha_s of the servos [-].")
      .def_readwrite("wall_speed_limit", &T307Timing::wall_speed_limit, "Servo speed cap [m/s].");
  py::class_<T307Settings>(lab, "T307Settings", "Settings of t307(): timing, sequences, limits.")
      .def(py::init<>(), "The header's defaults (the standard's 16 rows).")
      .def_readwrite("timing", &T307Settings::timing, "T307Timing.")
      .def_readwrite("sequences", &T307Settings::sequences, "[T307Sequence], run in this order.")
      .def_readwrite("max_permanent_strain", &T307Settings::max_permanent_strain,
                     "Stop after the cycle that passes this total permanent axial strain [-].")
      .def_readwrite("max_steps", &T307Settings::max_steps, "RunError after this many cycles [-].");
  py::class_<CaseSpec>(lab, "CaseSpec", "One case of the study: grading x material, dry or wet.")
      .def(py::init([](std::string grading, GrainModel model, bool wet) { return CaseSpec{std::move(grading), model, wet}; }),
           py::arg("grading") = "C5b", py::arg("model") = GrainModel::Hill, py::arg("wet") = false,
           "A case: grading name or file, GrainModel, wet.")
      .def_readwrite("grading", &CaseSpec::grading, "C5n, C5b or a grading CSV file.")
      .def_readwrite("model", &CaseSpec::model, "GrainModel.")
      .def_readwrite("wet", &CaseSpec::wet, "make_wet at the end of genesis (hill only).")
      .def_readwrite("confinement", &CaseSpec::confinement, "Confinement of its test [Pa]; 0: the study's.")
      .def_property_readonly("name", &CaseSpec::name, "The case's name, e.g. C5b_Hill_wet.")
      .def("__repr__", [](const CaseSpec& c) { return "CaseSpec('" + c.name() + "')"; }, "Its name.");
  py::class_<StudySettings>(lab, "StudySettings", R"(Settings of study(): genesis, material, finalization, wetting, the
triaxial test, output. Defaults are the CLI's default study: the memo's vessel scaled by 0.5
(genesis.vessel_radius = 0.0425, vessel_height = 0.120), each grading's scaled up to hold min_grains =
500 grains; the memo's full 170 mm x 240 mm vessel is vessel_radius = 0.085, vessel_height = 0.240,
min_grains = 0 (the CLI's --full).)")
      .def(py::init<>(), "The header's defaults.")
      .def_readwrite("genesis", &StudySettings::genesis, "GenesisSpec (its grading is replaced by each case's).")
      .def_readwrite("material", &StudySettings::material, "Class5Material (its model is replaced by each case's).")
      .def_readwrite("test_walls", &StudySettings::test_walls, "WallContact after finalization.")
      .def_readwrite("finalize", &StudySettings::finalize, "EquilibriumSettings after finalization and wetting (P_m).")
      .def_readwrite("suction", &StudySettings::suction, "Suction of make_wet [Pa].")
      .def_readwrite("moisture_gap", &StudySettings::moisture_gap, "Moisture gap g_m of make_wet [m].")
      .def_readwrite("triaxial", &StudySettings::triaxial, "TriaxialSettings.")
      .def_readwrite("pack_linear", &StudySettings::pack_linear, "Pack every material with linear contacts [bool].")
      .def_readwrite("min_grains", &StudySettings::min_grains,
                     "Scale each grading's vessel up (never down) until it holds this many grains; 0: off [-].")
      .def_readwrite("output_dir", &StudySettings::output_dir, "Folder the study writes into.")
      .def_readwrite("specimen_file", &StudySettings::specimen_file, "Start from this packed specimen ('' : pack).")
      .def_readwrite("save_specimens", &StudySettings::save_specimens, "Write the packed specimens [bool].")
      .def_readwrite("jobs", &StudySettings::jobs, "Cases run at once (0: the number of cores).");

  py::class_<Specimen>(lab, "Specimen", R"(A specimen in its vessel (genesis.hpp): the grains, the three walls and the
genesis history. The drivers (finalize, make_wet, triaxial) change it in place: copy() first to keep it.)")
      .def("copy", [](const Specimen& s) { return Specimen(s); }, "An independent copy.")
      .def_readonly("grading", &Specimen::grading, "Grading name.")
      .def_readonly("d_mult", &Specimen::d_mult, "D_mult [-].")
      .def_readonly("seed", &Specimen::seed, "Seed of the cloud [-].")
      .def_readonly("pressure", &Specimen::pressure, "Pressure P_m it was packed to [Pa].")
      .def_readonly("material", &Specimen::material, "What the assignment table holds: 'packed', 'C5b_Hill', ...")
      .def_readonly("packed_with", &Specimen::packed_with, "GrainModel of the packing contacts.")
      .def_readonly("wet", &Specimen::wet, "Whether make_wet has run [bool].")
      .def_readonly("clump_mix", &Specimen::clump_mix, "Its clumps' templates and target solid fractions [(name, fraction)]; [] for balls.")
      .def_property_readonly(
          "clump_templates",
          [](const Specimen& s) {
            std::vector<std::string> names;
            for (std::uint32_t k : s.clump_kind) names.push_back(s.clump_mix[k].first);
            return names;
          },
          "Each clump's template name, in clump order.")
      .def_property_readonly("clump_mix_fractions", [](const Specimen& s) { return clump_mix_fractions(s); },
                             "Each template's realised share of the clumps' union volume [-], in clump_mix's order.")
      .def_property_readonly("grains", [](const Specimen& s) { return s.sim.balls.size(); }, "Grains [-].")
      .def_property_readonly("phases", [](const Specimen& s) { return phase_list(s.phases); },
                             "Genesis phases: [{'name', 'steps', 'seconds' [s], 'state', 'line'}].")
      .def("diameters", &diameters, "Grain diameters [m] (numpy array, a copy).")
      .def("state", [](const Specimen& s) { return state_dict(measure(s)); },
           R"(The specimen now: {'grains', 'porosity', 'interior_porosity' [-], 'interior_margin' ('d_max', 'd50',
'none'), 'interior_margin_length' [m], 'coordination', 'mech_coordination' [-], 'radial_stress',
'bottom_stress', 'top_stress' [Pa], 'radius', 'height' [m], 'ratio' [-], 'wet_contacts', 'timestep' [s]}.)")
      .def("simulation", &specimen_simulation,
           "A hilldem.Simulation holding a copy of the specimen's state (views, contacts(), save_checkpoint).")
      .def("save", [](const Specimen& s, const std::filesystem::path& path, const PackingSettings& p) {
             save_packed_specimen(s, p, path.string());
           },
           py::arg("path"), py::arg("packing") = PackingSettings{},
           R"(Write a packed (not finalized) specimen for load_specimen or `hilldem triaxial --specimen`; packing:
the PackingSettings it was packed with (its contact and wall settings are recorded in the file).)");

  lab.def("pack_specimen", [](const GenesisSpec& spec, bool log) {
            validate(spec);
            return released([&](std::function<bool()> stop) {
              GenesisSpec g = spec;
              g.interrupt = std::move(stop);
              Specimen s = pack_specimen(g, log_stream(log));
              s.sim.interrupt = {};
              return s;
            });
          },
          py::arg("spec"), py::arg("log") = false,
          R"(Genesis up to the packed, frictionless specimen (cloud, relaxation, servo packing to P_m): a
Specimen. log: print the phases as the CLI does. RunError when a phase does not converge.)");
  lab.def("load_specimen", [](const std::filesystem::path& path) {
            PackingSettings p;
            Specimen s = load_packed_specimen(path.string(), &p);
            return py::make_tuple(std::move(s), p);
          },
          py::arg("path"), "A saved packed specimen: (Specimen, the PackingSettings stored with it).");
  lab.def("finalize", [](Specimen& s, const Class5Material& m, const WallContact& w, const EquilibriumSettings& e, bool log) {
            return phase_dict(released_on(s, [&] { return finalize(s, m, w, e, log_stream(log)); }));
          },
          py::arg("specimen"), py::arg("material"), py::arg("walls") = WallContact{}, py::arg("equilibrium") = EquilibriumSettings{},
          py::arg("log") = false,
          "Install the material (friction restored) and bring the specimen to equilibrium at equilibrium.pressure [Pa]; the phase dict.");
  lab.def("make_wet", [](Specimen& s, double suction, double gap, const EquilibriumSettings& e, bool log) {
            return phase_dict(released_on(s, [&] { return make_specimen_wet(s, suction, gap, e, log_stream(log)); }));
          },
          py::arg("specimen"), py::arg("suction"), py::arg("gap"), py::arg("equilibrium") = EquilibriumSettings{},
          py::arg("log") = false,
          "make_wet(suction [Pa], gap [m]) on a finalized hill specimen, then servo equilibrium; the phase dict.");
  lab.def("servo_equilibrium", [](Specimen& s, const EquilibriumSettings& e, const std::string& name, bool log) {
            return phase_dict(released_on(s, [&] { return servo_equilibrium(s, e, name, log_stream(log)); }));
          },
          py::arg("specimen"), py::arg("equilibrium"), py::arg("name") = "equilibrium", py::arg("log") = false,
          "Every wall to equilibrium.pressure [Pa] and static equilibrium; the phase dict.");
  lab.def("triaxial", [](Specimen& s, const TriaxialSettings& t, bool log) {
            validate(t);
            return triaxial_dict(released_on(s, [&] { return run_triaxial(s, t, log_stream(log)); }));
          },
          py::arg("specimen"), py::arg("settings"), py::arg("log") = false,
          R"(The triaxial test on a finalized specimen. Returns {'history': {column: numpy array}, 'loops':
[{...}], 'peak_q' [Pa], 'peak_strain' [-], 'height0', 'radius0' [m], 'worst_confinement_error',
'worst_platen_mismatch' [-] (and the strains where they happened), 'steps', 'seconds' [s],
'history_csv', 'loops_text'}. History columns: step, time [s], phase, cycle, eps_a, eps_r, eps_v [-],
sigma_a, sigma_r, q, sigma_top, sigma_bottom [Pa], porosity, coordination, platen_mismatch [-].
Loops: cycle, target_strain, eps_a, eps_b [-], q_a, q_b, q_c [Pa], closed, unload and reload (the
least-squares fits: slope = M_r on the unload [Pa], slope_se its standard error), unload_secant,
reload_secant (two-point secants) [Pa], loop_area [J/m^3], damping_ratio [-].)");
  lab.def("memo_cases", &memo_cases, "The memo's five cases: C5n/C5b x linear/hill, plus C5b hill wet.");
  lab.def("t307", [](Specimen& s, const T307Settings& t, bool log) {
            validate(t);
            return t307_dict(released_on(s, [&] { return run_t307(s, t, log_stream(log)); }));
          },
          py::arg("specimen"), py::arg("settings") = T307Settings{}, py::arg("log") = false,
          R"(AASHTO T 307 (time-scaled, docs/t307.md) on a finalized specimen. Returns {'rows': {column: numpy
array, one entry per sequence run, the conditioning (sequence 0) first}, 'cycles': {column: numpy
array, one entry per pulse}, 'fitted', 'fit' ({'k1', 'k2', 'k3' [-], 'se_k1', 'se_k2', 'se_k3' [-],
'r_squared' [-], 'rms_error' [Pa], 'points', 'iterations', 'converged'} or None), 'fit_error',
'stopped', 'stop_reason', 'height0', 'radius0' [m], 'timestep' [s], 'steps', 'seconds' [s],
'sequences_csv', 'cycles_csv', 'text'}. Row columns: sequence, sigma3, sigma_max, sigma_cyclic,
sigma_contact (nominal, Pa), cycles, averaged, cyclic_stress, max_deviator, confining, bulk_stress,
octahedral_shear [Pa], recoverable_axial [-], modulus (M_r) [Pa], poisson, permanent_strain,
total_permanent_strain, amplitude_error [-], steps. Cycle columns: sequence, cycle, q_peak, q_end,
sigma_r_peak [Pa], recoverable_axial, recoverable_radial, eps_a_end [-], modulus, command [Pa],
amplitude_error [-].)");
  lab.def("study", [](const StudySettings& s, const std::vector<CaseSpec>& cases, bool log) {
            return study_dict(released([&](std::function<bool()> stop) {
              StudySettings st = s;
              st.genesis.interrupt = std::move(stop);
              return run_study(st, cases, log_stream(log));
            }));
          },
          py::arg("settings"), py::arg("cases"), py::arg("log") = false,
          R"(The study as `hilldem triaxial` runs it: per case genesis (or settings.specimen_file), finalization,
wetting, confinement and the triaxial test, writing the CLI's files into settings.output_dir.
Returns {'cases': [{'name', 'spec', 'grading' (grading_report), 'packed', 'initial' (states),
'phases', 'test' (as triaxial()), 'seconds' [s], 'dir', ...}], 'seconds', 'cpu_seconds' [s],
'summary_csv', 'summary_markdown', 'findings'}.)");
}

}  // namespace hilldem::python
