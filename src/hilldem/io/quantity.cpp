#include "hilldem/io/quantity.hpp"

#include <cmath>
#include <limits>

namespace hilldem {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct FieldInfo {
  const char* name;
  const char* unit;
};
// prefix "sim." / "ball." / "wall." / "contact."
constexpr FieldInfo kSimFields[] = {{"time", "s"}, {"step", "-"}, {"timestep", "s"}, {"contacts", "-"},
                                    {"active_contacts", "-"}, {"wet_contacts", "-"}, {"unbalanced_ratio", "-"},
                                    {"kinetic_energy", "J"}};
constexpr FieldInfo kBallFields[] = {
    {"pos_x", "m"}, {"pos_y", "m"}, {"pos_z", "m"}, {"vel_x", "m/s"}, {"vel_y", "m/s"}, {"vel_z", "m/s"},
    {"spin_x", "rad/s"}, {"spin_y", "rad/s"}, {"spin_z", "rad/s"}, {"force_x", "N"}, {"force_y", "N"},
    {"force_z", "N"}, {"contact_force_x", "N"}, {"contact_force_y", "N"}, {"contact_force_z", "N"},
    {"radius", "m"}, {"mass", "kg"}};
constexpr FieldInfo kWallFields[] = {{"force_x", "N"}, {"force_y", "N"}, {"force_z", "N"}, {"force", "N"},
                                     {"moment_x", "N m"}, {"moment_y", "N m"}, {"moment_z", "N m"},
                                     {"pos_x", "m"}, {"pos_y", "m"}, {"pos_z", "m"}, {"radius", "m"}};
constexpr FieldInfo kContactFields[] = {
    {"exists", "-"}, {"active", "-"}, {"mois_state", "-"}, {"gap", "m"}, {"overlap", "m"},
    {"normal_force", "N"}, {"moisture_force", "N"}, {"shear_force", "N"}, {"trial_shear", "N"},
    {"force_x", "N"}, {"force_y", "N"}, {"force_z", "N"}, {"shear_x", "N"}, {"shear_y", "N"}, {"shear_z", "N"},
    {"shear_disp", "m"}, {"kn", "N/m or N/m^1.5"}, {"ks", "N/m or N/m^1.5"}, {"bn", "kg/(m^0.25 s)"},
    {"bs", "kg/(m^0.25 s)"}, {"eff_radius", "m"}, {"eff_young", "Pa"}, {"eff_shear", "Pa"}, {"eff_mass", "kg"},
    {"suction", "Pa"}, {"fric_coef", "-"}, {"damp_con", "-"}};

template <std::size_t N>
const FieldInfo* lookup(const FieldInfo (&fields)[N], const std::string& f) {
  for (const auto& fi : fields)
    if (f == fi.name) return &fi;
  return nullptr;
}
template <std::size_t N>
std::string names(const char* prefix, const FieldInfo (&fields)[N]) {
  std::string s;
  for (const auto& fi : fields) s += std::string(s.empty() ? "" : ", ") + prefix + fi.name + " [" + fi.unit + "]";
  return s;
}
int axis_of(const std::string& f) { return f.back() - 'x'; }
}  // namespace

std::string quantity_catalogue() {
  return names("sim.", kSimFields) + "\n" + names("ball.", kBallFields) + "\n" + names("wall.", kWallFields) +
         "\n" + names("contact.", kContactFields);
}

Quantity read_quantity(TableReader& t, const SimulationDescription& sim) {
  Quantity q;
  q.name = t.string("quantity", std::nullopt);
  const auto dot = q.name.find('.');
  const std::string prefix = dot == std::string::npos ? "" : q.name.substr(0, dot);
  q.field = dot == std::string::npos ? q.name : q.name.substr(dot + 1);
  const FieldInfo* info = nullptr;
  if (prefix == "sim") info = lookup(kSimFields, q.field);
  else if (prefix == "ball") info = lookup(kBallFields, q.field);
  else if (prefix == "wall") info = lookup(kWallFields, q.field);
  else if (prefix == "contact") info = lookup(kContactFields, q.field);
  if (!info) t.fail("quantity", "unknown quantity \"" + q.name + "\"; known:\n" + quantity_catalogue());
  q.unit = info->unit;

  auto ball_id = [&](const std::string& key, std::int64_t id) {
    if (!sim.has_ball_id(id)) t.fail(key, "no ball or pebble with id " + std::to_string(id));
    return id;
  };
  auto read_walls = [&] {
    const std::string w = t.string("wall", std::nullopt);
    q.walls = sim.walls_named(w);
    if (q.walls.empty()) t.fail("wall", "no wall named or grouped \"" + w + "\"");
    return w;
  };
  if (prefix == "sim") {
    q.target = QuantityTarget::Global;
    q.target_text = "simulation";
  } else if (prefix == "ball") {
    q.target = QuantityTarget::Ball;
    q.ball = ball_id("ball", t.integer("ball", std::nullopt, INT64_MIN, INT64_MAX));
    q.target_text = "ball " + std::to_string(q.ball);
  } else if (prefix == "wall") {
    q.target = QuantityTarget::Wall;
    q.target_text = "wall " + read_walls();
  } else if (t.has("balls")) {
    const auto ids = t.integers("balls");
    if (ids.size() != 2 || ids[0] == ids[1]) t.fail("balls", "must be two different ball ids [id1, id2]");
    q.target = QuantityTarget::BallBall;
    q.ball = ball_id("balls", ids[0]);
    q.ball2 = ball_id("balls", ids[1]);
    q.target_text = "balls " + std::to_string(q.ball) + "-" + std::to_string(q.ball2);
  } else {
    if (!t.has("ball") || !t.has("wall"))
      t.fail("quantity", "a contact quantity needs balls = [id1, id2], or ball = id with wall = \"name\"");
    q.target = QuantityTarget::BallWall;
    q.ball = ball_id("ball", t.integer("ball", std::nullopt, INT64_MIN, INT64_MAX));
    const std::string w = read_walls();
    if (q.walls.size() != 1) t.fail("wall", "a contact quantity needs exactly one wall; \"" + w + "\" selects several");
    q.target_text = "ball " + std::to_string(q.ball) + " - wall " + w;
  }
  return q;
}

namespace {
double sim_value(const Simulation& s, const std::string& f) {
  if (f == "time") return s.time;
  if (f == "step") return static_cast<double>(s.steps);
  if (f == "timestep") return s.last_dt;
  if (f == "contacts") return static_cast<double>(s.contact_count());
  if (f == "unbalanced_ratio") return s.mean_unbalanced_ratio();
  if (f == "kinetic_energy") {
    double e = 0.0;
    for (std::size_t i = 0; i < s.balls.size(); ++i)
      e += 0.5 * s.balls.mass[i] * norm2(s.balls.velocity[i]) + 0.5 * s.balls.inertia[i] * norm2(s.balls.spin[i]);
    return e;
  }
  double n = 0.0;
  for (std::size_t c = 0; c < s.contacts.size(); ++c) {
    if (f == "active_contacts") n += s.contacts.active[c];
    if (f == "wet_contacts") n += s.contacts.exists[c] && s.contacts.moisture[c] == Moisture::Wet;
  }
  return n;
}

double ball_value(const Simulation& s, std::size_t i, const std::string& f) {
  const BallStore& b = s.balls;
  if (f == "radius") return b.radius[i];
  if (f == "mass") return b.mass[i];
  const int d = axis_of(f);
  if (f.rfind("pos_", 0) == 0) return b.position[i][d];
  if (f.rfind("vel_", 0) == 0) return b.velocity[i][d];
  if (f.rfind("spin_", 0) == 0) return b.spin[i][d];
  if (f.rfind("force_", 0) == 0) return unbalanced_force(b, i, s.settings.gravity)[d];
  return b.contact_force[i][d];  // contact_force_*
}

double wall_value(const Simulation& s, const Quantity& q) {
  Vec3 force, moment;
  for (std::size_t k : q.walls) {
    force += s.walls.walls[k].force;
    moment += s.walls.walls[k].moment;
  }
  const Wall& w = s.walls.walls[q.walls.front()];
  const std::string& f = q.field;
  if (f == "force") return norm(force);
  if (f == "radius") return w.radius;
  const int d = axis_of(f);
  if (f.rfind("force_", 0) == 0) return force[d];
  if (f.rfind("moment_", 0) == 0) return moment[d];
  return w.point[d];  // pos_*
}

double contact_value(const Simulation& s, long c, const std::string& f) {
  if (f == "exists") return c >= 0 ? 1.0 : 0.0;
  if (c < 0) return kNaN;
  const ContactStore& k = s.contacts;
  const bool hill = k.model[c] == ModelKind::Hill;
  const HillMapping& h = k.hill_map[c];
  if (f == "active") return k.active[c];
  if (f == "mois_state") return static_cast<double>(k.moisture[c]);
  if (f == "gap") return k.gap[c];
  if (f == "overlap") return -k.gap[c];
  if (f == "normal_force") return k.normal_force[c];
  if (f == "moisture_force") return k.moisture_force[c];
  if (f == "shear_force") return norm(k.shear_force(c));
  if (f == "trial_shear") return k.trial_shear[c];
  if (f == "shear_disp") return norm(k.shear_disp[c]);
  if (f == "kn") return hill ? h.kn : k.linear_map[c].kn;
  if (f == "ks") return hill ? h.ks : k.linear_map[c].ks;
  if (f == "fric_coef") return hill ? k.hill_params[c].fric_coef : k.linear_params[c].fric;
  if (f.rfind("force_", 0) == 0) return k.force[c][axis_of(f)];
  if (f.rfind("shear_", 0) == 0 && f.size() == 7) return k.shear_force(c)[axis_of(f)];
  if (!hill) return kNaN;  // the rest are hill quantities
  if (f == "bn") return h.bn;
  if (f == "bs") return h.bs;
  if (f == "eff_radius") return h.eff_radius;
  if (f == "eff_young") return h.eff_young;
  if (f == "eff_shear") return h.eff_shear;
  if (f == "eff_mass") return h.eff_mass;
  if (f == "suction") return k.hill_params[c].suction;
  return k.hill_params[c].damp_con;  // damp_con
}
}  // namespace

double evaluate(const Simulation& sim, const Quantity& q) {
  switch (q.target) {
    case QuantityTarget::Global: return sim_value(sim, q.field);
    case QuantityTarget::Ball: return ball_value(sim, static_cast<std::size_t>(sim.balls.find(q.ball)), q.field);
    case QuantityTarget::Wall: return wall_value(sim, q);
    case QuantityTarget::BallBall: return contact_value(sim, sim.find_ball_ball(q.ball, q.ball2), q.field);
    case QuantityTarget::BallWall: return contact_value(sim, sim.find_ball_wall(q.ball, q.walls.front()), q.field);
  }
  return kNaN;
}

}  // namespace hilldem
