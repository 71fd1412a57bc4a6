#include "hilldem/io/scenario.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <fstream>
#include <numbers>
#include <map>
#include <set>
#include <sstream>

#include "hilldem/core/error.hpp"
#include "hilldem/io/output_folder.hpp"
#include "hilldem/io/packing_import.hpp"
#include "hilldem/io/scenario_clumps.hpp"
#include "hilldem/io/state_io.hpp"

#include <filesystem>

namespace hilldem {

const char* to_string(StageType t) {
  switch (t) {
    case StageType::Cycle: return "cycle";
    case StageType::Solve: return "solve";
    case StageType::Translate: return "translate";
    case StageType::Rotate: return "rotate";
    case StageType::Set: return "set";
    case StageType::SetContacts: return "set_contacts";
    case StageType::SetSimulation: return "set_simulation";
    case StageType::MakeWet: return "make_wet";
    case StageType::MakeDry: return "make_dry";
    case StageType::Probe: return "probe";
    case StageType::ListContacts: return "list_contacts";
    case StageType::SetServo: return "set_servo";
  }
  return "?";
}

namespace {

constexpr double kInf = HUGE_VAL;
constexpr double kMaxBalls = 5e7;  // a guard against typos that would exhaust memory
const Range kPoisson = Range::open_closed(-1.0, 0.5);    // spec §2.2
const Range kDampCon = Range::closed_open(0.0, 1.0);      // spec §2.2
const Range kLocalDamping = Range::closed_open(0.0, 1.0);
// Magnitudes beyond which a run is meaningless in double precision or physically absurd
// (docs/scenario-format.md, "Ranges"): a coordinate of 1e6 m keeps ~1e-10 m resolution; radii from
// a nanometre to a kilometre; densities from 1e-3 (lighter than any gas at 1 atm would be) to
// 1e6 kg/m^3 (50 x osmium); gravity up to 1e4 m/s^2 (1000 g, a centrifuge) per component.
constexpr double kMaxCoordinate = 1e6;  // [m]
const Range kCoordinate = Range::closed(-kMaxCoordinate, kMaxCoordinate);
const Range kBallRadius = Range::closed(1e-9, 1e3);  // [m]
const Range kDensity = Range::closed(1e-3, 1e6);     // [kg/m^3]
const Range kGravity = Range::closed(-1e4, 1e4);     // [m/s^2] each component
bool within(const Range& r, const Vec3& v) { return r.contains(v.x) && r.contains(v.y) && r.contains(v.z); }

struct Material {
  double density, young_mod, pois_ratio;
};

FixityMask read_fixity(TableReader& t, const std::string& key) {
  FixityMask m = 0;
  for (const std::string& s : t.strings(key)) {
    if (s == "x") m |= 1;
    else if (s == "y") m |= 2;
    else if (s == "z") m |= 4;
    else if (s == "spin_x") m |= 8;
    else if (s == "spin_y") m |= 16;
    else if (s == "spin_z") m |= 32;
    else if (s == "velocity") m |= kFixVel;
    else if (s == "spin") m |= kFixSpin;
    else if (s == "all") m |= kFixAll;
    else
      t.fail(key, "unknown component \"" + s +
                      "\"; allowed: \"x\", \"y\", \"z\", \"spin_x\", \"spin_y\", \"spin_z\", \"velocity\", \"spin\", \"all\"");
  }
  return m;
}

std::uint64_t read_groups(TableReader& t, GroupNames& names) {
  std::uint64_t mask = 0;
  for (const std::string& g : t.strings("groups")) {
    if (g.empty()) t.fail("groups", "group names must not be empty");
    try {
      mask |= names.bit(g);
    } catch (const InputError& e) {
      t.fail("groups", e.what());
    }
  }
  return mask;
}

// servo.* quantities (evaluated by the runner): field and unit.
constexpr const char* kServoFields[][2] = {{"stress", "Pa"}, {"target_stress", "Pa"}, {"speed", "m/s"}, {"enabled", "-"}};

class Reader {
 public:
  Reader(const toml::table& root, std::string file, const ScenarioLimits& limits)
      : root_(root, file, ""), file_(std::move(file)), limits_(limits) {}

  ScenarioDescription read() {
    ScenarioDescription sc;
    sc.file = file_;
    sc.title = root_.string("title", "");
    read_simulation(sc);
    read_output(sc);
    read_snapshots(sc);
    read_checkpoints(sc);
    for (TableReader& t : root_.tables("material")) read_material(t);
    for (TableReader& t : root_.tables("ball")) read_ball(t, sc.sim);
    for (TableReader& t : root_.tables("ball_grid")) read_ball_grid(t, sc.sim);
    for (TableReader& t : root_.tables("packing")) read_packing_table(t, sc.sim);
    for (TableReader& t : root_.tables("clump_template")) read_clump_template(t, sc.sim);
    for (TableReader& t : root_.tables("clump")) read_clump(t, sc.sim);
    if (sc.sim.settings.density_scaling && !sc.sim.clumps.empty())
      throw InputError(file_ + ": key 'simulation.density_scaling': does not apply to clumps (docs/clumps.md); set it false");
    finish_box(sc.sim);
    for (TableReader& t : root_.tables("wall")) read_wall(t, sc.sim);
    for (TableReader& t : root_.tables("servo")) read_servo(t, sc);
    for (TableReader& t : root_.tables("contact_model")) read_rule(t, sc.sim);
    for (TableReader& t : root_.tables("history")) read_history(t, sc);
    for (TableReader& t : root_.tables("stage")) read_stage(t, sc);
    root_.finish();
    if (sc.sim.balls.size() == 0 && sc.sim.clumps.empty())
      throw InputError(file_ + ": the scenario has no balls ([[ball]], [[ball_grid]], [[packing]] or [[clump]])");
    check_hill_moduli(sc.sim);
    return sc;
  }

 private:
  void read_simulation(ScenarioDescription& sc) {
    SimulationSettings& s = sc.sim.settings;
    auto t = root_.table("simulation");
    if (!t) return;
    s.gravity = t->vec3("gravity", Vec3{}, kGravity, "[m/s^2]");
    s.local_damping = t->real("local_damping", 0.0, kLocalDamping, "[-]");
    if (t->has("timestep") && t->is_string("timestep")) {
      t->choice("timestep", std::nullopt, {"auto"});
      s.auto_timestep = true;
    } else if (t->has("timestep")) {
      s.auto_timestep = false;
      s.timestep = t->real("timestep", std::nullopt, Range::open(0.0, 1.0), "[s] (or \"auto\")");
    }
    s.timestep_safety = t->real("timestep_safety", 0.8, Range::open_closed(0.0, 1.0), "[-]");
    s.timestep_max = t->real("timestep_max", 1e-4, Range::open(0.0, 1.0), "[s]");
    s.proximity = t->real("proximity", 0.0, Range::closed(0.0, kInf), "[m]");
    s.skin = t->real("skin", 0.0, Range::closed(0.0, kInf), "[m] (0: 0.1 x mean diameter)");
    sc.blowup_fraction = t->real("blowup_fraction", 0.5, Range::closed(0.0, kInf), "[-] (fraction of a ball's radius per step; 0: off)");
    s.density_scaling = t->boolean("density_scaling", false);
    if (s.density_scaling && s.auto_timestep)
      t->fail("density_scaling", "needs a fixed timestep [s] (the masses are scaled to it), not \"auto\"");
    for (const std::string& d : t->strings("periodic")) {
      if (d != "x" && d != "y" && d != "z") t->fail("periodic", "directions must be \"x\", \"y\" or \"z\"; got \"" + d + "\"");
      s.box.periodic[d[0] - 'x'] = true;
    }
    if (t->has("box_min") || t->has("box_max")) {
      s.box.lo = t->vec3("box_min", std::nullopt, kCoordinate, "[m]");
      s.box.hi = t->vec3("box_max", std::nullopt, kCoordinate, "[m]");
      for (int d = 0; d < 3; ++d)
        if (s.box.periodic[d] && !(s.box.lo[d] < s.box.hi[d])) t->fail("box_max", "must exceed box_min in every periodic direction");
      box_given_ = true;
    }
    t->finish();
  }

  void read_output(ScenarioDescription& sc) {
    auto t = root_.table("output");
    if (!t) return;
    sc.output_dir = t->string("dir", "");
    sc.history_every = t->integer("history_every", 1, 1, INT64_MAX);
    sc.history_file = t->string("history_file", "history.csv");
    if (sc.history_file.empty() || sc.history_file.find('/') != std::string::npos || sc.history_file == "." ||
        sc.history_file == ".." || sc.history_file == kLockFileName)
      t->fail("history_file", "must be a plain file name (not empty, \".\", \"..\" or \"" + std::string(kLockFileName) +
                                  "\"; no '/'); got \"" + sc.history_file + "\"");
    t->finish();
  }

  void read_snapshots(ScenarioDescription& sc) {
    auto t = root_.table("snapshots");
    if (!t) return;
    SnapshotSettings& s = sc.snapshots;
    s.enabled = t->boolean("enabled", true);
    s.every = t->integer("every", 0, 0, INT64_MAX);
    s.at_stage_ends = t->boolean("at_stage_ends", true);
    s.contacts = t->boolean("contacts", true);
    s.walls = t->boolean("walls", true);
    s.binary = t->choice("format", "binary", {"binary", "ascii"}) == "binary";
    s.folder = t->string("folder", "snapshots");
    if (s.folder.empty() || s.folder.find('/') != std::string::npos || s.folder == "." || s.folder == "..")
      t->fail("folder", "must be a plain folder name (no '/')");
    t->finish();
  }

  void read_checkpoints(ScenarioDescription& sc) {
    auto t = root_.table("checkpoints");
    if (!t) return;
    CheckpointSettings& c = sc.checkpoints;
    c.enabled = t->boolean("enabled", true);
    c.every = t->integer("every", 0, 0, INT64_MAX);
    c.every_seconds = t->real("every_seconds", 600.0, Range::closed(0.0, 1e9), "[s] (0: not by time)");
    c.at_stage_ends = t->boolean("at_stage_ends", true);
    c.stage_end_min_seconds =
        t->real("stage_end_min_seconds", 60.0, Range::closed(0.0, 1e9), "[s] (no stage-end checkpoint this soon after the last one)");
    c.keep = static_cast<int>(t->integer("keep", 2, 1, 1000));
    t->finish();
  }

  // [[servo]]: a Servo (control/servo.hpp) on the walls named or grouped `wall`.
  void read_servo(TableReader& t, ScenarioDescription& sc) {
    const SimulationDescription& sim = sc.sim;
    const std::string name = t.string("name", std::nullopt);
    if (name.empty()) t.fail("name", "must not be empty");
    if (sc.find_servo(name) >= 0) t.fail("name", "servo \"" + name + "\" is defined twice");
    const std::string wall = t.string("wall", std::nullopt);
    const std::vector<std::size_t> walls = sim.walls_named(wall);
    if (walls.empty()) t.fail("wall", "no wall named or grouped \"" + wall + "\"");
    for (const ScenarioServo& other : sc.servos)
      for (std::size_t w : walls)
        if (std::find(other.walls.begin(), other.walls.end(), w) != other.walls.end())
          t.fail("wall", "wall '" + sim.walls[w].name + "' is already driven by servo \"" + other.name + "\"");
    const bool radial = t.choice("mode", "axial", {"axial", "radial"}) == "radial";
    Vec3 outward;
    if (!radial) {
      outward = t.vec3("outward", std::nullopt, Range::any(), "[-] (the platen's outward normal, away from the specimen)");
      if (norm(outward) == 0.0) t.fail("outward", "must not be the zero vector");
    }
    ServoSettings set;
    set.target_stress = t.real("target_stress", std::nullopt, Range::any(), "[Pa] (compression > 0)");
    set.gain_factor = t.real("gain_factor", 0.5, Range::open_closed(0.0, 1.0), "[-]");
    set.max_speed = t.real("max_speed", 1.0, Range::positive(), "[m/s]");
    std::function<double(const Simulation&)> area;
    if (radial) {
      for (std::size_t w : walls)
        if (sim.walls[w].shape != WallShape::Cylinder)
          t.fail("mode", "\"radial\" drives cylinders; wall '" + sim.walls[w].name + "' is not one");
    }
    if (t.has("area") && t.is_string("area")) {
      t.choice("area", std::nullopt, {"auto"});
      if (radial) {
        // Lateral area 2πR·height of each cylinder, at its current radius.
        for (std::size_t w : walls)
          if (!(sim.walls[w].lo < sim.walls[w].hi))
            t.fail("area", "\"auto\" needs cylinders with a finite extent; wall '" + sim.walls[w].name + "' is infinite");
        area = [walls](const Simulation& s) {
          double a = 0.0;
          for (std::size_t w : walls) {
            const Wall& c = s.walls.walls[w];
            a += 2.0 * std::numbers::pi * c.radius * (c.hi - c.lo);
          }
          return a;
        };
      } else {
        double a = 0.0;
        for (std::size_t w : walls) {
          const Wall& f = sim.walls[w];
          if (f.shape != WallShape::Facet)
            t.fail("area", "\"auto\" sums facet areas; wall '" + f.name + "' is not a facet: give the area in m^2");
          a += 0.5 * norm(cross(f.vertex[1] - f.vertex[0], f.vertex[2] - f.vertex[0]));
        }
        area = [a](const Simulation&) { return a; };
      }
    } else {
      const double a = t.real("area", std::nullopt, Range::positive(), "[m^2] (or \"auto\")");
      area = [a](const Simulation&) { return a; };
    }
    const bool enabled = t.boolean("enabled", true);
    t.finish();
    ScenarioServo s{name, wall, Servo(radial ? Servo::Mode::Radial : Servo::Mode::Axial, walls, outward, set, area), walls};
    s.servo.enabled = enabled;
    sc.servos.push_back(std::move(s));
  }

  // A servo.* quantity (histories and probes): the servo index; the field and unit go into q.
  int read_servo_quantity(TableReader& t, const ScenarioDescription& sc, Quantity& q) {
    q.name = t.string("quantity", std::nullopt);
    q.field = q.name.substr(6);
    const char* unit = nullptr;
    for (const auto& f : kServoFields)
      if (q.field == f[0]) unit = f[1];
    if (!unit) t.fail("quantity", "unknown quantity \"" + q.name + "\"; servo quantities: servo.stress [Pa], servo.target_stress [Pa], servo.speed [m/s], servo.enabled [-]");
    q.unit = unit;
    const std::string name = t.string("servo", std::nullopt);
    const int k = sc.find_servo(name);
    if (k < 0) t.fail("servo", "no [[servo]] named \"" + name + "\"");
    q.target_text = "servo " + name;
    return k;
  }

  static bool is_servo_quantity(const TableReader& t) {
    const auto q = t.peek_string("quantity");
    return q && q->rfind("servo.", 0) == 0;
  }

  void read_material(TableReader& t) {
    const std::string name = t.string("name", std::nullopt);
    if (materials_.count(name)) t.fail("name", "material \"" + name + "\" is defined twice");
    Material m;
    m.density = t.real("density", std::nullopt, kDensity, "[kg/m^3]");
    m.young_mod = t.real("young_mod", 0.0, Range::closed(0.0, kInf), "[Pa]");
    m.pois_ratio = t.real("pois_ratio", 0.0, kPoisson, "[-]");
    t.finish();
    materials_[name] = m;
  }

  const Material& material(TableReader& t) {
    std::string known;
    for (const auto& [k, v] : materials_) known += (known.empty() ? "" : ", ") + k;
    const std::string name = t.string("material", std::nullopt);
    const auto it = materials_.find(name);
    if (it == materials_.end())
      t.fail("material", "no [[material]] named \"" + name + "\"; defined: " + (known.empty() ? "(none)" : known));
    return it->second;
  }

  BallInit common_ball(TableReader& t, SimulationDescription& sim) {
    BallInit b;
    const Material& m = material(t);
    b.density = m.density;
    b.young_mod = m.young_mod;
    b.pois_ratio = m.pois_ratio;
    b.radius = t.real("radius", std::nullopt, kBallRadius, "[m]");
    b.groups = read_groups(t, sim.groups);
    b.fixity = read_fixity(t, "fix");
    b.velocity = t.vec3("velocity", Vec3{}, Range::any(), "[m/s]");
    b.spin = t.vec3("spin", Vec3{}, Range::any(), "[rad/s]");
    return b;
  }

  void add_ball(TableReader& t, SimulationDescription& sim, const BallInit& b) {
    if (sim.balls.size() >= limits_.max_balls)
      t.fail("id", "more than " + std::to_string(limits_.max_balls) + " balls (the limit for one scenario)");
    if (!ids_.emplace(b.id, sim.balls.size()).second) t.fail("id", "ball id " + std::to_string(b.id) + " is used twice");
    sim.balls.push_back(b);
  }

  void read_ball(TableReader& t, SimulationDescription& sim) {
    BallInit b = common_ball(t, sim);
    b.id = t.integer("id", std::nullopt, 0, INT64_MAX);
    b.position = t.vec3("position", std::nullopt, kCoordinate, "[m]");
    t.finish();
    add_ball(t, sim, b);
  }

  void read_ball_grid(TableReader& t, SimulationDescription& sim) {
    BallInit b = common_ball(t, sim);
    std::int64_t id = t.integer("first_id", std::nullopt, 0, INT64_MAX);
    const Vec3 origin = t.vec3("origin", std::nullopt, kCoordinate, "[m]");
    const Vec3 counts = t.vec3("counts", std::nullopt, Range::closed(1, 1000), "[-]");
    if (counts.x != std::floor(counts.x) || counts.y != std::floor(counts.y) || counts.z != std::floor(counts.z))
      t.fail("counts", "must be whole numbers [nx, ny, nz]");
    if (counts.x * counts.y * counts.z > kMaxBalls)
      t.fail("counts", fmt::format("at most {:g} balls in all; got {:g}", kMaxBalls, counts.x * counts.y * counts.z));
    if (static_cast<double>(id) + counts.x * counts.y * counts.z > 9.2e18)
      t.fail("first_id", "ids would overflow a 64-bit integer");
    const double spacing = t.real("spacing", std::nullopt, Range::positive(), "[m]");
    const Vec3 last = origin + (counts - Vec3{1, 1, 1}) * spacing;
    if (!within(kCoordinate, last))
      t.fail("spacing", fmt::format("the grid's far corner [{:g}, {:g}, {:g}] m is outside {} [m] (origin + (counts - 1) x spacing)",
                                    last.x, last.y, last.z, kCoordinate.text()));
    t.finish();
    const double total = counts.x * counts.y * counts.z;
    if (total + static_cast<double>(sim.balls.size()) > static_cast<double>(limits_.max_balls))
      t.fail("counts", fmt::format("{:g} balls: more than {} balls in the scenario (the limit for one scenario)", total,
                                   limits_.max_balls));
    try {
      sim.balls.reserve(sim.balls.size() + static_cast<std::size_t>(total));
    } catch (const std::bad_alloc&) {
      throw OutOfMemory(fmt::format("reading {} ({:g} balls of a [[ball_grid]])", t.where("counts"), total),
                        (total + static_cast<double>(sim.balls.size())) * static_cast<double>(sizeof(BallInit)));
    }
    for (int k = 0; k < static_cast<int>(counts.z); ++k)
      for (int j = 0; j < static_cast<int>(counts.y); ++j)
        for (int i = 0; i < static_cast<int>(counts.x); ++i) {
          b.id = id++;
          b.position = origin + Vec3{i * spacing, j * spacing, k * spacing};
          add_ball(t, sim, b);
        }
  }

  // [[packing]]: balls from a file (path relative to the scenario file).
  void read_packing_table(TableReader& t, SimulationDescription& sim) {
    const std::string file = t.string("file", std::nullopt);
    const std::string format = t.choice("format", "lammps", {"lammps", "xyzr"});
    const Material& m = material(t);
    const std::uint64_t groups = read_groups(t, sim.groups);
    const auto rep = t.integers("replicate");
    if (!rep.empty() && (rep.size() != 3 || rep[0] < 1 || rep[1] < 1 || rep[2] < 1 || rep[0] > 10000 ||
                         rep[1] > 10000 || rep[2] > 10000 || rep[0] * rep[1] * rep[2] > 10000))
      t.fail("replicate", "must be [nx, ny, nz] with each >= 1 (at most 10000 copies in all)");
    std::int64_t next_id = 1;
    for (const auto& known : ids_) next_id = std::max(next_id, known.first + 1);
    std::int64_t id = t.integer("first_id", next_id, 0, INT64_MAX);
    t.finish();
    const std::filesystem::path base = std::filesystem::path(file_).parent_path();
    const std::string path = std::filesystem::path(file).is_absolute() ? file : (base / file).string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) t.fail("file", "\"" + path + "\" is not a readable regular file");
    Packing p;
    try {
      p = read_packing(path, format == "lammps" ? PackingFormat::Lammps : PackingFormat::Xyzr);
    } catch (const InputError& e) {
      t.fail("file", e.what());
    }
    if (!rep.empty()) {
      const int n[3] = {static_cast<int>(rep[0]), static_cast<int>(rep[1]), static_cast<int>(rep[2])};
      if (!p.has_box) t.fail("replicate", "needs a packing with a box (format \"lammps\")");
      replicate(p, n);
    }
    if (static_cast<double>(p.balls.size()) + static_cast<double>(sim.balls.size()) > kMaxBalls)
      t.fail("file", fmt::format("at most {:g} balls in all", kMaxBalls));
    if (p.has_box && !box_given_) {
      sim.settings.box.lo = p.box_lo;
      sim.settings.box.hi = p.box_hi;
      box_given_ = true;
    }
    for (const ImportedBall& ib : p.balls) {
      if (!within(kCoordinate, ib.position) || !kBallRadius.contains(ib.radius) || !(ib.density <= 0.0 || kDensity.contains(ib.density)))
        t.fail("file", fmt::format("\"{}\": a ball at [{:g}, {:g}, {:g}] m with radius {:g} m and density {:g} kg/m^3; positions "
                                   "must be in {} [m], radii in {} [m], densities in {} [kg/m^3]",
                                   path, ib.position.x, ib.position.y, ib.position.z, ib.radius, ib.density,
                                   kCoordinate.text(), kBallRadius.text(), kDensity.text()));
      BallInit b;
      b.id = id++;
      b.position = ib.position;
      b.radius = ib.radius;
      b.density = ib.density > 0.0 ? ib.density : m.density;
      b.young_mod = m.young_mod;
      b.pois_ratio = m.pois_ratio;
      b.groups = groups;
      add_ball(t, sim, b);
    }
  }

  // [[clump_template]]: a shape and its mass properties (io/scenario_clumps.hpp), of a material.
  void read_clump_template(TableReader& t, SimulationDescription& sim) {
    const std::string name = t.string("name", std::nullopt);
    if (templates_.count(name)) t.fail("name", "clump template \"" + name + "\" is defined twice");
    const Material& m = material(t);
    sim.clump_templates.push_back(read_clump_template_shape(t, m.density));
    t.finish();
    templates_[name] = {sim.clump_templates.size() - 1, m};
  }

  // [[clump]]: a clump of a template; its pebbles are balls first_id, first_id + 1, ...
  void read_clump(TableReader& t, SimulationDescription& sim) {
    const std::string name = t.string("template", std::nullopt);
    const auto it = templates_.find(name);
    if (it == templates_.end()) t.fail("template", "no [[clump_template]] named \"" + name + "\"");
    const auto& [index, m] = it->second;
    SimulationDescription::Clump c;
    c.tmpl = index;
    c.init.first_ball_id = t.integer("first_id", std::nullopt, 0, INT64_MAX / 2);
    read_clump_placement(t, c.init);
    c.init.groups = read_groups(t, sim.groups);
    c.init.fixity = read_fixity(t, "fix");
    c.init.young_mod = m.young_mod;
    c.init.pois_ratio = m.pois_ratio;
    t.finish();
    const std::size_t n = sim.clump_templates[index].pebbles.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::int64_t id = c.init.first_ball_id + static_cast<std::int64_t>(k);
      if (!ids_.emplace(id, sim.balls.size() + pebble_count_ + k).second)
        t.fail("first_id", "ball id " + std::to_string(id) + " (pebble " + std::to_string(k) + ") is used twice");
    }
    pebble_count_ += n;
    if (sim.balls.size() + pebble_count_ > limits_.max_balls)
      t.fail("first_id", "more than " + std::to_string(limits_.max_balls) + " balls and pebbles (the limit for one scenario)");
    sim.clumps.push_back(c);
  }

  // The hill model needs E > 0 on both balls (spec §2.4): refuse a material without it when a hill
  // rule can apply to its balls.
  void check_hill_moduli(const SimulationDescription& sim) {
    for (const ModelRule& r : sim.rules) {
      if (r.model != ModelKind::Hill) continue;
      for (std::size_t i = 0; i < sim.balls.size(); ++i) {
        const bool in_rule = (r.groups1 == 0 || (sim.balls[i].groups & r.groups1)) ||
                             (r.groups2 == 0 || (sim.balls[i].groups & r.groups2));
        if (in_rule && !(sim.balls[i].young_mod > 0.0))
          throw InputError(fmt::format("{}: key 'material.young_mod': ball {} has young_mod = 0 but the hill rule '{}' "
                                       "can apply to it; the hill model needs young_mod in (0, inf) [Pa]",
                                       file_, sim.balls[i].id, r.name));
      }
      for (const SimulationDescription::Clump& c : sim.clumps) {
        const bool in_rule = (r.groups1 == 0 || (c.init.groups & r.groups1)) || (r.groups2 == 0 || (c.init.groups & r.groups2));
        if (in_rule && !(c.init.young_mod > 0.0))
          throw InputError(fmt::format("{}: key 'material.young_mod': the clump of ball {} has young_mod = 0 but the hill rule "
                                       "'{}' can apply to it; the hill model needs young_mod in (0, inf) [Pa]",
                                       file_, c.init.first_ball_id, r.name));
      }
    }
  }

  void finish_box(SimulationDescription& sim) {
    if (!sim.settings.box.any()) return;
    if (!sim.clumps.empty())
      throw InputError(file_ + ": key 'simulation.periodic': clumps in a periodic box are not supported (docs/clumps.md)");
    if (!box_given_)
      throw InputError(file_ + ": key 'simulation.periodic' needs simulation.box_min and box_max [m] (or a [[packing]] LAMMPS file with a box)");
    for (std::size_t i = 0; i < sim.balls.size(); ++i)
      if (!std::isfinite(norm(sim.balls[i].position)))
        throw InputError(file_ + ": ball " + std::to_string(sim.balls[i].id) + " has a non-finite position");
    // The cell grid needs at least 3 cells across a period, each at least one interaction length
    // wide (contact/cell_grid.cpp): refuse here, naming the key, what the first rebuild would refuse.
    if (sim.balls.empty()) return;
    double rmax = 0.0, rsum = 0.0;
    for (const BallInit& b : sim.balls) rmax = std::max(rmax, b.radius), rsum += b.radius;
    const SimulationSettings& s = sim.settings;
    const double skin = s.skin > 0.0 ? s.skin : 0.1 * 2.0 * rsum / static_cast<double>(sim.balls.size());
    const double interaction = 2.0 * rmax + s.proximity + skin;
    for (int d = 0; d < 3; ++d) {
      const double length = s.box.hi[d] - s.box.lo[d];
      if (s.box.periodic[d] && !(length >= 3.0 * interaction))
        throw InputError(fmt::format(
            "{}: key 'simulation.box_max': the periodic box is {:g} m long in {}; it must be at least 3 interaction "
            "lengths, 3 x (2 R_max + proximity + skin) = 3 x ({:g} + {:g} + {:g}) = {:g} m",
            file_, length, static_cast<char>('x' + d), 2.0 * rmax, s.proximity, skin, 3.0 * interaction));
    }
  }

  void motion_keys(TableReader& t, Wall& w) {
    w.velocity = t.vec3("velocity", Vec3{}, Range::any(), "[m/s]");
    w.spin = t.vec3("spin", Vec3{}, Range::any(), "[rad/s]");
  }

  void read_wall(TableReader& t, SimulationDescription& sim) {
    Wall w;
    w.name = t.string("name", std::nullopt);
    if (w.name.empty()) t.fail("name", "must not be empty");
    if (!wall_names_.insert(w.name).second) t.fail("name", "wall \"" + w.name + "\" is defined twice");
    w.groups = read_groups(t, sim.groups);
    const std::string type = t.choice("type", std::nullopt, {"plane", "facet", "cylinder", "box"});
    if (type == "plane") {
      w.shape = WallShape::Plane;
      w.point = t.vec3("point", std::nullopt, kCoordinate, "[m]");
      const Vec3 n = t.vec3("normal", std::nullopt, Range::any(), "[-]");
      if (norm(n) == 0.0) t.fail("normal", "must not be the zero vector");
      w.normal = n / norm(n);
      w.rotation_center = t.vec3("rotation_center", w.point, kCoordinate, "[m]");
      motion_keys(t, w);
    } else if (type == "facet") {
      w.shape = WallShape::Facet;
      const auto v = t.vec3_list("vertices", "[m]");
      if (v.size() != 3) t.fail("vertices", "a facet needs exactly 3 vertices");
      for (const Vec3& x : v)
        if (!within(kCoordinate, x))
          t.fail("vertices", fmt::format("every coordinate must be in {} [m]; got [{:g}, {:g}, {:g}]", kCoordinate.text(), x.x, x.y, x.z));
      if (norm(cross(v[1] - v[0], v[2] - v[0])) == 0.0) t.fail("vertices", "the 3 vertices are collinear");
      for (int k = 0; k < 3; ++k) w.vertex[k] = v[k];
      w.rotation_center = t.vec3("rotation_center", (v[0] + v[1] + v[2]) / 3.0, kCoordinate, "[m]");
      motion_keys(t, w);
    } else if (type == "cylinder") {
      w.shape = WallShape::Cylinder;
      const std::string axis = t.choice("axis", "z", {"x", "y", "z"});
      w.axis = axis[0] - 'x';
      w.point = t.vec3("center", std::nullopt, kCoordinate, "[m]");
      w.radius = t.real("radius", std::nullopt, Range::positive(), "[m]");
      if (t.has("extent")) {
        const auto e = t.reals("extent", kCoordinate, "[m]");
        if (e.size() != 2 || !(e[0] < e[1]))
          t.fail("extent", "must be [lo, hi] with lo < hi [m], along the axis from the center");
        w.lo = e[0];
        w.hi = e[1];
      }
      w.rotation_center = w.point;
      w.velocity = t.vec3("velocity", Vec3{}, Range::any(), "[m/s]");
      w.radial_velocity = t.real("radial_velocity", 0.0, Range::any(), "[m/s]");
    } else {
      read_box(t, sim, w);
      return;
    }
    t.finish();
    sim.walls.push_back(w);
  }

  // A box of 12 facets (2 per face) named <name>.<face>.<1|2>, each in the groups <name> and
  // <name>.<face> (faces xmin, xmax, ymin, ymax, zmin, zmax), so `wall = "box.zmin"` sums the floor.
  void read_box(TableReader& t, SimulationDescription& sim, const Wall& base) {
    const Vec3 lo = t.vec3("min", std::nullopt, kCoordinate, "[m]");
    const Vec3 hi = t.vec3("max", std::nullopt, kCoordinate, "[m]");
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) t.fail("max", "must exceed min in x, y and z");
    t.finish();
    const char* faces[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
    for (int f = 0; f < 6; ++f) {
      const int axis = f / 2;
      const double at = f % 2 ? hi[axis] : lo[axis];
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3 c[4];
      for (int k = 0; k < 4; ++k) {
        c[k][axis] = at;
        c[k][u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        c[k][v] = (k >= 2) ? hi[v] : lo[v];
      }
      const std::string face = base.name + "." + faces[f];
      for (int half = 0; half < 2; ++half) {
        Wall w = base;
        w.shape = WallShape::Facet;
        w.name = face + "." + std::to_string(half + 1);
        w.groups = base.groups | sim.groups.bit(base.name) | sim.groups.bit(face);
        w.vertex[0] = c[0];
        w.vertex[1] = half == 0 ? c[1] : c[2];
        w.vertex[2] = half == 0 ? c[2] : c[3];
        w.rotation_center = (lo + hi) / 2.0;
        sim.walls.push_back(w);
      }
    }
  }

  std::uint64_t group_filter(TableReader& t, const std::string& g, SimulationDescription& sim, const std::string& key) {
    if (g == "any") return 0;
    const std::uint64_t bit = sim.groups.find(g);
    if (!bit) t.fail(key, "no ball or wall is in group \"" + g + "\"");
    return bit;
  }

  void read_rule(TableReader& t, SimulationDescription& sim) {
    ModelRule r;
    r.name = t.string("name", "rule " + std::to_string(sim.rules.size() + 1));
    const std::string between = t.choice("between", std::nullopt, {"ball-ball", "ball-wall"});
    r.kind = between == "ball-ball" ? ContactKind::BallBall : ContactKind::BallWall;
    const auto groups = t.strings("groups");
    if (groups.size() > 2) t.fail("groups", "at most two group names: [\"ball group\", \"other group\"]");
    if (groups.size() >= 1) {
      r.groups1_text = groups[0];
      r.groups1 = group_filter(t, groups[0], sim, "groups");
    }
    if (groups.size() == 2) {
      r.groups2_text = groups[1];
      r.groups2 = group_filter(t, groups[1], sim, "groups");
    }
    const std::string model = t.choice("model", std::nullopt, {"linear", "hill", "rrlinear"});
    if (model == "hill") {
      if (r.kind != ContactKind::BallBall)
        t.fail("model", "the hill model exists only between grains (ball-ball); use \"linear\" for ball-wall (spec §2.1)");
      r.model = ModelKind::Hill;
      r.hill.fric_coef = t.real("fric_coef", 0.0, Range::closed(0.0, kInf), "[-]");
      r.hill.damp_con = t.real("damp_con", 0.0, kDampCon, "[-]");
      r.hill.suction = t.real("suction", 0.0, Range::closed(0.0, kInf), "[Pa]");
    } else {
      r.model = model == "rrlinear" ? ModelKind::RrLinear : ModelKind::Linear;
      r.linear.emod = t.real("emod", std::nullopt, Range::positive(), "[Pa]");
      r.linear.kratio = t.real("kratio", 1.0, Range::positive(), "[-]");
      r.linear.fric = t.real("fric", 0.0, Range::closed(0.0, kInf), "[-]");
      if (r.model == ModelKind::RrLinear)  // μ_r (docs/spec/rrlinear.md)
        r.linear.rolling_fric = t.real("rr_fric", 0.0, Range::closed(0.0, kInf), "[-]");
    }
    t.finish();
    if (sim.rules.size() >= 30000) t.fail("name", "at most 30000 assignment rules");
    sim.rules.push_back(r);
  }

  void read_history(TableReader& t, ScenarioDescription& sc) {
    History h;
    h.name = t.string("name", std::nullopt);
    if (h.name.empty() || h.name.find_first_of(",\"\n") != std::string::npos)
      t.fail("name", "must be a non-empty name without commas, quotes or newlines");
    for (const History& o : sc.histories)
      if (o.name == h.name) t.fail("name", "history \"" + h.name + "\" is defined twice");
    if (is_servo_quantity(t)) h.servo = read_servo_quantity(t, sc, h.quantity);
    else h.quantity = read_quantity(t, sc.sim);
    if (h.quantity.field == "shear_disp") sc.sim.settings.track_shear_displacement = true;
    t.finish();
    sc.histories.push_back(h);
  }

  Selection read_selection(TableReader& t, const SimulationDescription& sim, bool walls_allowed) {
    Selection s;
    const int given = t.has("ball") + t.has("balls") + t.has("group") + (walls_allowed && t.has("wall"));
    const std::string keys = walls_allowed ? "ball, balls, group or wall" : "ball, balls or group";
    if (given != 1) t.fail(given ? "ball" : "type", "needs exactly one of the keys " + keys);
    if (t.has("ball") || t.has("balls")) {
      const auto ids = t.has("ball") ? t.integers("ball") : t.integers("balls");
      for (std::int64_t id : ids) {
        const auto i = ids_.find(id);
        if (i == ids_.end()) t.fail(t.has("ball") ? "ball" : "balls", "no ball with id " + std::to_string(id));
        s.balls.push_back(i->second);
      }
      if (s.balls.empty()) t.fail("balls", "must list at least one ball id");
      s.text = "ball(s) " + fmt::format("{}", fmt::join(ids, ","));
    } else if (t.has("group")) {
      const std::string g = t.string("group", std::nullopt);
      const std::uint64_t bit = sim.groups.find(g);
      for (std::size_t i = 0; i < sim.balls.size(); ++i)
        if (bit && (sim.balls[i].groups & bit)) s.balls.push_back(i);
      if (s.balls.empty()) t.fail("group", "no ball is in group \"" + g + "\"");
      s.text = "group " + g;
    } else {
      const std::string w = t.string("wall", std::nullopt);
      s.walls = sim.walls_named(w);
      if (s.walls.empty()) t.fail("wall", "no wall named or grouped \"" + w + "\"");
      s.text = "wall " + w;
    }
    return s;
  }

  void read_stage(TableReader& t, ScenarioDescription& sc) {
    Stage s;
    const std::string type = t.choice("type", std::nullopt,
                                      {"cycle", "solve", "translate", "rotate", "set", "set_contacts",
                                       "set_simulation", "make_wet", "make_dry", "probe", "list_contacts", "set_servo"});
    s.name = t.string("name", type == "probe" && t.is_string("label") ? *t.peek_string("label") : type);
    const SimulationDescription& sim = sc.sim;
    if (type == "cycle") {
      s.type = StageType::Cycle;
      s.steps = t.integer("steps", std::nullopt, 1, 1'000'000'000'000);
    } else if (type == "solve") {
      s.type = StageType::Solve;
      s.ratio = t.real("ratio", 1e-5, Range::open(0.0, 1.0), "[-]");
      s.max_steps = t.integer("max_steps", 1'000'000, 1, 1'000'000'000'000);
    } else if (type == "translate" || type == "rotate") {
      s.type = type == "translate" ? StageType::Translate : StageType::Rotate;
      s.sel = read_selection(t, sim, false);
      s.by = t.vec3("by", std::nullopt, Range::any(), type == "translate" ? "[m]" : "[rad] (rotation vector)");
      s.steps = t.integer("steps", std::nullopt, 1, 1'000'000'000);
    } else if (type == "set") {
      s.type = StageType::Set;
      s.sel = read_selection(t, sim, true);
      const bool walls = !s.sel.walls.empty();
      if (t.has("velocity")) s.velocity = t.vec3("velocity", std::nullopt, Range::any(), "[m/s]");
      if (t.has("spin")) s.spin = t.vec3("spin", std::nullopt, Range::any(), "[rad/s]");
      if (walls) {
        if (t.has("radial_velocity"))
          s.radial_velocity = t.real("radial_velocity", std::nullopt, Range::any(), "[m/s]");
      } else {
        if (t.has("position")) s.position = t.vec3("position", std::nullopt, kCoordinate, "[m]");
        if (t.has("applied_force")) s.applied_force = t.vec3("applied_force", std::nullopt, Range::any(), "[N]");
        s.fix = read_fixity(t, "fix");
        s.free = read_fixity(t, "free");
        if (s.fix & s.free) t.fail("free", "a component cannot be fixed and freed in the same stage");
      }
    } else if (type == "set_contacts") {
      s.type = StageType::SetContacts;
      const std::string m = t.choice("model", std::nullopt, {"linear", "hill", "rrlinear"});
      s.model_filter = m == "hill" ? ModelKind::Hill : m == "rrlinear" ? ModelKind::RrLinear : ModelKind::Linear;
      if (m == "hill") {
        if (t.has("fric_coef")) s.fric = t.real("fric_coef", std::nullopt, Range::closed(0.0, kInf), "[-]");
        if (t.has("damp_con")) s.damp_con = t.real("damp_con", std::nullopt, kDampCon, "[-]");
        if (t.has("suction")) s.suction = t.real("suction", std::nullopt, Range::closed(0.0, kInf), "[Pa]");
      } else {
        if (t.has("fric")) s.fric = t.real("fric", std::nullopt, Range::closed(0.0, kInf), "[-]");
        if (t.has("emod")) s.emod = t.real("emod", std::nullopt, Range::positive(), "[Pa]");
        if (t.has("kratio")) s.kratio = t.real("kratio", std::nullopt, Range::positive(), "[-]");
        if (m == "rrlinear" && t.has("rr_fric"))
          s.rolling_fric = t.real("rr_fric", std::nullopt, Range::closed(0.0, kInf), "[-]");
      }
    } else if (type == "set_simulation") {
      s.type = StageType::SetSimulation;
      if (t.has("gravity")) s.gravity = t.vec3("gravity", std::nullopt, kGravity, "[m/s^2]");
      if (t.has("local_damping")) s.local_damping = t.real("local_damping", std::nullopt, kLocalDamping, "[-]");
      if (t.has("timestep")) {
        if (t.is_string("timestep")) {
          t.choice("timestep", std::nullopt, {"auto"});
          s.timestep = 0.0;
        } else {
          s.timestep = t.real("timestep", std::nullopt, Range::open(0.0, 1.0), "[s] (or \"auto\")");
        }
      }
    } else if (type == "make_wet") {
      s.type = StageType::MakeWet;
      s.wet_suction = t.real("suction", std::nullopt, Range::closed(0.0, kInf), "[Pa]");
      s.wet_gap = t.real("gap", std::nullopt, Range::closed(0.0, kInf), "[m]");
    } else if (type == "make_dry") {
      s.type = StageType::MakeDry;
    } else if (type == "probe") {
      s.type = StageType::Probe;
      s.label = t.string("label", std::nullopt);
      if (s.label.empty()) t.fail("label", "must not be empty");
      if (!labels_.insert(s.label).second) t.fail("label", "probe label \"" + s.label + "\" is used twice");
      if (is_servo_quantity(t)) s.servo = read_servo_quantity(t, sc, s.quantity);
      else s.quantity = read_quantity(t, sim);
      if (s.quantity.field == "shear_disp") sc.sim.settings.track_shear_displacement = true;
      s.ratio_to = t.string("ratio_to", "");
      if (!s.ratio_to.empty() && (s.ratio_to == s.label || !labels_.count(s.ratio_to)))
        t.fail("ratio_to", "must name an earlier probe label; got \"" + s.ratio_to + "\"");
      s.scale = t.real("scale", 1.0, Range::any(), "[-]");
    } else if (type == "set_servo") {
      s.type = StageType::SetServo;
      const std::string name = t.string("servo", std::nullopt);
      s.servo = sc.find_servo(name);
      if (s.servo < 0) t.fail("servo", "no [[servo]] named \"" + name + "\"");
      if (t.has("target_stress")) s.target_stress = t.real("target_stress", std::nullopt, Range::any(), "[Pa]");
      if (t.has("gain_factor")) s.gain_factor = t.real("gain_factor", std::nullopt, Range::open_closed(0.0, 1.0), "[-]");
      if (t.has("max_speed")) s.max_speed = t.real("max_speed", std::nullopt, Range::positive(), "[m/s]");
      if (t.has("enabled")) s.enabled = t.boolean("enabled", true);
      if (!s.target_stress && !s.gain_factor && !s.max_speed && !s.enabled)
        t.fail("servo", "set_servo needs at least one of target_stress, gain_factor, max_speed, enabled");
    } else {
      s.type = StageType::ListContacts;
    }
    t.finish();
    sc.stages.push_back(std::move(s));
  }

  TableReader root_;
  std::string file_;
  ScenarioLimits limits_;
  std::map<std::string, Material> materials_;
  std::map<std::int64_t, std::size_t> ids_;  // ball id -> index
  struct TemplateEntry {
    std::size_t index;
    Material material;
  };
  std::map<std::string, TemplateEntry> templates_;  // clump template name -> index, material
  std::size_t pebble_count_ = 0;                     // pebbles of the clumps read so far
  std::set<std::string> wall_names_, labels_;
  bool box_given_ = false;
};

}  // namespace

int ScenarioPlan::find_servo(const std::string& name) const {
  for (std::size_t k = 0; k < servos.size(); ++k)
    if (servos[k].name == name) return static_cast<int>(k);
  return -1;
}

ScenarioDescription read_scenario(const std::string& text, const std::string& file, const ScenarioLimits& limits) {
  const toml::table root = parse_toml(text, file);
  ScenarioDescription sc = Reader(root, file, limits).read();
  sc.text = text;
  return sc;
}

ScenarioDescription read_scenario_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(path + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the scenario file");
  std::ostringstream ss;
  ss << in.rdbuf();
  try {
    return read_scenario(ss.str(), path);
  } catch (const std::bad_alloc&) {
    throw OutOfMemory("reading the scenario " + path, -1.0);
  }
}

Scenario build_scenario(ScenarioDescription d) {
  Scenario sc;
  try {
    sc.sim = build_simulation(d.sim);
  } catch (const std::bad_alloc&) {
    throw OutOfMemory(fmt::format("building the simulation of {} ({} balls)", d.file, d.sim.balls.size()),
                      state_memory_estimate(d.sim.balls.size(), 0));
  }
  static_cast<ScenarioPlan&>(sc) = std::move(d);
  return sc;
}

Scenario load_scenario(const std::string& text, const std::string& file, const ScenarioLimits& limits) {
  return build_scenario(read_scenario(text, file, limits));
}

Scenario load_scenario_file(const std::string& path) { return build_scenario(read_scenario_file(path)); }

}  // namespace hilldem
