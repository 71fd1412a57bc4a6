// numpy views of the ball columns (zero-copy, read-only), the setters that write them with the
// invalidations the engine needs, balls added, the walls, and the contacts as numpy arrays.
//
// Views are read-only: a write straight into a column would bypass what the engine must redo after
// it (forces after a move, masses and contact mappings after a radius change) and could put a NaN
// into the cycle. Writes go through set_*, which check shapes, indices and finiteness. A view keeps
// its simulation alive; while any is alive, adding balls is refused (PySimulation::check_no_views).
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>

#include "bindings.hpp"
#include "hilldem/io/scenario.hpp"
#include "py_simulation.hpp"

namespace py = pybind11;

namespace hilldem::python {

namespace {

// The base object of a view: keeps the simulation alive and counts the views alive.
struct ViewToken {
  py::object owner;
  PySimulation* ps;
  ViewToken(py::object o, PySimulation* p) : owner(std::move(o)), ps(p) { ++ps->live_views; }
  ~ViewToken() { --ps->live_views; }
  ViewToken(const ViewToken&) = delete;
  ViewToken& operator=(const ViewToken&) = delete;
};

// A read-only view of `column` (shape (n,) or (n, 3) for Vec3), based on a new ViewToken.
template <class T>
py::array column_view(py::object self, std::vector<T>& column) {
  PySimulation& ps = self.cast<PySimulation&>();
  py::object token = py::cast(new ViewToken(self, &ps), py::return_value_policy::take_ownership);
  const auto n = static_cast<py::ssize_t>(column.size());
  py::array out;
  if constexpr (std::is_same_v<T, Vec3>) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double));
    out = py::array(py::dtype::of<double>(), {n, py::ssize_t{3}}, {py::ssize_t{sizeof(Vec3)}, py::ssize_t{sizeof(double)}},
                    reinterpret_cast<double*>(column.data()), token);
  } else {
    out = py::array(py::dtype::of<T>(), {n}, {py::ssize_t{sizeof(T)}}, column.data(), token);
  }
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

// Ball indices [0, n) from an index array (None: every ball, in order).
std::vector<std::size_t> ball_indices(const char* what, const Simulation& sim, const py::object& indices) {
  const std::size_t n = sim.balls.size();
  std::vector<std::size_t> out;
  if (indices.is_none()) {
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = i;
    return out;
  }
  const auto idx = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(indices);
  if (!idx || idx.ndim() != 1)
    throw InputError(fmt::format("{}: indices must be a 1-d array of ball indices (integers in [0, {}))", what, n));
  out.reserve(static_cast<std::size_t>(idx.shape(0)));
  for (py::ssize_t k = 0; k < idx.shape(0); ++k) {
    const std::int64_t i = idx.at(k);
    if (i < 0 || static_cast<std::uint64_t>(i) >= n)
      throw InputError(fmt::format("{}: indices[{}] = {} is not a ball index; allowed: [0, {})", what, k, i, n));
    out.push_back(static_cast<std::size_t>(i));
  }
  return out;
}

// values as float64 of shape (k, 3) (vectors) or (k,) (scalars), every element finite and in range.
py::array_t<double> real_values(const char* what, const py::object& values, std::size_t k, bool vectors, double lo,
                                bool lo_open, const char* unit) {
  auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!v) throw InputError(fmt::format("{}: values must be an array of numbers", what));
  const bool shape_ok = vectors ? (v.ndim() == 2 && v.shape(1) == 3 && static_cast<std::size_t>(v.shape(0)) == k)
                                : (v.ndim() == 1 && static_cast<std::size_t>(v.shape(0)) == k);
  if (!shape_ok) {
    std::string shape;
    for (py::ssize_t d = 0; d < v.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(v.shape(d));
    throw InputError(fmt::format("{}: values must have shape ({}{}), one per index; got ({})", what, k, vectors ? ", 3" : ",", shape));
  }
  const double* p = v.data();
  for (py::ssize_t j = 0; j < v.size(); ++j) {
    const bool ok = std::isfinite(p[j]) && (lo_open ? p[j] > lo : p[j] >= lo);
    if (!ok)
      throw InputError(fmt::format("{}: values[{}] = {} is out of range; allowed: {}{}, inf) {}", what,
                                   vectors ? fmt::format("{}, {}", j / 3, j % 3) : std::to_string(j), p[j],
                                   lo_open ? "(" : "[", std::isinf(lo) ? "-inf" : fmt::format("{}", lo), unit));
  }
  return v;
}

constexpr double kAny = -HUGE_VAL;

// set_<column>(values, indices=None): Vec3 columns, then `after` (the invalidation the column needs).
template <class After>
void set_vectors(PySimulation& ps, const char* what, std::vector<Vec3> BallStore::*column, const py::object& values,
                 const py::object& indices, const char* unit, After after) {
  ps.check_idle(what);
  Simulation& sim = ps.sim();
  const auto idx = ball_indices(what, sim, indices);
  const auto v = real_values(what, values, idx.size(), true, kAny, true, unit);
  const double* p = v.data();
  for (std::size_t k = 0; k < idx.size(); ++k) (sim.balls.*column)[idx[k]] = {p[3 * k], p[3 * k + 1], p[3 * k + 2]};
  after(sim);
}

// Radii [m] or densities [kg/m^3]: > 0; masses, inertias and every contact's mapping follow.
void set_shape(PySimulation& ps, const char* what, std::vector<double> BallStore::*column, const py::object& values,
               const py::object& indices, const char* unit) {
  ps.check_idle(what);
  Simulation& sim = ps.sim();
  const auto idx = ball_indices(what, sim, indices);
  const auto v = real_values(what, values, idx.size(), false, 0.0, true, unit);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    (sim.balls.*column)[idx[k]] = v.at(static_cast<py::ssize_t>(k));
    sim.balls.update_mass(idx[k]);
  }
  sim.refresh_mappings();
  sim.invalidate_forces();
}

void set_fixity(PySimulation& ps, const char* what, const py::object& indices, int mask, bool fix) {
  ps.check_idle(what);
  if (mask < 0 || mask > kFixAll)
    throw InputError(fmt::format("{}: mask must be a fixity mask in [0, {}] (hilldem.FIX_X ... FIX_ALL); got {}", what, kFixAll, mask));
  Simulation& sim = ps.sim();
  for (std::size_t i : ball_indices(what, sim, indices))
    sim.balls.fixity[i] = static_cast<FixityMask>(fix ? (sim.balls.fixity[i] | mask) : (sim.balls.fixity[i] & ~mask));
}

// Balls described by TOML text ([[material]] and [[ball]]/[[ball_grid]]/[[packing]] tables, read by
// the scenario reader with all its checks), appended to the simulation.
std::size_t add_balls(PySimulation& ps, const std::string& text, const std::string& name) {
  ps.check_usable("add_balls");
  ps.check_idle("add_balls");
  ps.check_no_views("add_balls");
  const ScenarioDescription d = read_scenario(text, name);
  if (!d.sim.walls.empty() || !d.sim.rules.empty() || !d.stages.empty())
    throw InputError(name + ": add_balls takes materials and balls only (no walls, contact models or stages)");
  Simulation& sim = ps.sim();
  for (const BallInit& b : d.sim.balls)
    if (sim.balls.find(b.id) >= 0) throw InputError(fmt::format("{}: ball id {} is already in the simulation", name, b.id));
  const std::vector<std::string> names = group_names(d.sim.groups);
  for (BallInit b : d.sim.balls) {
    std::uint64_t groups = 0;
    for (std::size_t bit = 0; bit < names.size(); ++bit)
      if (b.groups & (std::uint64_t{1} << bit)) groups |= sim.groups.bit(names[bit]);
    b.groups = groups;
    sim.balls.add(b);
  }
  sim.invalidate_forces();
  return d.sim.balls.size();
}

const char* wall_shape_name(WallShape s) {
  switch (s) {
    case WallShape::Plane: return "plane";
    case WallShape::Facet: return "facet";
    case WallShape::Cylinder: return "cylinder";
  }
  return "?";
}

py::tuple vec(const Vec3& v) { return py::make_tuple(v.x, v.y, v.z); }

py::list walls(const PySimulation& ps) {
  py::list out;
  const Simulation& sim = ps.sim();
  for (const Wall& w : sim.walls.walls) {
    py::dict d;
    d["name"] = w.name;
    d["shape"] = wall_shape_name(w.shape);
    d["groups"] = sim.groups.describe(w.groups);
    d["point"] = vec(w.point);
    d["normal"] = vec(w.normal);
    d["vertices"] = py::make_tuple(vec(w.vertex[0]), vec(w.vertex[1]), vec(w.vertex[2]));
    d["axis"] = w.axis;
    d["radius"] = w.radius;
    d["extent"] = py::make_tuple(w.lo, w.hi);
    d["velocity"] = vec(w.velocity);
    d["spin"] = vec(w.spin);
    d["radial_velocity"] = w.radial_velocity;
    d["force"] = vec(w.force);
    d["moment"] = vec(w.moment);
    d["normal_force"] = w.normal_force;
    d["active_contacts"] = w.active_contacts;
    out.append(d);
  }
  return out;
}

std::size_t wall_index(const Simulation& sim, const py::object& wall) {
  if (py::isinstance<py::str>(wall)) {
    const std::string name = wall.cast<std::string>();
    const long k = sim.walls.find(name);
    if (k < 0) throw InputError("set_wall: no wall named '" + name + "'");
    return static_cast<std::size_t>(k);
  }
  const std::int64_t k = wall.cast<std::int64_t>();
  if (k < 0 || static_cast<std::uint64_t>(k) >= sim.walls.size())
    throw InputError(fmt::format("set_wall: wall index {} out of range; allowed: [0, {})", k, sim.walls.size()));
  return static_cast<std::size_t>(k);
}

Vec3 finite_vec(const char* what, const char* unit, const std::array<double, 3>& a) {
  for (double v : a)
    if (!std::isfinite(v)) throw InputError(fmt::format("set_wall: {} must be finite {}; got {}", what, unit, v));
  return {a[0], a[1], a[2]};
}

void set_wall(PySimulation& ps, const py::object& wall, const std::optional<std::array<double, 3>>& velocity,
              const std::optional<std::array<double, 3>>& spin, const std::optional<double>& radial_velocity) {
  ps.check_idle("set_wall");
  Wall& w = ps.sim().walls.walls[wall_index(ps.sim(), wall)];
  if (radial_velocity && (!std::isfinite(*radial_velocity) || w.shape != WallShape::Cylinder))
    throw InputError(fmt::format("set_wall: radial_velocity [m/s] must be finite, on a cylinder ('{}' is a {})", w.name,
                                 wall_shape_name(w.shape)));
  if (velocity) w.velocity = finite_vec("velocity", "[m/s]", *velocity);
  if (spin) w.spin = finite_vec("spin", "[rad/s]", *spin);
  if (radial_velocity) w.radial_velocity = *radial_velocity;
}

// Every contact that exists, as numpy arrays (copies: the contact rows move at every rebuild).
py::dict contacts(const PySimulation& ps) {
  const Simulation& sim = ps.sim();
  const ContactStore& c = sim.contacts;
  std::vector<std::size_t> rows;
  for (std::size_t k = 0; k < c.size(); ++k)
    if (c.exists[k]) rows.push_back(k);
  const auto n = static_cast<py::ssize_t>(rows.size());
  py::array_t<std::int64_t> ball1(n), piece2(n);
  py::array_t<std::uint8_t> kind(n), model(n), moisture(n);
  py::array_t<bool> active(n), wet(n);
  py::array_t<double> gap(n), overlap(n), normal_force(n), moisture_force(n);
  py::array_t<double> normal({n, py::ssize_t{3}}), force({n, py::ssize_t{3}}), shear({n, py::ssize_t{3}}),
      point({n, py::ssize_t{3}});
  const auto put = [](py::array_t<double>& a, py::ssize_t j, const Vec3& v) {
    auto m = a.mutable_unchecked<2>();
    m(j, 0) = v.x, m(j, 1) = v.y, m(j, 2) = v.z;
  };
  for (py::ssize_t j = 0; j < n; ++j) {
    const std::size_t k = rows[static_cast<std::size_t>(j)];
    const ContactKey& key = c.key[k];
    const bool bb = key.kind == ContactKind::BallBall;
    ball1.mutable_at(j) = sim.balls.id[key.a];
    piece2.mutable_at(j) = bb ? sim.balls.id[key.b] : static_cast<std::int64_t>(key.b);
    kind.mutable_at(j) = static_cast<std::uint8_t>(key.kind);
    model.mutable_at(j) = static_cast<std::uint8_t>(c.model[k]);
    moisture.mutable_at(j) = static_cast<std::uint8_t>(c.moisture[k]);
    wet.mutable_at(j) = c.model[k] == ModelKind::Hill && c.moisture[k] == Moisture::Wet;
    active.mutable_at(j) = c.active[k] != 0;
    gap.mutable_at(j) = c.gap[k];
    overlap.mutable_at(j) = std::max(0.0, -c.gap[k]);
    normal_force.mutable_at(j) = c.normal_force[k];
    moisture_force.mutable_at(j) = c.moisture_force[k];
    put(normal, j, c.normal[k]);
    put(force, j, c.force[k]);
    put(shear, j, c.shear_force(k));
    put(point, j, sim.geometry(k).point);
  }
  py::dict d;
  d["ball1"] = ball1;
  d["piece2"] = piece2;
  d["kind"] = kind;
  d["model"] = model;
  d["moisture"] = moisture;
  d["wet"] = wet;
  d["active"] = active;
  d["gap"] = gap;
  d["overlap"] = overlap;
  d["normal_force"] = normal_force;
  d["moisture_force"] = moisture_force;
  d["normal"] = normal;
  d["force"] = force;
  d["shear_force"] = shear;
  d["point"] = point;
  return d;
}

}  // namespace

void bind_arrays(py::class_<PySimulation>& cls, py::module_& m) {
  py::class_<ViewToken>(m, "_ViewToken", "Keeps a simulation alive behind a numpy view of its balls.");
  m.attr("FIX_X") = 1, m.attr("FIX_Y") = 2, m.attr("FIX_Z") = 4;
  m.attr("FIX_SPIN_X") = 8, m.attr("FIX_SPIN_Y") = 16, m.attr("FIX_SPIN_Z") = 32;
  m.attr("FIX_VELOCITY") = int{kFixVel}, m.attr("FIX_SPIN") = int{kFixSpin}, m.attr("FIX_ALL") = int{kFixAll};

#define HILLDEM_VIEW(name, column, doc)                                                                        \
  cls.def_property_readonly(name, [](py::object self) { return column_view(self, self.cast<PySimulation&>().sim().balls.column); }, \
                            doc " (read-only numpy view, no copy)")
  HILLDEM_VIEW("positions", position, "Ball centres [m], shape (n, 3)");
  HILLDEM_VIEW("velocities", velocity, "Ball velocities [m/s], shape (n, 3)");
  HILLDEM_VIEW("spins", spin, "Ball angular velocities [rad/s], shape (n, 3)");
  HILLDEM_VIEW("forces", contact_force, "Sum of the contact forces on each ball [N], shape (n, 3)");
  HILLDEM_VIEW("moments", contact_moment, "Sum of the contact moments on each ball [N m], shape (n, 3)");
  HILLDEM_VIEW("applied_forces", applied_force, "User-applied force on each ball [N], shape (n, 3)");
  HILLDEM_VIEW("applied_moments", applied_moment, "User-applied moment on each ball [N m], shape (n, 3)");
  HILLDEM_VIEW("radii", radius, "Ball radii [m], shape (n,)");
  HILLDEM_VIEW("densities", density, "Ball densities [kg/m^3], shape (n,)");
  HILLDEM_VIEW("masses", mass, "Ball masses [kg], shape (n,)");
  HILLDEM_VIEW("ids", id, "User ids (int64), shape (n,)");
  HILLDEM_VIEW("groups", groups, "Group bit masks (uint64; bit k: group_names[k]), shape (n,)");
  HILLDEM_VIEW("fixity", fixity, "Fixity masks (uint8; hilldem.FIX_*), shape (n,)");
#undef HILLDEM_VIEW

  const auto nothing = [](Simulation&) {};
  cls.def("set_positions", [](PySimulation& ps, const py::object& v, const py::object& i) {
            set_vectors(ps, "set_positions", &BallStore::position, v, i, "[m]", [](Simulation& s) { s.invalidate_forces(); });
          },
          py::arg("values"), py::arg("indices") = py::none(),
          "Move balls to values [m] (shape (k, 3)); forces and contacts are recomputed before the next cycle.")
      .def("set_velocities", [nothing](PySimulation& ps, const py::object& v, const py::object& i) {
             set_vectors(ps, "set_velocities", &BallStore::velocity, v, i, "[m/s]", nothing);
           },
           py::arg("values"), py::arg("indices") = py::none(), "Set ball velocities [m/s] (shape (k, 3)).")
      .def("set_spins", [nothing](PySimulation& ps, const py::object& v, const py::object& i) {
             set_vectors(ps, "set_spins", &BallStore::spin, v, i, "[rad/s]", nothing);
           },
           py::arg("values"), py::arg("indices") = py::none(), "Set ball angular velocities [rad/s] (shape (k, 3)).")
      .def("set_applied_forces", [nothing](PySimulation& ps, const py::object& v, const py::object& i) {
             set_vectors(ps, "set_applied_forces", &BallStore::applied_force, v, i, "[N]", nothing);
           },
           py::arg("values"), py::arg("indices") = py::none(), "Set constant applied forces [N] (shape (k, 3)).")
      .def("set_applied_moments", [nothing](PySimulation& ps, const py::object& v, const py::object& i) {
             set_vectors(ps, "set_applied_moments", &BallStore::applied_moment, v, i, "[N m]", nothing);
           },
           py::arg("values"), py::arg("indices") = py::none(), "Set constant applied moments [N m] (shape (k, 3)).")
      .def("set_radii", [](PySimulation& ps, const py::object& v, const py::object& i) {
             set_shape(ps, "set_radii", &BallStore::radius, v, i, "[m]");
           },
           py::arg("values"), py::arg("indices") = py::none(),
           "Set radii [m] (> 0); masses, inertias and contact mappings follow, forces are recomputed.")
      .def("set_densities", [](PySimulation& ps, const py::object& v, const py::object& i) {
             set_shape(ps, "set_densities", &BallStore::density, v, i, "[kg/m^3]");
           },
           py::arg("values"), py::arg("indices") = py::none(),
           "Set densities [kg/m^3] (> 0); masses, inertias and contact mappings follow.")
      .def("fix", [](PySimulation& ps, const py::object& i, int mask) { set_fixity(ps, "fix", i, mask, true); },
           py::arg("indices"), py::arg("mask") = int{kFixAll},
           "Fix velocity components (hilldem.FIX_* mask) of balls: they keep their velocity and ignore forces.")
      .def("free", [](PySimulation& ps, const py::object& i, int mask) { set_fixity(ps, "free", i, mask, false); },
           py::arg("indices"), py::arg("mask") = int{kFixAll}, "Free velocity components (hilldem.FIX_* mask) of balls.")
      .def("index_of", [](const PySimulation& ps, std::int64_t id) {
             const long i = ps.sim().balls.find(id);
             if (i < 0) throw InputError(fmt::format("index_of: no ball with id {}", id));
             return i;
           },
           py::arg("id"), "Index of the ball with user id `id` (InputError if none).")
      .def_property_readonly("group_names", [](const PySimulation& ps) { return group_names(ps.sim().groups); },
                             "Group names, in bit order (groups masks).")
      .def("_add_balls", &add_balls, py::arg("text"), py::arg("name"),
           "Append the balls of TOML text ([[material]], [[ball]], ...); BufferError while views are alive.")
      .def("walls", &walls, "Every wall as a dict (copies): geometry [m], imposed motion [m/s, rad/s], force sums [N, N m].")
      .def("set_wall", &set_wall, py::arg("wall"), py::arg("velocity") = py::none(), py::arg("spin") = py::none(),
           py::arg("radial_velocity") = py::none(),
           "Impose a wall's motion (wall: name or index): velocity [m/s], spin [rad/s], radial_velocity [m/s] (cylinders).")
      .def("contacts", &contacts,
           R"(Every contact that exists, as a dict of numpy arrays (copies), one row per contact: ball1 (id),
piece2 (ball id, or wall index when kind == 1), kind (0 ball-ball, 1 ball-wall), model (0 linear,
1 hill, 2 rrlinear), moisture (0 dry, 1 ruptured, 2 wet), wet, active, gap [m], overlap [m],
normal_force [N] (compression > 0), moisture_force [N] (<= 0), normal (n, 3), force on piece 2
(n, 3) [N], shear_force (n, 3) [N], point (n, 3) [m].)");
}

}  // namespace hilldem::python
