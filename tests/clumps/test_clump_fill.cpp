// The sphere fill of shapes (bodies/clump_fill.hpp) and closed meshes (bodies/clump_mesh.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "hilldem/bodies/clump_fill.hpp"
#include "hilldem/bodies/clump_mesh.hpp"
#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"

using namespace hilldem;

namespace {

const double pi = std::numbers::pi;

// A fresh folder for the mesh files of one test.
std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("hilldem_clump_fill_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

void write(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// The unit cube [-0.5, 0.5]³ as 12 outward triangles (a triangulation other than convex_hull's).
TriangleMesh cube_mesh() {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

std::string ascii_stl(const TriangleMesh& m) {
  std::string s = "solid cube made by hand\n";
  for (const auto& t : m.triangles) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int k : t) {
      const Vec3 v = m.vertices[k];
      s += "      vertex " + std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid cube\n";
}

std::string binary_stl(const TriangleMesh& m) {
  std::string s(80, ' ');
  const std::uint32_t n = static_cast<std::uint32_t>(m.triangles.size());
  s.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : m.triangles) {
    float rec[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) rec[3 + 3 * k + i] = static_cast<float>(m.vertices[t[k]][i]);
    s.append(reinterpret_cast<const char*>(rec), 48);
    s.append(2, '\0');
  }
  return s;
}

std::string obj(const TriangleMesh& m) {
  std::string s = "# a cube\no cube\n";
  for (const Vec3& v : m.vertices) s += "v " + std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
  for (const auto& t : m.triangles)
    s += "f " + std::to_string(t[0] + 1) + "/1/1 " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return s;
}

double fidelity(const FillShape& s, const Pebbles& p) { return make_template_columns(p, 1000.0, 256).volume / s.volume(); }

void expect_error(const std::function<void()>& f, std::initializer_list<const char*> parts) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    for (const char* part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what() << " lacks " << part;
  }
}

}  // namespace

// The distance to the ellipsoid's surface: the least distance to a dense set of its surface points
// (the closest point by bisection is exact to rounding, the set's spacing bounds the difference).
TEST(ClumpFill, EllipsoidDistanceIsTheLeastToTheSurface) {
  const double a = 1.5, b = 1.2, c = 1.0;
  const EllipsoidShape e(a, b, c);
  const Vec3 points[] = {{0, 0, 0}, {0.7, 0, 0}, {0, 0.5, 0}, {0.3, 0.4, 0}, {1.2, 0.1, 0.2}, {-0.5, 0.6, -0.4}, {0, 0, 0.9}, {0.2, 0, 0.5}};
  for (const Vec3& x : points) {
    double best = 1e300;
    const int n = 600;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j < 2 * n; ++j) {
        const double th = pi * i / n, ph = pi * j / n;
        const Vec3 s{a * std::sin(th) * std::cos(ph), b * std::sin(th) * std::sin(ph), c * std::cos(th)};
        best = std::min(best, norm(s - x));
      }
    const double d = e.inner_distance(x);
    EXPECT_LE(d, best + 1e-12) << x.x << " " << x.y << " " << x.z;
    EXPECT_GT(d, best - 2e-5) << x.x << " " << x.y << " " << x.z;
  }
  EXPECT_EQ(e.inner_distance({0, 0, 0}), 1.0);  // the smallest semi-axis
  EXPECT_EQ(e.inner_distance({1.5, 0, 0}), 0.0);
  EXPECT_EQ(e.inner_distance({2.0, 0, 0}), 0.0);
  EXPECT_NEAR(EllipsoidShape(2, 2, 2).inner_distance({0.5, 0.5, 0.5}), 2 - std::sqrt(0.75), 1e-15);
}

// A sphere is one pebble: the sphere itself, fidelity 1.
TEST(ClumpFill, SphereIsOnePebble) {
  const EllipsoidShape s(3e-3, 3e-3, 3e-3);
  const FillResult r = fill_shape(s, {});
  ASSERT_EQ(r.pebbles.size(), 1u);
  EXPECT_EQ(r.pebbles.radius[0], 3e-3);
  EXPECT_EQ(r.pebbles.position[0], Vec3{});
  EXPECT_EQ(r.sample_fidelity, 1.0);
}

// Every pebble is inside: for the ellipsoid, every point of a pebble's surface; for the box-shaped
// polyhedra, |x_i| + r ≤ the half-extent along each axis.
TEST(ClumpFill, PebblesInsideTheShape) {
  const EllipsoidShape e(1.5, 1.2, 1.0);
  const FillResult r = fill_shape(e, {30, 0.2, 1.0, 41});
  ASSERT_EQ(r.pebbles.size(), 30u);
  for (std::size_t k = 0; k < r.pebbles.size(); ++k) {
    double worst = 0.0;
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j < 80; ++j) {
        const double th = pi * i / 40, ph = pi * j / 40;
        const Vec3 x = r.pebbles.position[k] + Vec3{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)} * r.pebbles.radius[k];
        worst = std::max(worst, x.x * x.x / 2.25 + x.y * x.y / 1.44 + x.z * x.z);
      }
    EXPECT_LE(worst, 1.0 + 1e-12) << k;
    EXPECT_GE(r.pebbles.radius[k], 0.2 * 1.0 - 1e-15);
  }
  struct Box {
    const char* name;
    Vec3 half;
  };
  for (const Box& b : {Box{"cube", {0.5, 0.5, 0.5}}, Box{"prism", {1.0, 0.5, 0.5}}, Box{"slab", {0.5, 0.5, 0.165}}}) {
    const Pebbles p = named_shape_fill(b.name, {20, 0.3, 1.0, 41});
    for (std::size_t k = 0; k < p.size(); ++k)
      for (int i = 0; i < 3; ++i) EXPECT_LE(std::abs(p.position[k][i]) + p.radius[k], b.half[i] + 1e-12) << b.name << " " << k;
  }
  // the rock: each pebble's centre is at least its radius from every triangle's plane, inside
  const TriangleMesh rock = aggregate_polyhedron("rock");
  const Pebbles p = fill_shape(MeshShape(rock), {20, 0.3, 1.0, 41}).pebbles;
  for (std::size_t k = 0; k < p.size(); ++k)
    for (const auto& t : rock.triangles) {
      const Vec3 a = rock.vertices[t[0]], n = unit_or_zero(cross(rock.vertices[t[1]] - a, rock.vertices[t[2]] - a));
      EXPECT_GE(dot(a - p.position[k], n), p.radius[k] - 1e-12) << k;
    }
}

// Fidelity (the union's volume by 256 columns / the shape's) rises with the pebble count, and the
// triaxial ellipsoid passes c/b, the bound of pebbles on its major axis.
TEST(ClumpFill, FidelityRisesWithCount) {
  const EllipsoidShape e(1.5, 1.2, 1.0);
  const MeshShape cube(aggregate_polyhedron("cube")), rock(aggregate_polyhedron("rock"));
  for (const FillShape* s : {static_cast<const FillShape*>(&e), static_cast<const FillShape*>(&cube), static_cast<const FillShape*>(&rock)}) {
    double last = 0.0;
    for (int count : {1, 3, 10, 30}) {
      const double f = fidelity(*s, fill_shape(*s, {count, 0.1, 1.0, 41}).pebbles);
      EXPECT_GT(f, last + 0.01) << count;
      EXPECT_LT(f, 1.0) << count;
      last = f;
    }
  }
  EXPECT_GT(fidelity(e, fill_shape(e, {30, 0.1, 1.0, 41}).pebbles), 0.95);  // c/b = 0.83 on the axis
  // the fidelity target stops the fill early
  const FillResult r = fill_shape(e, {1000, 0.1, 0.9, 41});
  EXPECT_GE(r.sample_fidelity, 0.9);
  EXPECT_LT(r.pebbles.size(), fill_shape(e, {1000, 0.1, 0.95, 41}).pebbles.size());
}

// The mesh volumes and the hull: the cube's, the prism's and the slab's are exact.
TEST(ClumpFill, HullAndVolumes) {
  EXPECT_NEAR(mesh_volume(aggregate_polyhedron("cube")), 1.0, 1e-15);
  EXPECT_NEAR(mesh_volume(aggregate_polyhedron("prism")), 2.0, 1e-15);
  EXPECT_NEAR(mesh_volume(aggregate_polyhedron("slab")), 0.33, 1e-15);
  EXPECT_GT(mesh_volume(aggregate_polyhedron("rock")), 0.5);
  // an interior vertex changes nothing; a regular octahedron of half-diagonal 1 has volume 4/3
  std::vector<Vec3> oct = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0.1, 0.2, 0.1}};
  const TriangleMesh h = convex_hull(oct);
  EXPECT_EQ(h.triangles.size(), 8u);
  EXPECT_NEAR(mesh_volume(h), 4.0 / 3.0, 1e-15);
  // an octahedron's inscribed sphere: radius 1/√3
  EXPECT_NEAR(MeshShape(h).inner_distance({0, 0, 0}), 1.0 / std::sqrt(3.0), 1e-15);
  expect_error([] { convex_hull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}); }, {"one plane"});
  expect_error([] { aggregate_polyhedron("dodecahedron"); }, {"dodecahedron", "cube, prism, slab, rock"});
}

// A cube read as ASCII STL, binary STL or OBJ (triangulated otherwise than the hull) and the
// polyhedral cube give the same template.
TEST(ClumpFill, MeshFilesAndThePolyhedronGiveOneTemplate) {
  const auto dir = scratch("cube");
  write(dir / "cube.stl", ascii_stl(cube_mesh()));
  write(dir / "cube_bin.STL", binary_stl(cube_mesh()));
  write(dir / "cube.obj", obj(cube_mesh()));
  const FillParams f{12, 0.3, 0.99, 41};
  const Pebbles ref = fill_shape(MeshShape(aggregate_polyhedron("cube")), f).pebbles;
  const ClumpTemplate tref = make_template(ref, 2650.0);
  ASSERT_GT(ref.size(), 3u);
  for (const char* name : {"cube.stl", "cube_bin.STL", "cube.obj"}) {
    const TriangleMesh m = read_mesh((dir / name).string());
    EXPECT_EQ(m.vertices.size(), 8u) << name;
    EXPECT_NEAR(mesh_volume(m), 1.0, 1e-15) << name;
    // The pebbles in the shape's frame. (The template's principal frame is not compared: a cube's
    // fill is nearly isotropic, so its principal axes are ill-defined.)
    const Pebbles p = fill_shape(MeshShape(m), f).pebbles;
    ASSERT_EQ(p.size(), ref.size()) << name;
    for (std::size_t k = 0; k < p.size(); ++k) {
      EXPECT_NEAR(norm(p.position[k] - ref.position[k]), 0.0, 1e-14) << name << " " << k;
      EXPECT_NEAR(p.radius[k], ref.radius[k], 1e-14) << name << " " << k;
    }
    const ClumpTemplate t = make_template(p, 2650.0);
    EXPECT_NEAR(t.volume, tref.volume, 1e-12 * tref.volume) << name;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(t.principal_inertia[i], tref.principal_inertia[i], 1e-10 * tref.principal_inertia[i]) << name;
  }
  // an inward-oriented mesh is turned over
  TriangleMesh in = cube_mesh();
  for (auto& t : in.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(mesh_volume(closed_mesh(in, "inward")), 1.0, 1e-15);
}

TEST(ClumpFill, MalformedMeshesNameTheFault) {
  const auto dir = scratch("bad");
  TriangleMesh open = cube_mesh();
  open.triangles.pop_back();
  write(dir / "open.stl", ascii_stl(open));
  expect_error([&] { read_mesh((dir / "open.stl").string()); }, {"open.stl", "open", "triangle"});
  std::string text = ascii_stl(cube_mesh());
  text.replace(text.find("endloop"), 7, "endlop");
  write(dir / "typo.stl", text);
  expect_error([&] { read_mesh((dir / "typo.stl").string()); }, {"typo.stl", "line 7", "expected 'endloop'", "endlop"});
  text = ascii_stl(cube_mesh());
  text.replace(text.find("vertex ") + 7, 1, "x");
  write(dir / "number.stl", text);
  expect_error([&] { read_mesh((dir / "number.stl").string()); }, {"number.stl", "line 4", "not a finite number"});
  write(dir / "short.stl", binary_stl(cube_mesh()).substr(0, 300));
  expect_error([&] { read_mesh((dir / "short.stl").string()); }, {"short.stl", "neither ASCII STL", "300 bytes", "n = 12"});
  write(dir / "index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_error([&] { read_mesh((dir / "index.obj").string()); }, {"index.obj", "line 4", "out of range"});
  write(dir / "word.obj", "v 0 0 0\nvertex 1 0 0\n");
  expect_error([&] { read_mesh((dir / "word.obj").string()); }, {"word.obj", "line 2", "unknown OBJ statement"});
  TriangleMesh flipped = cube_mesh();
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  write(dir / "flipped.obj", obj(flipped));
  expect_error([&] { read_mesh((dir / "flipped.obj").string()); }, {"flipped.obj", "oriented inconsistently"});
  TriangleMesh degenerate = cube_mesh();
  degenerate.triangles[0] = {0, 0, 3};
  expect_error([&] { closed_mesh(degenerate, "d"); }, {"triangle 0", "zero area"});
  expect_error([&] { read_mesh((dir / "none.stl").string()); }, {"none.stl", "cannot open"});
  expect_error([&] { read_mesh((dir / "cube.ply").string()); }, {".stl or .obj"});
  expect_error([] { fill_shape(EllipsoidShape(2, 1, 1), {0, 0.5, 0.9, 41}); }, {"count"});
  expect_error([] { fill_shape(EllipsoidShape(2, 1, 1), {5, 0.5, 1.1, 41}); }, {"fidelity"});
  expect_error([] { fill_shape(EllipsoidShape(2, 1, 1), {5, 0.5, 0.9, 5}); }, {"resolution"});
  expect_error([] { EllipsoidShape(1, 2, 1); }, {"a >= b >= c"});
}
