#include "hilldem/bodies/clump_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) { throw InputError(source + ": " + what); }

// The closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, §5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// The solid angle [sr] of triangle (a, b, c) seen from p, signed (positive when p is on the inner
// side of a counter-clockwise triangle): Van Oosterom & Strackee's formula.
double solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 x = a - p, y = b - p, z = c - p;
  const double lx = norm(x), ly = norm(y), lz = norm(z);
  const double num = dot(x, cross(y, z));
  const double den = lx * ly * lz + dot(x, y) * lz + dot(x, z) * ly + dot(y, z) * lx;
  return 2.0 * std::atan2(num, den);
}

struct Welder {
  std::map<std::array<double, 3>, int> index;
  TriangleMesh mesh;
  int add(const Vec3& v) {
    const auto [it, fresh] = index.try_emplace({v.x, v.y, v.z}, static_cast<int>(mesh.vertices.size()));
    if (fresh) mesh.vertices.push_back(v);
    return it->second;
  }
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the mesh file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

double parse_number(const std::string& tok, const std::string& source, int line) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(tok, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != tok.size() || !std::isfinite(v))
    fail(source, "line " + std::to_string(line) + ": '" + tok + "' is not a finite number");
  return v;
}

TriangleMesh read_stl_binary(const std::string& bytes, const std::string& path) {
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);
  Welder w;
  for (std::uint32_t t = 0; t < n; ++t) {
    const char* rec = bytes.data() + 84 + 50 * static_cast<std::size_t>(t);
    std::array<int, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      float c[3];
      std::memcpy(c, rec + 12 + 12 * k, 12);
      if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]))
        fail(path, "triangle " + std::to_string(t) + ": a vertex coordinate is not finite");
      tri[k] = w.add({c[0], c[1], c[2]});
    }
    w.mesh.triangles.push_back(tri);
  }
  return std::move(w.mesh);
}

TriangleMesh read_stl_ascii(const std::string& bytes, const std::string& path) {
  std::vector<std::pair<std::string, int>> tok;  // token, line
  {
    std::istringstream in(bytes);
    std::string line;
    int no = 0;
    while (std::getline(in, line)) {
      ++no;
      std::istringstream ls(line);
      std::string t;
      bool first = true;
      while (ls >> t) {
        tok.emplace_back(t, no);
        // the name after "solid" is free text
        if (first && t == "solid") break;
        first = false;
      }
    }
  }
  std::size_t at = 0;
  const auto line_of = [&] { return at < tok.size() ? tok[at].second : (tok.empty() ? 1 : tok.back().second); };
  const auto expect = [&](const char* word) {
    if (at >= tok.size()) fail(path, "line " + std::to_string(line_of()) + ": the file ends where '" + word + "' was expected");
    if (tok[at].first != word)
      fail(path, "line " + std::to_string(line_of()) + ": expected '" + word + "', got '" + tok[at].first + "'");
    ++at;
  };
  const auto number = [&] {
    if (at >= tok.size()) fail(path, "line " + std::to_string(line_of()) + ": the file ends where a number was expected");
    const double v = parse_number(tok[at].first, path, tok[at].second);
    ++at;
    return v;
  };
  expect("solid");
  Welder w;
  while (true) {
    if (at >= tok.size()) fail(path, "line " + std::to_string(line_of()) + ": the file ends without 'endsolid'");
    if (tok[at].first == "endsolid") break;
    expect("facet");
    expect("normal");
    number(), number(), number();  // the normal is not used: the orientation comes from the vertex order
    expect("outer");
    expect("loop");
    std::array<int, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      expect("vertex");
      const double x = number(), y = number(), z = number();
      tri[k] = w.add({x, y, z});
    }
    if (at < tok.size() && tok[at].first == "vertex")
      fail(path, "line " + std::to_string(line_of()) + ": a facet with more than three vertices");
    expect("endloop");
    expect("endfacet");
    w.mesh.triangles.push_back(tri);
  }
  return std::move(w.mesh);
}

TriangleMesh read_obj(const std::string& bytes, const std::string& path) {
  TriangleMesh m;
  std::istringstream in(bytes);
  std::string line;
  int no = 0;
  std::vector<std::pair<int, int>> face_lines;  // (first triangle, line) to name a face in errors
  while (std::getline(in, line)) {
    ++no;
    std::istringstream ls(line);
    std::string key;
    if (!(ls >> key) || key[0] == '#') continue;
    if (key == "v") {
      std::string a, b, c;
      if (!(ls >> a >> b >> c)) fail(path, "line " + std::to_string(no) + ": 'v' needs three coordinates");
      m.vertices.push_back({parse_number(a, path, no), parse_number(b, path, no), parse_number(c, path, no)});
    } else if (key == "f") {
      std::vector<int> f;
      std::string t;
      while (ls >> t) {
        const std::string head = t.substr(0, t.find('/'));
        std::size_t used = 0;
        long v = 0;
        try {
          v = std::stol(head, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != head.size() || v == 0)
          fail(path, "line " + std::to_string(no) + ": '" + t + "' is not a vertex index (1-based, or negative from the end)");
        const long n = static_cast<long>(m.vertices.size());
        const long i = v > 0 ? v - 1 : n + v;
        if (i < 0 || i >= n)
          fail(path, "line " + std::to_string(no) + ": vertex index " + std::to_string(v) + " out of range (" +
                         std::to_string(n) + " vertices so far)");
        f.push_back(static_cast<int>(i));
      }
      if (f.size() < 3) fail(path, "line " + std::to_string(no) + ": a face needs at least three vertices");
      for (std::size_t k = 1; k + 1 < f.size(); ++k) m.triangles.push_back({f[0], f[k], f[k + 1]});
    } else if (key == "vt" || key == "vn" || key == "vp" || key == "g" || key == "o" || key == "s" || key == "usemtl" ||
               key == "mtllib" || key == "l") {
      continue;
    } else {
      fail(path, "line " + std::to_string(no) + ": unknown OBJ statement '" + key + "'");
    }
  }
  return m;
}

}  // namespace

double mesh_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles) v += dot(m.vertices[t[0]], cross(m.vertices[t[1]], m.vertices[t[2]]));
  return v / 6.0;
}

TriangleMesh closed_mesh(TriangleMesh m, const std::string& source) {
  if (m.triangles.size() < 4) fail(source, "a closed mesh needs at least 4 triangles, got " + std::to_string(m.triangles.size()));
  double extent = 0.0;
  for (const Vec3& v : m.vertices) extent = std::max({extent, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  // edge (low, high vertex) -> triangles using it, with +1 along low→high, −1 against
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> edges;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& tri = m.triangles[t];
    const Vec3 a = m.vertices[tri[0]], b = m.vertices[tri[1]], c = m.vertices[tri[2]];
    if (!(norm(cross(b - a, c - a)) > 1e-24 * extent * extent))
      fail(source, "triangle " + std::to_string(t) + " has zero area (repeated or collinear vertices)");
    for (int k = 0; k < 3; ++k) {
      const int i = tri[k], j = tri[(k + 1) % 3];
      edges[{std::min(i, j), std::max(i, j)}].emplace_back(static_cast<int>(t), i < j ? 1 : -1);
    }
  }
  for (const auto& entry : edges) {
    const std::pair<int, int>& e = entry.first;  // (not a structured binding: lambdas capture it in C++20 only from clang 16)
    const std::vector<std::pair<int, int>>& users = entry.second;
    const auto where = [&] {
      const Vec3 a = m.vertices[e.first], b = m.vertices[e.second];
      return "triangle " + std::to_string(users[0].first) + ", edge (" + std::to_string(a.x) + ", " + std::to_string(a.y) +
             ", " + std::to_string(a.z) + ")-(" + std::to_string(b.x) + ", " + std::to_string(b.y) + ", " +
             std::to_string(b.z) + ") m";
    };
    if (users.size() == 1) fail(source, "the mesh is open: " + where() + " belongs to no other triangle");
    if (users.size() > 2)
      fail(source, "the mesh is not a closed surface: " + where() + " is shared by " + std::to_string(users.size()) + " triangles");
    if (users[0].second == users[1].second)
      fail(source, "triangles " + std::to_string(users[0].first) + " and " + std::to_string(users[1].first) +
                       " are oriented inconsistently (they run along their shared edge the same way)");
  }
  if (mesh_volume(m) < 0.0)
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

TriangleMesh read_mesh(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".stl" && ext != ".obj") fail(path, "a mesh file must end in .stl or .obj");
  const std::string bytes = read_bytes(path);
  TriangleMesh m;
  if (ext == ".obj") {
    m = read_obj(bytes, path);
  } else {
    std::uint32_t n = 0;
    if (bytes.size() >= 84) std::memcpy(&n, bytes.data() + 80, 4);
    if (bytes.size() >= 84 && bytes.size() == 84 + 50 * static_cast<std::size_t>(n)) {
      m = read_stl_binary(bytes, path);
    } else if (bytes.rfind("solid", 0) == 0) {
      m = read_stl_ascii(bytes, path);
    } else {
      fail(path, "neither ASCII STL (it starts with 'solid') nor binary STL (84 + 50 n bytes for the n triangles of its header: " +
                     std::to_string(bytes.size()) + " bytes" + (bytes.size() >= 84 ? ", header n = " + std::to_string(n) : "") + ")");
    }
  }
  return closed_mesh(std::move(m), path);
}

TriangleMesh convex_hull(const std::vector<Vec3>& p) {
  const std::string source = "convex hull";
  if (p.size() < 4 || p.size() > 200) fail(source, "needs 4 to 200 vertices, got " + std::to_string(p.size()));
  double extent = 0.0;
  for (const Vec3& v : p) {
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) fail(source, "a vertex is not finite");
    extent = std::max({extent, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  }
  const double tol = 1e-10 * extent;
  struct Plane {
    Vec3 n;
    double d;
  };
  std::vector<Plane> planes;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t k = j + 1; k < n; ++k) {
        Vec3 nrm = cross(p[j] - p[i], p[k] - p[i]);
        const double len = norm(nrm);
        if (!(len > 1e-12 * extent * extent)) continue;
        nrm = nrm / len;
        double d = dot(nrm, p[i]);
        bool above = false, below = false;
        for (const Vec3& q : p) {
          const double s = dot(nrm, q) - d;
          above |= s > tol;
          below |= s < -tol;
        }
        if (above && below) continue;
        if (above) nrm = -nrm, d = -d;
        bool known = false;
        for (const Plane& pl : planes) known |= dot(pl.n, nrm) > 1.0 - 1e-9 && std::abs(pl.d - d) <= tol;
        if (!known) planes.push_back({nrm, d});
      }
  if (planes.size() < 4) fail(source, "the vertices lie on one plane");
  TriangleMesh m;
  m.vertices = p;
  for (const Plane& pl : planes) {
    std::vector<int> on;
    Vec3 c;
    for (std::size_t q = 0; q < n; ++q)
      if (std::abs(dot(pl.n, p[q]) - pl.d) <= tol) on.push_back(static_cast<int>(q)), c += p[q];
    c = c / static_cast<double>(on.size());
    const Vec3 u = unit_or_zero(p[on[0]] - c), v = cross(pl.n, u);
    std::vector<std::pair<double, int>> ring;
    for (int q : on) ring.emplace_back(std::atan2(dot(p[q] - c, v), dot(p[q] - c, u)), q);
    std::sort(ring.begin(), ring.end());
    for (std::size_t k = 1; k + 1 < ring.size(); ++k) m.triangles.push_back({ring[0].second, ring[k].second, ring[k + 1].second});
  }
  // Vertices inside the hull are kept but used by no triangle: harmless to the distance and volume.
  return closed_mesh(std::move(m), source);
}

TriangleMesh aggregate_polyhedron(const std::string& name) {
  const auto box = [](double lx, double ly, double lz) {
    std::vector<Vec3> v;
    for (int i = 0; i < 8; ++i) v.push_back({(i & 1 ? 0.5 : -0.5) * lx, (i & 2 ? 0.5 : -0.5) * ly, (i & 4 ? 0.5 : -0.5) * lz});
    return convex_hull(v);
  };
  if (name == "cube") return box(1.0, 1.0, 1.0);
  if (name == "prism") return box(2.0, 1.0, 1.0);
  if (name == "slab") return box(1.0, 1.0, 0.33);
  if (name == "rock")
    return convex_hull({{1.0, 0.1, 0.2}, {-0.9, 0.2, -0.1}, {0.2, 0.8, 0.3}, {-0.1, -0.7, 0.2},
                        {0.1, 0.2, 0.6}, {0.3, -0.1, -0.55}, {0.6, 0.5, -0.3}, {-0.5, -0.4, -0.4},
                        {-0.4, 0.5, 0.4}, {0.5, -0.5, 0.4}, {-0.6, -0.2, 0.45}, {0.2, 0.6, -0.5}});
  throw InputError("unknown polyhedron '" + name + "'; known: " + kAggregatePolyhedra);
}

MeshShape::MeshShape(TriangleMesh mesh) : mesh_(std::move(mesh)) {
  lo_ = hi_ = mesh_.vertices.at(mesh_.triangles.at(0)[0]);
  for (const auto& t : mesh_.triangles)
    for (int k : t) {
      const Vec3& v = mesh_.vertices[k];
      lo_ = {std::min(lo_.x, v.x), std::min(lo_.y, v.y), std::min(lo_.z, v.z)};
      hi_ = {std::max(hi_.x, v.x), std::max(hi_.y, v.y), std::max(hi_.z, v.z)};
    }
  volume_ = mesh_volume(mesh_);
}

double MeshShape::inner_distance(const Vec3& x) const {
  double omega = 0.0, d2 = 1e300;
  for (const auto& t : mesh_.triangles) {
    const Vec3 &a = mesh_.vertices[t[0]], &b = mesh_.vertices[t[1]], &c = mesh_.vertices[t[2]];
    d2 = std::min(d2, norm2(closest_on_triangle(x, a, b, c) - x));
    omega += solid_angle(x, a, b, c);
  }
  // The winding number Ω / 4π is 1 inside and 0 outside a closed outward mesh.
  // A point within 1e-12 of the box's diagonal of the surface is on it: its winding number is near
  // 1/2 and its distance rounding's, so neither the sign nor the value depends on the triangulation.
  const double d = std::sqrt(d2);
  if (!(omega > 2.0 * std::numbers::pi) || d <= 1e-12 * norm(hi_ - lo_)) return 0.0;
  return d;
}

}  // namespace hilldem
