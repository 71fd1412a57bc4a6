#include "hilldem/io/state_io.hpp"

#include <cmath>
#include <cstring>
#include <optional>
#include <fmt/format.h>
#include <set>
#include <type_traits>
#include <utility>
#include <utility>
#include <vector>

namespace hilldem {

// Tripwires: these types are written field by field or as raw bytes below. When one changes, this
// file must change with it (a new field would otherwise be silently left out of checkpoints). The
// size catches most changes; the count of aggregate initialisers catches a field hidden in padding.
namespace tripwire {
struct Any {
  template <class T>
  operator T() const;
};
template <class T, std::size_t... I>
constexpr bool takes(std::index_sequence<I...>) {
  return requires { T{(void(I), Any{})...}; };
}
template <class T, std::size_t N = 0>
constexpr std::size_t initialisers() {
  if constexpr (N < 64 && takes<T>(std::make_index_sequence<N + 1>{})) return initialisers<T, N + 1>();
  else return N;
}
}  // namespace tripwire
static_assert(tripwire::initialisers<SimulationSettings>() == 11, "SimulationSettings changed: update write_settings/read_settings in io/state_io.cpp");
static_assert(tripwire::initialisers<Wall>() == 21, "Wall changed: update write_wall/read_wall in io/state_io.cpp");
static_assert(tripwire::initialisers<ModelRule>() == 9, "ModelRule changed: update write_rule/read_rule in io/state_io.cpp");
static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 changed: update io/state_io.cpp");
static_assert(sizeof(HillParams) == 3 * sizeof(double), "HillParams changed: update io/state_io.cpp");
static_assert(sizeof(HillMapping) == 9 * sizeof(double), "HillMapping changed: update io/state_io.cpp");
static_assert(sizeof(LinearParams) == 4 * sizeof(double), "LinearParams changed: update io/state_io.cpp");
static_assert(sizeof(LinearMapping) == 2 * sizeof(double), "LinearMapping changed: update io/state_io.cpp");
static_assert(sizeof(ContactKey) == 12, "ContactKey changed: update io/state_io.cpp");
static_assert(sizeof(Wall) == 352, "Wall changed: update write_wall/read_wall in io/state_io.cpp");
static_assert(sizeof(SimulationSettings) == 144, "SimulationSettings changed: update io/state_io.cpp");
static_assert(sizeof(ModelRule) == 184, "ModelRule changed: update io/state_io.cpp");

namespace {

constexpr std::uint64_t kMaxBalls = 1ull << 31;  // indices are 32-bit in ContactKey
constexpr std::uint64_t kMaxWalls = 1ull << 31;

// ---- column codecs: ContactKey has padding, so it is written field by field ----

template <class T>
void put_column(SectionWriter& w, const std::vector<T>& v) {
  if constexpr (std::is_same_v<T, ContactKey>) {
    w.u64(v.size());
    w.u32(9);
    for (const ContactKey& k : v) {
      w.u32(k.a);
      w.u8(static_cast<std::uint8_t>(k.kind));
      w.u32(k.b);
    }
  } else {
    w.column(v);
  }
}

template <class T>
void get_column(SectionReader& r, std::vector<T>& v, const char* what) {
  if constexpr (std::is_same_v<T, ContactKey>) {
    const std::uint64_t n = r.u64();
    if (r.u32() != 9) r.fail(std::string("column '") + what + "' has an unexpected element size");
    if (n > r.remaining() / 9) r.fail(std::string("column '") + what + "' is truncated");
    v.resize(n);
    for (ContactKey& k : v) {
      k.a = r.u32();
      const std::uint8_t kind = r.u8();
      if (kind > 1) r.fail("a contact key has kind " + std::to_string(kind));
      k.kind = static_cast<ContactKind>(kind);
      k.b = r.u32();
    }
  } else {
    r.column(v, what);
  }
}

// ---- walls ----

void write_wall(SectionWriter& w, const Wall& x) {
  w.str(x.name);
  w.u64(x.groups);
  w.u32(static_cast<std::uint32_t>(x.shape));
  w.vec3(x.point);
  w.vec3(x.normal);
  for (const Vec3& v : x.vertex) w.vec3(v);
  w.u32(static_cast<std::uint32_t>(x.axis));
  w.f64(x.radius);
  w.f64(x.lo);
  w.f64(x.hi);
  w.vec3(x.velocity);
  w.vec3(x.spin);
  w.vec3(x.rotation_center);
  w.f64(x.radial_velocity);
  w.vec3(x.force);
  w.vec3(x.moment);
  w.f64(x.normal_force);
  w.f64(x.normal_stiffness);
  w.u64(x.active_contacts);
}

Wall read_wall(SectionReader& r) {
  Wall x;
  x.name = r.str(4096);
  x.groups = r.u64();
  const std::uint32_t shape = r.u32();
  if (shape > 2) r.fail("wall '" + x.name + "' has shape code " + std::to_string(shape));
  x.shape = static_cast<WallShape>(shape);
  x.point = r.vec3();
  x.normal = r.vec3();
  for (Vec3& v : x.vertex) v = r.vec3();
  const std::uint32_t axis = r.u32();
  if (axis > 2) r.fail("wall '" + x.name + "' has axis " + std::to_string(axis));
  x.axis = static_cast<int>(axis);
  x.radius = r.f64();
  x.lo = r.f64();
  x.hi = r.f64();
  x.velocity = r.vec3();
  x.spin = r.vec3();
  x.rotation_center = r.vec3();
  x.radial_velocity = r.f64();
  x.force = r.vec3();
  x.moment = r.vec3();
  x.normal_force = r.f64();
  x.normal_stiffness = r.f64();
  x.active_contacts = r.u64();
  return x;
}

// ---- settings ----

void write_settings(SectionWriter& w, const SimulationSettings& s) {
  w.vec3(s.gravity);
  w.f64(s.local_damping);
  w.boolean(s.auto_timestep);
  w.f64(s.timestep);
  w.f64(s.timestep_safety);
  w.f64(s.timestep_max);
  w.f64(s.proximity);
  w.f64(s.skin);
  w.boolean(s.density_scaling);
  w.boolean(s.track_shear_displacement);
  for (bool p : s.box.periodic) w.boolean(p);
  w.vec3(s.box.lo);
  w.vec3(s.box.hi);
}

SimulationSettings read_settings(SectionReader& r) {
  SimulationSettings s;
  s.gravity = r.vec3();
  s.local_damping = r.f64();
  s.auto_timestep = r.boolean();
  s.timestep = r.f64();
  s.timestep_safety = r.f64();
  s.timestep_max = r.f64();
  s.proximity = r.f64();
  s.skin = r.f64();
  s.density_scaling = r.boolean();
  s.track_shear_displacement = r.boolean();
  for (bool& p : s.box.periodic) p = r.boolean();
  s.box.lo = r.vec3();
  s.box.hi = r.vec3();
  r.finish();
  auto finite = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite(s.gravity)) r.fail("gravity is not finite");
  if (!(s.local_damping >= 0.0 && s.local_damping < 1.0)) r.fail("local_damping outside [0, 1)");
  if (!(s.timestep > 0.0 && s.timestep < 1.0)) r.fail("timestep outside (0, 1) s");
  if (!(s.timestep_safety > 0.0 && s.timestep_safety <= 1.0)) r.fail("timestep_safety outside (0, 1]");
  if (!(s.timestep_max > 0.0 && s.timestep_max < 1.0)) r.fail("timestep_max outside (0, 1) s");
  if (!(s.proximity >= 0.0 && std::isfinite(s.proximity))) r.fail("proximity is negative or not finite");
  if (!(s.skin >= 0.0 && std::isfinite(s.skin))) r.fail("skin is negative or not finite");
  for (int d = 0; d < 3; ++d)
    if (s.box.periodic[d] && !(s.box.lo[d] < s.box.hi[d] && std::isfinite(s.box.hi[d] - s.box.lo[d])))
      r.fail("the periodic box is empty or not finite");
  return s;
}

// Section versions: 2 added rrlinear (the rules' μ_r, the contacts' moment_state column). A table of
// version 1 reads with μ_r = 0; contacts of version 1 are refused (their state digest covers another
// layout).
constexpr std::uint32_t kTableVersion = 2;
constexpr std::uint32_t kContactsVersion = 2;
constexpr std::uint32_t kCycleVersion = 2;

// ---- groups and table ----

void write_rule(SectionWriter& w, const ModelRule& r) {
  w.str(r.name);
  w.u8(static_cast<std::uint8_t>(r.kind));
  w.u64(r.groups1);
  w.u64(r.groups2);
  w.str(r.groups1_text);
  w.str(r.groups2_text);
  w.u8(static_cast<std::uint8_t>(r.model));
  w.f64(r.linear.emod);
  w.f64(r.linear.kratio);
  w.f64(r.linear.fric);
  w.f64(r.linear.rolling_fric);
  w.f64(r.hill.fric_coef);
  w.f64(r.hill.damp_con);
  w.f64(r.hill.suction);
}

ModelRule read_rule(SectionReader& r) {
  ModelRule x;
  x.name = r.str(4096);
  const std::uint8_t kind = r.u8();
  x.groups1 = r.u64();
  x.groups2 = r.u64();
  x.groups1_text = r.str(4096);
  x.groups2_text = r.str(4096);
  const std::uint8_t model = r.u8();
  if (kind > 1 || model >= kModelCount) r.fail("rule '" + x.name + "' has an unknown contact kind or model");
  x.kind = static_cast<ContactKind>(kind);
  x.model = static_cast<ModelKind>(model);
  if (x.model == ModelKind::Hill && x.kind != ContactKind::BallBall) r.fail("rule '" + x.name + "': hill between a ball and a wall");
  x.linear.emod = r.f64();
  x.linear.kratio = r.f64();
  x.linear.fric = r.f64();
  if (r.version() >= 2) x.linear.rolling_fric = r.f64();  // (version 1: no rrlinear, μ_r = 0)
  x.hill.fric_coef = r.f64();
  x.hill.damp_con = r.f64();
  x.hill.suction = r.f64();
  return x;
}

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Every floating-point number of a value is finite (doubles, Vec3 and the structs of doubles the stores
// hold); integers and enums always are. A saved state is never non-finite: the runner stops a run
// before it gets there (blow-up detection), so a non-finite value means a damaged file.
template <class T>
bool all_finite(const T& v) {
  if constexpr (std::is_floating_point_v<T>) {
    return std::isfinite(v);
  } else if constexpr (std::is_same_v<T, Vec3>) {
    return finite3(v);
  } else if constexpr (std::is_same_v<T, Quat>) {
    return std::isfinite(v.w) && std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  } else if constexpr (std::is_same_v<T, HillParams> || std::is_same_v<T, HillMapping> || std::is_same_v<T, LinearParams> ||
                       std::is_same_v<T, LinearMapping>) {
    static_assert(sizeof(T) % sizeof(double) == 0);
    double d[sizeof(T) / sizeof(double)];
    std::memcpy(d, &v, sizeof(T));
    for (double x : d)
      if (!std::isfinite(x)) return false;
    return true;
  } else {
    return true;
  }
}

// Column names for messages, in for_each_column / zip_columns order (a column the engine adds later
// is still written and compared; only its message says "column N").
constexpr const char* kBallColumns[] = {"id", "radius", "density", "mass", "inertia", "young_mod", "pois_ratio", "groups",
                                        "fixity", "position", "velocity", "spin", "contact_force", "contact_moment",
                                        "applied_force", "applied_moment"};
constexpr const char* kContactColumns[] = {
    "key", "image", "exists", "rule", "model", "linear_params", "hill_params", "linear_map", "hill_map", "shear_state",
    "shear_disp", "normal", "moisture", "moment_state", "gap", "force", "normal_force", "moisture_force",
    "trial_shear", "active", "k_tran", "k_shear"};

template <std::size_t N>
std::string column_name(const char* const (&names)[N], std::size_t k) {
  return k < N ? names[k] : "column " + std::to_string(k + 1);
}

// sim.clumps: every ClumpBodies column, validated against the balls read before.
void read_clumps(SectionReader r, Simulation& sim) {
  ClumpBodies c;
  std::uint32_t expected = 0;
  c.for_each_column([&](auto&) { ++expected; });
  const std::uint32_t columns = r.u32();
  if (columns != expected)
    r.fail(std::to_string(columns) + " clump columns, this build has " + std::to_string(expected) +
           " (written by an incompatible hilldem build)");
  std::size_t k = 0;
  c.for_each_column([&](auto& col) {
    const char* name = ClumpBodies::kColumnNames[k++];
    get_column(r, col, name);
    for (const auto& x : col)
      if (!all_finite(x)) r.fail(std::string("clump column '") + name + "' has a non-finite value");
  });
  r.finish();
  const std::size_t n = c.state.position.size();
  bool even = c.state.velocity.size() == n && c.state.orientation.size() == n && c.state.spin.size() == n &&
              c.state.body_momentum.size() == n && c.state.mass.size() == n && c.state.principal_inertia.size() == n &&
              c.state.fixity.size() == n && c.groups.size() == n;
  if (!even) r.fail("the clump columns have different lengths");
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& in = c.state.principal_inertia[i];
    if (!(c.state.mass[i] > 0.0 && in.x > 0.0 && in.y > 0.0 && in.z > 0.0))
      r.fail("clump " + std::to_string(i) + " has a mass or principal moment that is not positive");
    if (c.state.fixity[i] > kFixAll) r.fail("clump " + std::to_string(i) + " has fixity bits beyond the six components");
  }
  try {
    c.check(sim.balls);
  } catch (const RunError& e) {
    r.fail(e.what());
  }
  sim.clumps = std::move(c);
}

void check_contacts(SectionReader& r, const ContactStore& c, std::size_t n_balls, std::size_t n_walls, std::size_t n_rules) {
  const std::size_t n = c.size();
  std::size_t k = 0;
  ContactStore::zip_columns(c, c, [&](const auto& col, const auto&) {
    if (col.size() != n)
      r.fail("column '" + column_name(kContactColumns, k) + "' has " + std::to_string(col.size()) + " rows, 'key' has " +
             std::to_string(n));
    ++k;
  });
  for (std::size_t i = 0; i < n; ++i) {
    const ContactKey& key = c.key[i];
    const std::string row = "contact row " + std::to_string(i);
    if (key.a >= n_balls) r.fail(row + " refers to ball index " + std::to_string(key.a) + " of " + std::to_string(n_balls));
    if (key.kind == ContactKind::BallBall && (key.b >= n_balls || key.b <= key.a))
      r.fail(row + " refers to an invalid second ball index " + std::to_string(key.b));
    if (key.kind == ContactKind::BallWall && key.b >= n_walls)
      r.fail(row + " refers to wall index " + std::to_string(key.b) + " of " + std::to_string(n_walls));
    if (i > 0 && !(c.key[i - 1] < key)) r.fail(row + ": contact keys are not strictly sorted");
    if (c.image[i] > 26) r.fail(row + " has periodic image code " + std::to_string(c.image[i]));
    if (c.exists[i] > 1 || c.active[i] > 1) r.fail(row + " has a flag that is neither 0 nor 1");
    if (c.rule[i] < 0 || static_cast<std::size_t>(c.rule[i]) >= n_rules)
      r.fail(row + " refers to assignment rule " + std::to_string(c.rule[i]) + " of " + std::to_string(n_rules));
    if (static_cast<std::uint8_t>(c.model[i]) >= kModelCount) r.fail(row + " has an unknown model code");
    if (c.model[i] == ModelKind::Hill && key.kind != ContactKind::BallBall) r.fail(row + ": a hill contact with a wall");
    if (static_cast<std::uint8_t>(c.moisture[i]) > 2) r.fail(row + " has an unknown moisture state");
  }
  // Contacts hold finite numbers (rows that are only neighbour pairs may keep an infinite gap).
  std::size_t column = 0;
  ContactStore::zip_columns(c, c, [&](const auto& col, const auto&) {
    for (std::size_t i = 0; i < n; ++i)
      if (c.exists[i] && !all_finite(col[i]))
        r.fail("contact row " + std::to_string(i) + " has a non-finite '" + column_name(kContactColumns, column) + "'");
    ++column;
  });
}

}  // namespace

void write_simulation(CheckpointWriter& w, const Simulation& sim) {
  // The ball-ball neighbour rows that are not contacts are not saved (44 % of the rows of a dense
  // bed): the restore makes them again from the positions at the last rebuild, as that rebuild
  // made them (NeighbourList::restore_rows), and keeps the saved run's rebuild schedule. So no
  // rebuild is added (in a periodic box a rebuild wraps positions, and x - L rounds differently
  // from x). The contacts and the wall rows (few; the walls have moved since) are saved whole.
  // (Columns of unequal lengths, a store no engine makes, are written as they are, for the reader
  // to refuse.)
  bool even = true;
  ContactStore::zip_columns(sim.contacts, sim.contacts,
                            [&](const auto& col, const auto&) { even = even && col.size() == sim.contacts.key.size(); });
  const bool compact = even;
  {
    SectionWriter& s = w.section("sim.clock");
    s.f64(sim.time);
    s.i64(sim.steps);
    s.f64(sim.last_dt);
  }
  write_settings(w.section("sim.settings"), sim.settings);
  {
    SectionWriter& s = w.section("sim.groups");
    const auto names = group_names(sim.groups);
    s.u64(names.size());
    for (const std::string& n : names) s.str(n);
  }
  {
    SectionWriter& s = w.section("sim.table", kTableVersion);
    s.u64(sim.table.rules.size());
    for (const ModelRule& r : sim.table.rules) write_rule(s, r);
  }
  {
    SectionWriter& s = w.section("sim.balls");
    s.u64(sim.balls.size());
    std::uint32_t columns = 0;
    auto& balls = const_cast<BallStore&>(sim.balls);  // for_each_column is non-const; only read here
    balls.for_each_column([&](auto&) { ++columns; });
    s.u32(columns);
    balls.for_each_column([&](auto& col) { put_column(s, col); });
  }
  if (!sim.clumps.empty()) {
    // (Only with clumps: a checkpoint without clumps has no such section, and builds without clumps read it.)
    SectionWriter& s = w.section("sim.clumps");
    auto& clumps = const_cast<ClumpBodies&>(sim.clumps);  // for_each_column is non-const; only read here
    std::uint32_t columns = 0;
    clumps.for_each_column([&](auto&) { ++columns; });
    s.u32(columns);
    clumps.for_each_column([&](auto& col) { put_column(s, col); });
  }
  {
    SectionWriter& s = w.section("sim.walls");
    s.u64(sim.walls.size());
    for (const Wall& x : sim.walls.walls) write_wall(s, x);
  }
  {
    SectionWriter& s = w.section("sim.contacts", kContactsVersion);
    std::uint32_t columns = 0;
    ContactStore::zip_columns(sim.contacts, sim.contacts, [&](const auto&, const auto&) { ++columns; });
    s.u32(columns);
    if (compact) {
      ContactStore rows;  // the contacts and the wall rows
      for (std::size_t c = 0; c < sim.contacts.size(); ++c)
        if (sim.contacts.exists[c] || sim.contacts.key[c].kind == ContactKind::BallWall) rows.append_row(sim.contacts, c);
      ContactStore::zip_columns(rows, rows, [&](const auto& col, const auto&) { put_column(s, col); });
    } else {
      ContactStore::zip_columns(sim.contacts, sim.contacts, [&](const auto& col, const auto&) { put_column(s, col); });
    }
  }
  {
    // The cycle's bookkeeping: the restored run rebuilds its neighbour list when this one would have.
    // Version 2 adds whether the rows are complete (version 1: a compact save asked for a rebuild
    // at the first cycle and gave no positions).
    SectionWriter& s = w.section("sim.cycle", kCycleVersion);
    const CycleState cs = sim.cycle_state();
    s.boolean(cs.forces_ready);
    s.boolean(cs.rebuild_needed);
    s.i64(cs.rebuilds);
    s.u64(cs.unassigned_pairs);
    put_column(s, cs.position_at_build);
    s.f64(cs.wall_travel);
    s.boolean(!compact);
  }
  {
    SectionWriter& s = w.section("sim.info");
    s.i64(sim.rebuilds());
    s.u64(sim.unassigned_pairs());
    s.u64(sim.contact_count());
  }
}

void read_simulation(const CheckpointReader& cr, Simulation& out, bool prepare_to_cycle) {
  Simulation sim;
  {
    SectionReader r = cr.section("sim.clock");
    sim.time = r.f64();
    sim.steps = r.i64();
    sim.last_dt = r.f64();
    r.finish();
    if (!std::isfinite(sim.time) || sim.steps < 0 || !std::isfinite(sim.last_dt) || sim.last_dt < 0.0)
      r.fail("time, steps or last time step out of range");
  }
  {
    SectionReader r = cr.section("sim.settings");
    sim.settings = read_settings(r);
  }
  {
    SectionReader r = cr.section("sim.groups");
    const std::uint64_t n = r.count(8, 64);
    for (std::uint64_t k = 0; k < n; ++k) {
      const std::string name = r.str(4096);
      if (sim.groups.find(name)) r.fail("group '" + name + "' is listed twice");
      sim.groups.bit(name);
    }
    r.finish();
  }
  {
    SectionReader r = cr.section("sim.table", kTableVersion);
    const std::uint64_t n = r.count(32, 32767);
    for (std::uint64_t k = 0; k < n; ++k) sim.table.rules.push_back(read_rule(r));
    r.finish();
  }
  {
    // First pass: the columns into a scratch store, to validate them and create each ball (which
    // builds the id index); second pass: every column as saved.
    SectionReader r = cr.section("sim.balls");
    const std::uint64_t n = r.count(0, kMaxBalls);
    std::uint32_t expected = 0;
    sim.balls.for_each_column([&](auto&) { ++expected; });
    const std::uint32_t columns = r.u32();
    if (columns != expected)
      r.fail(std::to_string(columns) + " ball columns, this build has " + std::to_string(expected) +
             " (written by an incompatible hilldem build)");
    BallStore scratch;
    std::size_t k = 0;
    scratch.for_each_column([&](auto& col) {
      get_column(r, col, column_name(kBallColumns, k).c_str());
      if (col.size() != n) r.fail("ball column '" + column_name(kBallColumns, k) + "' has the wrong length");
      for (std::size_t i = 0; i < col.size(); ++i)
        if (!all_finite(col[i]))
          r.fail("ball " + std::to_string(scratch.id.size() > i ? scratch.id[i] : 0) + " has a non-finite '" +
                 column_name(kBallColumns, k) + "'");
      ++k;
    });
    r.finish();
    std::set<std::int64_t> ids;
    const std::uint64_t known_groups = [&] {
      std::uint64_t m = 0;
      for (std::size_t g = 0; g < group_names(sim.groups).size(); ++g) m |= std::uint64_t{1} << g;
      return m;
    }();
    for (std::size_t i = 0; i < n; ++i) {
      const std::string ball = "ball " + std::to_string(scratch.id[i]);
      if (!ids.insert(scratch.id[i]).second) r.fail(ball + " appears twice");
      if (!(scratch.radius[i] > 0.0 && std::isfinite(scratch.radius[i]))) r.fail(ball + " has a radius that is not positive and finite");
      if (!(scratch.mass[i] > 0.0 && std::isfinite(scratch.mass[i]) && scratch.inertia[i] > 0.0 && std::isfinite(scratch.inertia[i])))
        r.fail(ball + " has a mass or inertia that is not positive and finite");
      if (scratch.fixity[i] > kFixAll) r.fail(ball + " has fixity bits beyond the six components");
      if (scratch.groups[i] & ~known_groups) r.fail(ball + " is in a group that is not defined");
      BallInit b;
      b.id = scratch.id[i];
      b.position = scratch.position[i];
      b.radius = scratch.radius[i];
      b.density = scratch.density[i];
      b.young_mod = scratch.young_mod[i];
      b.pois_ratio = scratch.pois_ratio[i];
      b.velocity = scratch.velocity[i];
      b.spin = scratch.spin[i];
      b.fixity = scratch.fixity[i];
      b.groups = scratch.groups[i];
      sim.balls.add(b);
    }
    SectionReader again = cr.section("sim.balls");
    again.u64();
    again.u32();
    k = 0;
    sim.balls.for_each_column([&](auto& col) { get_column(again, col, column_name(kBallColumns, k++).c_str()); });
  }
  if (cr.has("sim.clumps")) read_clumps(cr.section("sim.clumps"), sim);
  {
    SectionReader r = cr.section("sim.walls");
    const std::uint64_t n = r.count(8, kMaxWalls);
    std::set<std::string> names;
    for (std::uint64_t k = 0; k < n; ++k) {
      Wall x = read_wall(r);
      if (x.name.empty() || !names.insert(x.name).second) r.fail("wall name '" + x.name + "' is empty or used twice");
      if (x.shape == WallShape::Cylinder && !(x.radius > 0.0)) r.fail("cylinder wall '" + x.name + "' has no positive radius");
      const bool finite = finite3(x.point) && finite3(x.normal) && finite3(x.vertex[0]) && finite3(x.vertex[1]) &&
                          finite3(x.vertex[2]) && std::isfinite(x.radius) && std::isfinite(x.lo) && std::isfinite(x.hi) &&
                          finite3(x.velocity) && finite3(x.spin) && finite3(x.rotation_center) &&
                          std::isfinite(x.radial_velocity) && finite3(x.force) && finite3(x.moment) &&
                          std::isfinite(x.normal_force) && std::isfinite(x.normal_stiffness);
      if (!finite) r.fail("wall '" + x.name + "' has a non-finite position, velocity or force");
      sim.walls.add(std::move(x));
    }
    r.finish();
  }
  {
    SectionReader r = cr.section("sim.contacts", kContactsVersion);
    // (Version 1, before rrlinear, had no moment_state column.)
    if (r.version() < kContactsVersion)
      r.fail("contacts of section version " + std::to_string(r.version()) +
             ", written by an older hilldem build: resume it with that build");
    std::uint32_t expected = 0;
    ContactStore::zip_columns(sim.contacts, sim.contacts, [&](auto&, auto&) { ++expected; });
    const std::uint32_t columns = r.u32();
    if (columns != expected)
      r.fail(std::to_string(columns) + " contact columns, this build has " + std::to_string(expected) +
             " (written by an incompatible hilldem build)");
    std::size_t k = 0;
    ContactStore::zip_columns(sim.contacts, sim.contacts,
                              [&](auto& col, auto&) { get_column(r, col, column_name(kContactColumns, k++).c_str()); });
    r.finish();
    check_contacts(r, sim.contacts, sim.balls.size(), sim.walls.size(), sim.table.rules.size());
  }

  std::optional<CycleState> cycle;
  if (cr.has("sim.cycle")) {
    SectionReader r = cr.section("sim.cycle", kCycleVersion);
    CycleState cs;
    cs.forces_ready = r.boolean();
    cs.rebuild_needed = r.boolean();
    cs.rebuilds = r.i64();
    cs.unassigned_pairs = r.u64();
    get_column(r, cs.position_at_build, "position_at_build");
    cs.wall_travel = r.f64();
    cs.rows_complete = r.version() < 2 || r.boolean();  // (version 1: every row, or a rebuild asked for)
    r.finish();
    if (cs.rebuilds < 0) r.fail("negative rebuild count " + std::to_string(cs.rebuilds));
    if (!cs.position_at_build.empty() && cs.position_at_build.size() != sim.balls.size())
      r.fail("positions at the last rebuild for " + std::to_string(cs.position_at_build.size()) + " balls, the state has " +
             std::to_string(sim.balls.size()));
    for (const Vec3& x : cs.position_at_build)
      if (!finite3(x)) r.fail("a non-finite position at the last rebuild");
    if (!(cs.wall_travel >= 0) || !std::isfinite(cs.wall_travel)) r.fail("wall travel must be finite and >= 0");
    cycle = std::move(cs);
  }

  if (prepare_to_cycle && cycle) {
    // Exact: the saved rows, ball columns and walls as they are, the row lists rebuilt from the rows,
    // and the next rebuild at the step the saved run would have made it.
    try {
      sim.restore_cycle_state(std::move(*cycle));
    } catch (const RunError& e) {
      throw InputError(cr.source() + ": the saved state cannot be cycled: " + e.what());
    }
  } else if (prepare_to_cycle) {
    // A checkpoint without the cycle section (written before it existed). Detect contacts and
    // compute forces once (this marks the forces as ready and builds the per-ball row lists), then
    // put back everything saved: the restored rows by key, the balls, the walls' sums.
    const BallStore balls = sim.balls;
    const WallStore walls = sim.walls;
    const ContactStore saved = sim.contacts;
    try {
      sim.update_forces();
    } catch (const RunError& e) {
      throw InputError(cr.source() + ": the saved state cannot be cycled: " + e.what());
    }
    ContactStore& cur = sim.contacts;
    for (std::size_t row = 0; row < cur.size(); ++row) {
      const long s = saved.find(cur.key[row]);
      if (s >= 0) {
        const auto from = static_cast<std::size_t>(s);
        ContactStore::zip_columns(cur, saved, [&](auto& dst, const auto& src) { dst[row] = src[from]; });
      } else if (cur.exists[row]) {
        cur.remove(row);  // not a contact when the checkpoint was written: it is created by the next cycle
      }
    }
    sim.balls = balls;
    sim.walls = walls;
  }
  out = std::move(sim);
}

void write_servo(SectionWriter& w, const Servo& servo) {
  w.f64(servo.settings.target_stress);
  w.f64(servo.settings.gain_factor);
  w.f64(servo.settings.max_speed);
  w.boolean(servo.enabled);
  w.f64(servo.speed());
}

void read_servo(SectionReader& r, Servo& servo) {
  ServoSettings s;
  s.target_stress = r.f64();
  s.gain_factor = r.f64();
  s.max_speed = r.f64();
  const bool enabled = r.boolean();
  r.f64();  // the last speed (informational)
  if (!std::isfinite(s.target_stress) || !(s.gain_factor > 0.0 && s.gain_factor <= 1.0) ||
      !(s.max_speed > 0.0 && std::isfinite(s.max_speed)))
    r.fail("servo settings out of range (target stress finite, gain factor in (0, 1], max speed > 0)");
  servo.settings = s;
  servo.enabled = enabled;
}

namespace {

struct Part {
  std::string label;
  std::string bytes;
};

std::vector<Part> state_parts(const Simulation& sim) {
  std::vector<Part> parts;
  {
    SectionWriter s;
    s.f64(sim.time);
    s.i64(sim.steps);
    s.f64(sim.last_dt);
    parts.push_back({"clock (time, steps, last_dt)", s.bytes()});
  }
  {
    SectionWriter s;
    write_settings(s, sim.settings);
    parts.push_back({"settings", s.bytes()});
  }
  std::size_t k = 0;
  auto& balls = const_cast<BallStore&>(sim.balls);  // for_each_column is non-const; only read here
  balls.for_each_column([&](auto& col) {
    SectionWriter s;
    put_column(s, col);
    parts.push_back({"ball column '" + column_name(kBallColumns, k++) + "'", s.bytes()});
  });
  if (!sim.clumps.empty()) {
    k = 0;
    auto& clumps = const_cast<ClumpBodies&>(sim.clumps);  // only read here
    clumps.for_each_column([&](auto& col) {
      SectionWriter s;
      put_column(s, col);
      parts.push_back({std::string("clump column '") + ClumpBodies::kColumnNames[k++] + "'", s.bytes()});
    });
  }
  for (const Wall& w : sim.walls.walls) {
    SectionWriter s;
    write_wall(s, w);
    parts.push_back({"wall '" + w.name + "'", s.bytes()});
  }
  // Existing contacts only, every column.
  std::vector<std::size_t> rows;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.exists[c]) rows.push_back(c);
  k = 0;
  ContactStore::zip_columns(sim.contacts, sim.contacts, [&](const auto& col, const auto&) {
    using T = typename std::decay_t<decltype(col)>::value_type;
    std::vector<T> picked;
    picked.reserve(rows.size());
    for (std::size_t c : rows) picked.push_back(col[c]);
    SectionWriter s;
    put_column(s, picked);
    parts.push_back({"contact column '" + column_name(kContactColumns, k++) + "'", s.bytes()});
  });
  return parts;
}

}  // namespace

std::string state_bytes(const Simulation& sim) {
  std::string out;
  for (const Part& p : state_parts(sim)) {
    out += p.label;
    out += p.bytes;
  }
  return out;
}

std::string state_digest(const Simulation& sim) {
  // FNV-1a over state_bytes, part by part (the same bytes in the same order, without concatenating them).
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const std::string& bytes) {
    for (unsigned char ch : bytes) {
      h ^= ch;
      h *= 1099511628211ull;
    }
  };
  for (const Part& p : state_parts(sim)) {
    mix(p.label);
    mix(p.bytes);
  }
  return fmt::format("{:016x}", h);
}

std::string state_difference(const Simulation& a, const Simulation& b) {
  const auto pa = state_parts(a), pb = state_parts(b);
  if (pa.size() != pb.size())
    return fmt::format("different numbers of walls or columns ({} vs {})", pa.size(), pb.size());
  for (std::size_t k = 0; k < pa.size(); ++k) {
    if (pa[k].label != pb[k].label) return "different parts: " + pa[k].label + " vs " + pb[k].label;
    if (pa[k].bytes != pb[k].bytes) {
      std::size_t at = 0;
      while (at < pa[k].bytes.size() && at < pb[k].bytes.size() && pa[k].bytes[at] == pb[k].bytes[at]) ++at;
      return fmt::format("{} differs (sizes {} and {} bytes, first difference at byte {})", pa[k].label,
                         pa[k].bytes.size(), pb[k].bytes.size(), at);
    }
  }
  return "";
}

double state_memory_estimate(std::size_t balls, std::size_t rows) {
  std::size_t per_ball = 0, per_row = 0;
  BallStore b;
  b.for_each_column([&](auto& c) { per_ball += sizeof(typename std::decay_t<decltype(c)>::value_type); });
  ContactStore c;
  ContactStore::zip_columns(c, c, [&](auto& col, auto&) { per_row += sizeof(typename std::decay_t<decltype(col)>::value_type); });
  return 2.0 * (static_cast<double>(balls) * static_cast<double>(per_ball) + static_cast<double>(rows) * static_cast<double>(per_row));
}

}  // namespace hilldem
