#include "hilldem/labtests/specimen_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {
constexpr const char* kMagic = "hilldem-specimen";
constexpr int kVersion = 1;

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}
}  // namespace

namespace {
// Every pair of grains (or pebbles of different clumps) on a grid of cells one largest diameter wide:
// overlaps beyond kMaxOverlap of the smaller diameter, or two at one centre, refuse the file.
template <class Row>
void check_overlaps(const std::vector<Row>& rows, const std::string& source) {
  if (rows.empty()) return;
  double r_max = 0.0;
  for (const Row& r : rows) r_max = std::max(r_max, r.v[3]);
  const double cell = 2.0 * r_max;
  auto key = [&](double a) { return static_cast<std::int64_t>(std::floor(a / cell)); };
  std::map<std::array<std::int64_t, 3>, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < rows.size(); ++i) grid[{key(rows[i].v[0]), key(rows[i].v[1]), key(rows[i].v[2])}].push_back(i);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& a = rows[i];
    const std::array<std::int64_t, 3> c{key(a.v[0]), key(a.v[1]), key(a.v[2])};
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == grid.end()) continue;
          for (std::size_t j : it->second) {
            if (j <= i) continue;
            const Row& b = rows[j];
            if (a.body == b.body) continue;  // pebbles of one clump overlap by design
            const double d = std::sqrt((a.v[0] - b.v[0]) * (a.v[0] - b.v[0]) + (a.v[1] - b.v[1]) * (a.v[1] - b.v[1]) +
                                       (a.v[2] - b.v[2]) * (a.v[2] - b.v[2]));
            const double d_small = 2.0 * std::min(a.v[3], b.v[3]);
            const int first = std::min(a.line, b.line), second = std::max(a.line, b.line);
            const std::int64_t id1 = a.line < b.line ? a.id : b.id, id2 = a.line < b.line ? b.id : a.id;
            if (d <= 1e-9 * d_small)
              throw InputError(fmt::format("{}:{}: grains {} and {} (line {}) have one centre", source, second, id1, id2, first));
            const double overlap = a.v[3] + b.v[3] - d;
            if (overlap > kMaxOverlap * d_small)
              throw InputError(fmt::format("{}:{}: grains {} and {} (line {}) overlap by {:.4g} mm, {:.3g} % of the smaller diameter; "
                                           "at most {:g} % is a packed state",
                                           source, second, id1, id2, first, overlap * 1e3, 100 * overlap / d_small,
                                           100 * kMaxOverlap));
          }
        }
  }
}
}  // namespace

std::string packed_specimen_text(const Specimen& s, const PackingSettings& p) {
  if (s.material != "packed" || s.wet)
    throw InputError("only a packed specimen (before finalization) can be saved: its state is exact without contact history");
  const Simulation& sim = s.sim;
  std::string out;
  out += "# hilldem packed specimen: frictionless packing by boundary contraction; positions, radii and grain\n";
  out += "# properties reproduce every contact force of the packing contacts. `hilldem triaxial --specimen FILE` starts here.\n";
  out += fmt::format("format,{},{}\n", kMagic, kVersion);
  out += fmt::format("grading,{}\n", s.grading);
  out += fmt::format("d_mult,{}\n", s.d_mult);
  out += fmt::format("seed,{}\n", s.seed);
  out += fmt::format("pressure[Pa],{}\n", s.pressure);
  out += fmt::format("local_damping,{}\n", sim.settings.local_damping);
  out += fmt::format("vessel_radius[m],{}\n", s.vessel.radius(sim));
  out += fmt::format("vessel_bottom[m],{}\n", s.vessel.bottom_z(sim));
  out += fmt::format("vessel_top[m],{}\n", s.vessel.top_z(sim));
  out += fmt::format("packing_model,{}\n", to_string(s.packed_with));
  out += fmt::format("packing_damp_con,{}\n", p.contact.damp_con);
  out += fmt::format("packing_emod[Pa],{}\n", p.contact.emod);
  out += fmt::format("packing_kratio,{}\n", p.contact.kratio);
  out += fmt::format("packing_fric,{}\n", p.contact.fric);
  out += fmt::format("wall_emod[Pa],{}\n", p.walls.emod);
  out += fmt::format("wall_kratio,{}\n", p.walls.kratio);
  if (!s.clump_mix.empty()) {
    // The mix (clump_mix_text: a template's name, or NAME:FRACTION,... with the fractions genesis
    // aimed at), then a clump row: its first pebble's ball id (the others follow), its template,
    // centre of mass, orientation (the principal frame's, a unit quaternion), the factor its unit
    // template (pebbles of radius 1) is scaled by, and its pebbles' properties. Every number is
    // written to round trip exactly.
    const ClumpBodies& c = sim.clumps;
    if (grain_count(sim) != c.size()) throw InputError("a specimen of clumps and balls together cannot be saved");
    if (s.clump_kind.size() != c.size()) throw InputError("the specimen's clumps and their templates do not match");
    out += fmt::format("clump_template,{}\n", clump_mix_text(s.clump_mix));
    out += fmt::format("clump_size,{}\n", s.clump_size == SizeMeasure::EnclosingDiameter ? "enclosing" : "equal-volume");
    out += fmt::format("grains,{}\n", c.size());
    out += "id,template,x[m],y[m],z[m],qw,qx,qy,qz,scale[m],density[kg/m3],young_mod[Pa],pois_ratio[-]\n";
    std::vector<std::size_t> first(c.size(), c.pebbles.size());
    for (std::size_t k = c.pebbles.size(); k-- > 0;) first[c.pebbles.clump[k]] = k;
    for (std::size_t i = 0; i < c.size(); ++i) {
      const std::uint32_t b = c.ball[first[i]];
      const Vec3& x = c.state.position[i];
      const Quat& q = c.state.orientation[i];
      out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{}\n", sim.balls.id[b], s.clump_mix[s.clump_kind[i]].first, x.x, x.y,
                         x.z, q.w, q.x, q.y, q.z,
                         c.pebbles.radius[first[i]], sim.balls.density[b], sim.balls.young_mod[b], sim.balls.pois_ratio[b]);
    }
    return out;
  }
  out += fmt::format("grains,{}\n", sim.balls.size());
  out += "id,x[m],y[m],z[m],radius[m],density[kg/m3],young_mod[Pa],pois_ratio[-]\n";
  for (std::size_t i = 0; i < sim.balls.size(); ++i) {
    const Vec3& x = sim.balls.position[i];
    out += fmt::format("{},{},{},{},{},{},{},{}\n", sim.balls.id[i], x.x, x.y, x.z,
                       sim.balls.radius[i], sim.balls.density[i], sim.balls.young_mod[i], sim.balls.pois_ratio[i]);
  }
  return out;
}

void save_packed_specimen(const Specimen& s, const PackingSettings& p, const std::string& path) {
  const std::string text = packed_specimen_text(s, p);
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw RunError(path + ": cannot write the specimen");
}

Specimen parse_packed_specimen(const std::string& text, const std::string& source, PackingSettings* p_out) {
  std::istringstream in(text);
  std::string line;
  int lineno = 0;
  std::map<std::string, std::pair<std::string, int>> keys;
  auto fail = [&](int at, const std::string& what) { return InputError(fmt::format("{}:{}: {}", source, at, what)); };
  bool header = false;
  struct Row {
    std::int64_t id;
    double v[11];
    int line;
    std::size_t body;
    std::uint32_t kind;  // a clump's template: its index in the mix
  };
  // A clump file has its mix before the table (clump_template) and clump rows, each naming its
  // template (files written before mixes have no template column: every clump is the one template's).
  bool clump_file = false, template_column = false;
  ClumpMix mix;
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    ++lineno;
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) cells.push_back(trim(c));
    if (!header) {
      if (keys.empty() && cells[0] != "format")
        throw fail(lineno, fmt::format("not a hilldem specimen file: the first line must be `format,{},{}`", kMagic, kVersion));
      if (cells.size() >= 1 && cells[0] == "id") {
        header = true;
        clump_file = keys.count("clump_template") > 0;
        if (clump_file) {
          const auto& [text, at] = keys["clump_template"];
          try {
            mix = parse_clump_mix(text, "clump_template");
            check_clump_mix(mix, "clump_template");
          } catch (const InputError& e) {
            throw fail(at, e.what());
          }
          if (mix.empty()) throw fail(at, "clump_template names no template");
          template_column = cells.size() == 13 && cells[1] == "template";
          if (!template_column && !(cells.size() == 12 && mix.size() == 1))
            throw fail(lineno, "expected the header id,template,x[m],y[m],z[m],qw,qx,qy,qz,scale[m],density[kg/m3],young_mod[Pa],"
                               "pois_ratio[-]");
        }
        if (!clump_file && cells.size() != 8)
          throw fail(lineno, "expected the header id,x[m],y[m],z[m],radius[m],density[kg/m3],young_mod[Pa],pois_ratio[-]");
        continue;
      }
      if (cells.size() < 2) throw fail(lineno, "expected `key,value`, got '" + line + "'");
      if (keys.count(cells[0])) throw fail(lineno, "duplicate key '" + cells[0] + "'");
      // The value is the rest of the line (format's is "hilldem-specimen,1"; a mix's has commas).
      std::string value = cells[1];
      for (std::size_t k = 2; k < cells.size(); ++k) value += "," + cells[k];
      keys[cells[0]] = {value, lineno};
      continue;
    }
    const std::size_t columns = clump_file ? 12 : 8;
    if (cells.size() != columns + template_column)
      throw fail(lineno, fmt::format("expected {} values, got {}", columns + template_column, cells.size()));
    Row r{};
    if (template_column) {
      const auto it = std::find_if(mix.begin(), mix.end(), [&](const auto& m) { return m.first == cells[1]; });
      if (it == mix.end())
        throw fail(lineno, fmt::format("clump {}: template '{}' is not in the file's clump_template ({})", cells[0], cells[1],
                                       clump_mix_text(mix)));
      r.kind = static_cast<std::uint32_t>(it - mix.begin());
      cells.erase(cells.begin() + 1);
    }
    r.line = lineno;
    r.body = rows.size();
    char* end = nullptr;
    r.id = std::strtoll(cells[0].c_str(), &end, 10);
    if (cells[0].empty() || *end != '\0' || r.id < 0) throw fail(lineno, "bad ball id '" + cells[0] + "'");
    for (std::size_t k = 0; k + 1 < columns; ++k) {
      r.v[k] = std::strtod(cells[k + 1].c_str(), &end);
      if (cells[k + 1].empty() || *end != '\0' || !std::isfinite(r.v[k])) throw fail(lineno, "bad number '" + cells[k + 1] + "'");
    }
    struct Range {
      const char* column;
      double lo, hi;
      bool lo_open;
    };
    const Range ranges[] = {{clump_file ? "scale[m]" : "radius[m]", kMinGrainRadius, kMaxGrainRadius, false},
                                       {"density[kg/m3]", kMinGrainDensity, kMaxGrainDensity, false},
                                       {"young_mod[Pa]", kMinGrainModulus, kMaxGrainModulus, false},
                                       {"pois_ratio[-]", kMinPoisson, kMaxPoisson, true}};
    const int first_property = clump_file ? 7 : 3;  // scale (or radius), density, E, ν
    for (int k = 0; k < 4; ++k) {
      const Range& g = ranges[k];
      const double x = r.v[k + first_property];
      if ((g.lo_open ? x <= g.lo : x < g.lo) || x > g.hi)
        throw fail(lineno, fmt::format("grain {}: {} must be in {}{:g}, {:g}], got {:g}", r.id, g.column, g.lo_open ? "(" : "[", g.lo,
                                       g.hi, x));
    }
    if (clump_file) {
      const double q2 = r.v[3] * r.v[3] + r.v[4] * r.v[4] + r.v[5] * r.v[5] + r.v[6] * r.v[6];
      if (std::abs(q2 - 1.0) > 1e-9)
        throw fail(lineno, fmt::format("clump {}: the orientation (qw, qx, qy, qz) must be a unit quaternion, got |q|^2 = {:.12g}", r.id, q2));
    }
    rows.push_back(r);
  }
  auto get = [&](const std::string& k) -> std::pair<std::string, int> {
    auto it = keys.find(k);
    if (it == keys.end()) throw InputError(fmt::format("{}: missing key '{}' (not a hilldem specimen file?)", source, k));
    return it->second;
  };
  auto number = [&](const std::string& k, bool positive) {
    const auto [v, at] = get(k);
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(x) || (positive && x <= 0) || x < 0)
      throw fail(at, fmt::format("{} must be a number {}, got '{}'", k, positive ? "> 0" : ">= 0", v));
    return x;
  };
  if (get("format").first != fmt::format("{},{}", kMagic, kVersion))
    throw fail(get("format").second, fmt::format("unsupported format '{}' (expected {},{})", get("format").first, kMagic, kVersion));
  if (!header) throw InputError(source + ": no grain table (header id,x[m],...)");
  const double count = number("grains", false);
  if (static_cast<double>(rows.size()) != count)
    throw InputError(fmt::format("{}: {} grain rows but grains = {:g}", source, rows.size(), count));

  Specimen s;
  s.grading = get("grading").first;
  s.d_mult = number("d_mult", true);
  s.seed = static_cast<std::uint64_t>(number("seed", false));
  s.pressure = number("pressure[Pa]", true);
  PackingSettings p;
  // packing_model and packing_damp_con are absent from the files written before each material was
  // packed with its own model: those specimens were packed with linear contacts.
  p.contact.model = GrainModel::Linear;
  if (keys.count("packing_model")) {
    const auto [m, at] = get("packing_model");
    if (m == "hill") p.contact.model = GrainModel::Hill;
    else if (m != "linear") throw fail(at, "packing_model must be linear or hill, got '" + m + "'");
  }
  if (keys.count("packing_damp_con")) {
    p.contact.damp_con = number("packing_damp_con", false);
    if (p.contact.damp_con >= 1) throw fail(get("packing_damp_con").second, "packing_damp_con must be below 1");
  }
  s.packed_with = p.contact.model;
  p.contact.emod = number("packing_emod[Pa]", true);
  p.contact.kratio = number("packing_kratio", true);
  p.contact.fric = number("packing_fric", false);
  p.walls.emod = number("wall_emod[Pa]", true);
  p.walls.kratio = number("wall_kratio", true);
  Simulation& sim = s.sim;
  sim.settings.local_damping = number("local_damping", false);
  if (sim.settings.local_damping >= 1) throw fail(get("local_damping").second, "local_damping must be below 1");
  const double radius = number("vessel_radius[m]", true);
  const double bottom = std::strtod(get("vessel_bottom[m]").first.c_str(), nullptr);
  const double top = std::strtod(get("vessel_top[m]").first.c_str(), nullptr);
  if (!(top > bottom)) throw fail(get("vessel_top[m]").second, "vessel_top must be above vessel_bottom");
  const std::uint64_t grain_bit = sim.groups.bit(kGrainGroup);
  s.vessel = add_vessel(sim, radius, top - bottom, sim.groups.bit(kVesselGroup));
  sim.walls.walls[s.vessel.bottom].point.z = sim.walls.walls[s.vessel.bottom].rotation_center.z = bottom;
  sim.walls.walls[s.vessel.top].point.z = sim.walls.walls[s.vessel.top].rotation_center.z = top;
  // Each grain's pebbles or ball as (centre, radius) rows, checked against the vessel and each other.
  std::vector<Row> spheres;
  if (clump_file) {
    const auto [size, size_at] = get("clump_size");
    if (size == "enclosing") s.clump_size = SizeMeasure::EnclosingDiameter;
    else if (size != "equal-volume") throw fail(size_at, "clump_size must be equal-volume or enclosing, got '" + size + "'");
    s.clump_mix = mix;
  }
  for (const Row& r : rows) {
    if (!clump_file) {
      spheres.push_back(r);
      continue;
    }
    // The clump as saved: its unit template scaled by `scale` (bitwise the genesis's: the unit's
    // pebble radius is 1), its orientation and centre written over those add() computes.
    const ClumpTemplate t = named_template(s.clump_mix[r.kind].first, r.v[8]).scaled_by(r.v[7]);
    for (std::size_t k = 0; k < t.pebbles.size(); ++k)
      if (sim.balls.find(r.id + static_cast<std::int64_t>(k)) >= 0) throw fail(r.line, fmt::format("duplicate ball id {}", r.id + k));
    ClumpInit c;
    c.first_ball_id = r.id;
    c.position = Vec3{r.v[0], r.v[1], r.v[2]};
    c.young_mod = r.v[9];
    c.pois_ratio = r.v[10];
    c.groups = grain_bit;
    const std::size_t i = sim.clumps.add(sim.balls, t, c);
    s.clump_kind.push_back(r.kind);
    sim.clumps.state.orientation[i] = Quat{r.v[3], r.v[4], r.v[5], r.v[6]};
    for (std::size_t k = 0; k < sim.clumps.pebbles.size(); ++k) {
      if (sim.clumps.pebbles.clump[k] != i) continue;
      const Vec3 x = pebble_position(sim.clumps.state, sim.clumps.pebbles, k);
      Row p{};
      p.id = r.id;
      p.v[0] = x.x, p.v[1] = x.y, p.v[2] = x.z, p.v[3] = sim.clumps.pebbles.radius[k];
      p.line = r.line;
      p.body = r.body;
      spheres.push_back(p);
    }
  }
  for (const Row& r : spheres) {
    const Vec3 x{r.v[0], r.v[1], r.v[2]};
    const double rad = r.v[3];
    const char* what = clump_file ? "a pebble of clump" : "ball";
    if (!clump_file && sim.balls.find(r.id) >= 0) throw fail(r.line, fmt::format("duplicate ball id {}", r.id));
    if (std::hypot(x.x, x.y) > radius || x.z < bottom || x.z > top)
      throw fail(r.line, fmt::format("{} {} lies outside the vessel", what, r.id));
    const double beyond = std::max({std::hypot(x.x, x.y) + rad - radius, bottom - (x.z - rad), x.z + rad - top});
    if (beyond > kMaxOverlap * 2.0 * rad)
      throw fail(r.line, fmt::format("{} {} reaches {:.4g} mm beyond a vessel wall, {:.3g} % of its diameter; at most {:g} % "
                                     "is a packed state",
                                     clump_file ? what : "grain", r.id, beyond * 1e3, 100 * beyond / (2.0 * rad), 100 * kMaxOverlap));
    if (clump_file) continue;
    BallInit b;
    b.id = r.id;
    b.position = x;
    b.radius = r.v[3];
    b.density = r.v[4];
    b.young_mod = r.v[5];
    b.pois_ratio = r.v[6];
    b.groups = grain_bit;
    sim.balls.add(b);
  }
  if (clump_file) sim.clumps.place_pebbles(sim.balls);
  check_overlaps(spheres, source);
  sim.sort_balls_spatially();
  install_table(sim, packing_table(sim, p.contact, p.walls));
  sim.update_forces();
  if (p_out) {
    p_out->contact = p.contact;
    p_out->walls.emod = p.walls.emod;
    p_out->walls.kratio = p.walls.kratio;
  }
  return s;
}

Specimen load_packed_specimen(const std::string& path, PackingSettings* p) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot open the specimen file");
  std::stringstream buf;
  buf << f.rdbuf();
  return parse_packed_specimen(buf.str(), path, p);
}

}  // namespace hilldem
