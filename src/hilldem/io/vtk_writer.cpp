#include "hilldem/io/vtk_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <limits>
#include <numbers>

#include "hilldem/core/error.hpp"
#include "hilldem/io/checkpoint.hpp"

namespace hilldem {

namespace {

// One VTK data array, kept as raw little-endian bytes until the file is assembled.
struct Array {
  std::string name;
  std::string type;  // "Float64", "Int64", "Int32", "UInt8", "String"
  int components = 1;
  std::size_t tuples = 0;
  std::string bytes;                 // raw values (numeric types)
  std::vector<std::string> strings;  // String arrays
};

template <class T>
const char* vtk_type() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  else if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  else if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  else return "UInt8";
}

template <class T>
Array make_array(const std::string& name, const std::vector<T>& v) {
  Array a{name, vtk_type<T>(), 1, v.size(), {}, {}};
  a.bytes.assign(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  return a;
}

Array make_array(const std::string& name, const std::vector<Vec3>& v) {
  std::vector<double> flat;
  flat.reserve(3 * v.size());
  for (const Vec3& x : v) flat.insert(flat.end(), {x.x, x.y, x.z});
  Array a = make_array(name, flat);
  a.components = 3;
  a.tuples = v.size();
  return a;
}

Array make_strings(const std::string& name, std::vector<std::string> s) {
  Array a{name, "String", 1, s.size(), {}, std::move(s)};
  return a;
}

// Assembles a PolyData file.
class PolyFile {
 public:
  explicit PolyFile(bool binary) : binary_(binary) {}
  std::vector<Array> point_data, cell_data, field_data;
  std::vector<Vec3> points;
  // Cells: connectivity and offsets (end of each cell), by kind.
  std::vector<std::int64_t> vert_conn, vert_off, line_conn, line_off, poly_conn, poly_off;

  std::string xml() {
    std::string out = "<?xml version=\"1.0\"?>\n";
    out += "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
    out += "  <PolyData>\n";
    out += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">\n",
                       points.size(), vert_off.size(), line_off.size(), poly_off.size());
    section(out, "PointData", point_data, "      ");
    section(out, "CellData", cell_data, "      ");
    out += "      <Points>\n";
    array(out, make_array("Points", points), "        ");
    out += "      </Points>\n";
    cells(out, "Verts", vert_conn, vert_off);
    cells(out, "Lines", line_conn, line_off);
    cells(out, "Polys", poly_conn, poly_off);
    out += "    </Piece>\n";
    section(out, "FieldData", field_data, "    ", true);
    out += "  </PolyData>\n";
    if (binary_ && !appended_.empty()) {
      out += "  <AppendedData encoding=\"raw\">\n   _";
      out += appended_;
      out += "\n  </AppendedData>\n";
    }
    out += "</VTKFile>\n";
    return out;
  }

 private:
  void cells(std::string& out, const char* tag, const std::vector<std::int64_t>& conn, const std::vector<std::int64_t>& off) {
    if (off.empty()) return;
    out += fmt::format("      <{}>\n", tag);
    array(out, make_array("connectivity", conn), "        ");
    array(out, make_array("offsets", off), "        ");
    out += fmt::format("      </{}>\n", tag);
  }
  void section(std::string& out, const char* tag, const std::vector<Array>& arrays, const char* indent, bool field = false) {
    if (arrays.empty()) return;
    out += fmt::format("{}<{}>\n", indent, tag);
    for (const Array& a : arrays) array(out, a, std::string(indent) + "  ", field);
    out += fmt::format("{}</{}>\n", indent, tag);
  }
  void array(std::string& out, const Array& a, const std::string& indent, bool field = false) {
    std::string head = fmt::format("{}<DataArray type=\"{}\" Name=\"{}\"", indent, a.type, a.name);
    if (a.components != 1) head += fmt::format(" NumberOfComponents=\"{}\"", a.components);
    if (field) head += fmt::format(" NumberOfTuples=\"{}\"", a.tuples);
    if (a.type == "String") {
      // Strings are always ASCII: each as its character codes, terminated by 0.
      out += head + " format=\"ascii\">\n" + indent + " ";
      for (const std::string& s : a.strings) {
        for (unsigned char c : s) out += fmt::format(" {}", static_cast<int>(c));
        out += " 0";
      }
      out += "\n" + indent + "</DataArray>\n";
      return;
    }
    if (binary_) {
      out += head + fmt::format(" format=\"appended\" offset=\"{}\"/>\n", appended_.size());
      const std::uint64_t n = a.bytes.size();
      appended_.append(reinterpret_cast<const char*>(&n), sizeof n);
      appended_ += a.bytes;
      return;
    }
    out += head + " format=\"ascii\">\n" + indent + " ";
    const std::size_t count = a.tuples * static_cast<std::size_t>(a.components);
    for (std::size_t k = 0; k < count; ++k) {
      if (a.type == "Float64") {
        double v;
        std::memcpy(&v, a.bytes.data() + 8 * k, 8);
        out += fmt::format(" {:.17g}", v);
      } else if (a.type == "Int64") {
        std::int64_t v;
        std::memcpy(&v, a.bytes.data() + 8 * k, 8);
        out += fmt::format(" {}", v);
      } else if (a.type == "Int32") {
        std::int32_t v;
        std::memcpy(&v, a.bytes.data() + 4 * k, 4);
        out += fmt::format(" {}", v);
      } else {
        out += fmt::format(" {}", static_cast<int>(static_cast<unsigned char>(a.bytes[k])));
      }
    }
    out += "\n" + indent + "</DataArray>\n";
  }

  bool binary_;
  std::string appended_;
};

std::vector<Array> time_fields(const Simulation& sim) {
  return {make_array("TimeValue", std::vector<double>{sim.time}), make_array("step", std::vector<std::int64_t>{sim.steps})};
}

void save(const std::string& path, PolyFile& f) { write_file_atomically(path, f.xml(), false); }

// Bounding box of the ball centres ± radii (a unit box around the origin when there are no balls).
std::pair<Vec3, Vec3> ball_bounds(const Simulation& sim) {
  if (sim.balls.size() == 0) return {Vec3{-0.5, -0.5, -0.5}, Vec3{0.5, 0.5, 0.5}};
  Vec3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t i = 0; i < sim.balls.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double x = sim.balls.position[i][d], r = sim.balls.radius[i];
      if (!std::isfinite(x)) continue;
      lo[d] = std::min(lo[d], x - r);
      hi[d] = std::max(hi[d], x + r);
    }
  for (int d = 0; d < 3; ++d)
    if (!(lo[d] <= hi[d])) lo[d] = -0.5, hi[d] = 0.5;
  return {lo, hi};
}

}  // namespace

void write_balls_vtp(const Simulation& sim, const std::string& path, bool binary) {
  const BallStore& b = sim.balls;
  const std::size_t n = b.size();
  PolyFile f(binary);
  f.points = b.position;
  std::vector<std::int32_t> coordination(n, 0), wet(n, 0), group(n, -1), fixity(n);
  std::vector<double> moisture(n, 0.0);
  std::vector<std::int64_t> groups(n);
  const ContactStore& c = sim.contacts;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c.exists[k]) continue;
    const ContactKey& key = c.key[k];
    const bool is_wet = c.model[k] == ModelKind::Hill && c.moisture[k] == Moisture::Wet;
    const double fm = std::abs(c.moisture_force[k]);
    for (int side = 0; side < (key.kind == ContactKind::BallBall ? 2 : 1); ++side) {
      const std::size_t i = side == 0 ? key.a : key.b;
      if (c.active[k]) ++coordination[i];
      if (is_wet) ++wet[i];
      moisture[i] += fm;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    groups[i] = static_cast<std::int64_t>(b.groups[i]);
    if (b.groups[i]) group[i] = std::countr_zero(b.groups[i]);
    fixity[i] = b.fixity[i];
  }
  // The clump of each pebble (its index), -1 for a ball that is none: ParaView colours the shapes by it.
  std::vector<std::int32_t> clump_id(n, -1);
  for (std::size_t k = 0; k < sim.clumps.ball.size(); ++k)
    clump_id[sim.clumps.ball[k]] = static_cast<std::int32_t>(sim.clumps.pebbles.clump[k]);
  f.point_data = {make_array("id", b.id),
                  make_array("radius", b.radius),
                  make_array("mass", b.mass),
                  make_array("velocity", b.velocity),
                  make_array("spin", b.spin),
                  make_array("contact_force", b.contact_force),
                  make_array("contact_moment", b.contact_moment),
                  make_array("fixity", fixity),
                  make_array("groups", groups),
                  make_array("group", group),
                  make_array("coordination", coordination),
                  make_array("wet_contacts", wet),
                  make_array("moisture_force", moisture),
                  make_array("clump_id", clump_id)};
  for (std::size_t i = 0; i < n; ++i) {
    f.vert_conn.push_back(static_cast<std::int64_t>(i));
    f.vert_off.push_back(static_cast<std::int64_t>(i + 1));
  }
  f.field_data = time_fields(sim);
  f.field_data.push_back(make_strings("group_names", group_names(sim.groups)));
  save(path, f);
}

void write_contacts_vtp(const Simulation& sim, const std::string& path, bool binary) {
  const ContactStore& c = sim.contacts;
  const BallStore& b = sim.balls;
  PolyFile f(binary);
  std::vector<std::int64_t> ball1, ball2;
  std::vector<std::int32_t> wall, kind, model, state, wet, active;
  std::vector<double> gap, fn, fm, fs_mag, suction;
  std::vector<Vec3> normal, fs, force, point;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c.exists[k]) continue;
    const ContactKey& key = c.key[k];
    const bool bb = key.kind == ContactKind::BallBall;
    const Vec3 x1 = b.position[key.a];
    const Vec3 xc = x1 + c.normal[k] * (b.radius[key.a] + 0.5 * c.gap[k]);
    Vec3 x2 = xc;
    if (bb) {
      x2 = b.position[key.b];
      if (c.image[k] != kNoImage) x2 += image_shift(c.image[k], sim.settings.box);  // the image in contact
    }
    f.line_conn.push_back(static_cast<std::int64_t>(f.points.size()));
    f.points.push_back(x1);
    f.line_conn.push_back(static_cast<std::int64_t>(f.points.size()));
    f.points.push_back(x2);
    f.line_off.push_back(static_cast<std::int64_t>(f.line_conn.size()));
    ball1.push_back(b.id[key.a]);
    ball2.push_back(bb ? b.id[key.b] : -1);
    wall.push_back(bb ? -1 : static_cast<std::int32_t>(key.b));
    kind.push_back(bb ? 0 : 1);
    const bool hill = c.model[k] == ModelKind::Hill;
    model.push_back(hill ? 1 : 0);
    state.push_back(hill ? static_cast<std::int32_t>(c.moisture[k]) : 0);
    wet.push_back(hill && c.moisture[k] == Moisture::Wet ? 1 : 0);
    active.push_back(c.active[k] ? 1 : 0);
    gap.push_back(c.gap[k]);
    normal.push_back(c.normal[k]);
    fn.push_back(c.normal_force[k]);
    fm.push_back(c.moisture_force[k]);
    fs.push_back(c.shear_force(k));
    fs_mag.push_back(norm(c.shear_force(k)));
    force.push_back(c.force[k]);
    point.push_back(xc);
    suction.push_back(hill ? c.hill_params[k].suction : 0.0);
  }
  f.cell_data = {make_array("ball1", ball1),
                 make_array("ball2", ball2),
                 make_array("wall", wall),
                 make_array("kind", kind),
                 make_array("model", model),
                 make_array("mois_state", state),
                 make_array("wet", wet),
                 make_array("active", active),
                 make_array("gap", gap),
                 make_array("normal", normal),
                 make_array("normal_force", fn),
                 make_array("moisture_force", fm),
                 make_array("shear_force", fs),
                 make_array("shear_force_mag", fs_mag),
                 make_array("force", force),
                 make_array("contact_point", point),
                 make_array("suction", suction)};
  f.field_data = time_fields(sim);
  save(path, f);
}

void write_walls_vtp(const Simulation& sim, const std::string& path, bool binary) {
  PolyFile f(binary);
  std::vector<std::int32_t> index;
  std::vector<Vec3> force, velocity;
  std::vector<double> normal_force;
  std::vector<std::string> names;
  const auto [lo, hi] = ball_bounds(sim);
  const Vec3 centre = (lo + hi) / 2.0;
  const double span = std::max(norm(hi - lo), 1e-9);
  auto triangle = [&](const Vec3& p, const Vec3& q, const Vec3& r, std::size_t w) {
    for (const Vec3& x : {p, q, r}) {
      f.poly_conn.push_back(static_cast<std::int64_t>(f.points.size()));
      f.points.push_back(x);
    }
    f.poly_off.push_back(static_cast<std::int64_t>(f.poly_conn.size()));
    const Wall& wall = sim.walls.walls[w];
    index.push_back(static_cast<std::int32_t>(w));
    force.push_back(wall.force);
    normal_force.push_back(wall.normal_force);
    velocity.push_back(wall.velocity);
  };
  for (std::size_t w = 0; w < sim.walls.size(); ++w) {
    const Wall& wall = sim.walls.walls[w];
    names.push_back(wall.name);
    if (wall.shape == WallShape::Facet) {
      triangle(wall.vertex[0], wall.vertex[1], wall.vertex[2], w);
    } else if (wall.shape == WallShape::Plane) {
      // A square patch, 1.5 × the balls' diagonal wide, around the balls' centre projected on the plane.
      const Vec3 n = unit_or_zero(wall.normal);
      const Vec3 c = centre - n * dot(centre - wall.point, n);
      Vec3 u = cross(n, std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0});
      u = unit_or_zero(u) * (0.75 * span);
      const Vec3 v = cross(n, u);
      triangle(c - u - v, c + u - v, c + u + v, w);
      triangle(c - u - v, c + u + v, c - u + v, w);
    } else {
      const int ax = wall.axis, u = (ax + 1) % 3, v = (ax + 2) % 3;
      double a0 = wall.lo, a1 = wall.hi;
      if (!(a0 < a1)) a0 = lo[ax] - wall.point[ax], a1 = hi[ax] - wall.point[ax];  // infinite: the balls' span
      constexpr int kSides = 48;
      for (int s = 0; s < kSides; ++s) {
        auto at = [&](int k, double along) {
          const double phi = 2.0 * std::numbers::pi * k / kSides;
          Vec3 x = wall.point;
          x[ax] += along;
          x[u] += wall.radius * std::cos(phi);
          x[v] += wall.radius * std::sin(phi);
          return x;
        };
        triangle(at(s, a0), at(s + 1, a0), at(s + 1, a1), w);
        triangle(at(s, a0), at(s + 1, a1), at(s, a1), w);
      }
    }
  }
  f.cell_data = {make_array("wall", index), make_array("force", force), make_array("normal_force", normal_force),
                 make_array("velocity", velocity)};
  f.field_data = time_fields(sim);
  f.field_data.push_back(make_strings("wall_names", names));
  save(path, f);
}

SnapshotSeries::SnapshotSeries(std::string folder, SnapshotOptions options)
    : folder_(std::move(folder)), options_(options) {
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec) throw InputError(folder_ + ": cannot create the snapshot folder: " + ec.message());
}

void SnapshotSeries::write(const Simulation& sim, bool replace_same_step) {
  SnapshotEntry e{static_cast<std::int64_t>(entries_.size()), sim.steps, sim.time};
  if (replace_same_step && !entries_.empty() && entries_.back().step == sim.steps) {
    e.index = entries_.back().index;
    entries_.pop_back();
  }
  const std::filesystem::path dir(folder_);
  const std::string k = fmt::format("{:06}", e.index);
  write_balls_vtp(sim, (dir / ("balls_" + k + ".vtp")).string(), options_.binary);
  if (options_.contacts) write_contacts_vtp(sim, (dir / ("contacts_" + k + ".vtp")).string(), options_.binary);
  if (options_.walls) write_walls_vtp(sim, (dir / ("walls_" + k + ".vtp")).string(), options_.binary);
  entries_.push_back(e);
  write_index();
}

void SnapshotSeries::restore(std::vector<SnapshotEntry> entries) {
  entries_ = std::move(entries);
  write_index();
}

void SnapshotSeries::write_index() const {
  const std::filesystem::path dir(folder_);
  for (const char* kind : {"balls", "contacts", "walls"}) {
    if ((std::string(kind) == "contacts" && !options_.contacts) || (std::string(kind) == "walls" && !options_.walls)) continue;
    std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n";
    for (const SnapshotEntry& e : entries_)
      out += fmt::format("    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}_{:06}.vtp\"/>\n", e.time, kind, e.index);
    out += "  </Collection>\n</VTKFile>\n";
    write_file_atomically((dir / (std::string(kind) + ".pvd")).string(), out, false);
  }
}

}  // namespace hilldem
