// The scenario's clump keys (docs/scenario-format.md): [[clump_template]] and [[clump]], built into
// the simulation, and their errors naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "hilldem/core/error.hpp"
#include "hilldem/bodies/clump_fill.hpp"
#include "hilldem/bodies/clump_mesh.hpp"
#include "hilldem/io/quantity.hpp"
#include "hilldem/io/scenario.hpp"

namespace hilldem {
namespace {

const std::string kHead = R"(title = "clumps"
[simulation]
timestep = 1e-6
gravity = [0.0, 0.0, -9.81]
[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[ball]]
id = 1
position = [0.0, 0.0, 0.02]
radius = 5e-3
material = "granite"
[[contact_model]]
name = "all"
between = "ball-ball"
model = "hill"
fric_coef = 0.4
)";

const std::string kRod = R"(
[[clump_template]]
name = "rod"
material = "granite"
centres = [[-3e-3, 0.0, 0.0], [0.0, 0.0, 0.0], [3e-3, 0.0, 0.0]]
radii = [2.5e-3, 2.5e-3, 2.5e-3]
size = 10e-3
)";

const std::string kClump = R"(
[[clump]]
template = "rod"
first_id = 10
position = [0.0, 0.0, 0.0]
orientation = [0.0, 0.0, 0.0, 2.0]
velocity = [0.1, 0.0, 0.0]
spin = [0.0, 0.0, 3.0]
groups = ["rods"]
fix = ["z"]
)";

std::string error_of(const std::string& text) {
  try {
    read_scenario(text, "case.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& text, std::initializer_list<const char*> parts) {
  const std::string e = error_of(text);
  ASSERT_FALSE(e.empty()) << "accepted";
  for (const char* p : parts) EXPECT_NE(e.find(p), std::string::npos) << "'" << p << "' not in: " << e;
}

TEST(ClumpScenario, ClumpsAreBuiltAfterTheBalls) {
  const Scenario sc = load_scenario(kHead + kRod + kClump, "case.toml");
  const Simulation& sim = sc.sim;
  ASSERT_EQ(sim.clumps.size(), 1u);
  ASSERT_EQ(sim.balls.size(), 4u);
  EXPECT_EQ(sim.balls.find(10), 1);
  EXPECT_EQ(sim.balls.find(12), 3);
  // size = equal-volume diameter 10 mm: m = ρ π d³ / 6 (the column integration to 1e-3).
  const double m = 2650.0 * std::numbers::pi * 1e-6 / 6.0;
  EXPECT_NEAR(sim.clumps.state.mass[0], m, 1e-3 * m);
  EXPECT_EQ(sim.balls.mass[1], sim.clumps.state.mass[0]) << "a pebble carries its clump's mass";
  EXPECT_EQ(sim.balls.fixity[1], kFixAll) << "pebbles are moved by their clump";
  EXPECT_EQ(sim.clumps.state.fixity[0], FixityMask{0b100});
  EXPECT_EQ(sim.balls.groups[2], sim.groups.find("rods"));
  // Turned by π about z (the quaternion normalised): the first pebble, given at −x, is at +x.
  EXPECT_GT(sim.balls.position[1].x, 2e-3);
  EXPECT_NEAR(sim.balls.position[1].x, -sim.balls.position[3].x, 1e-15);
  EXPECT_NEAR(sim.balls.position[1].y, 0.0, 1e-15);
  EXPECT_EQ(sim.clumps.state.spin[0].z, 3.0);
}

TEST(ClumpScenario, EllipsoidAndUserMassProperties) {
  const std::string text = kHead + R"(
[[clump_template]]
name = "egg"
material = "granite"
ellipsoid = [8e-3, 4e-3, 4e-3]
count = 5
smallest_ratio = 0.4
[[clump_template]]
name = "given"
material = "granite"
centres = [[0.0, 0.0, 0.0]]
radii = [5e-3]
volume = 5e-7
centre_of_mass = [0.0, 0.0, 0.0]
inertia = [1e-8, 2e-8, 3e-8, 0.0, 0.0, 0.0]
[[clump]]
template = "egg"
first_id = 10
position = [0.0, 0.03, 0.0]
[[clump]]
template = "given"
first_id = 20
position = [0.0, -0.03, 0.0]
)";
  const Scenario sc = load_scenario(text, "case.toml");
  ASSERT_EQ(sc.sim.clumps.size(), 2u);
  EXPECT_EQ(sc.sim.balls.size(), 1u + 5u + 1u);
  EXPECT_EQ(sc.sim.clumps.state.mass[1], 2650.0 * 5e-7);
  const Vec3 in = sc.sim.clumps.state.principal_inertia[1];
  EXPECT_NEAR(in.x, 1e-8, 1e-20);
  EXPECT_NEAR(in.y, 2e-8, 1e-20);
  EXPECT_NEAR(in.z, 3e-8, 1e-20);
}

// A history or probe may name a pebble by its ball id (first_id, +1, ...): the history samples the
// pebble's ball; an id past the last pebble is refused with the key.
TEST(ClumpScenario, HistoriesNameAPebbleByItsBallId) {
  auto history = [](int id) {
    return "[[history]]\nname = \"p\"\nquantity = \"ball.pos_x\"\nball = " + std::to_string(id) + "\n";
  };
  const Scenario sc = load_scenario(kHead + kRod + kClump + history(12), "case.toml");
  ASSERT_EQ(sc.histories.size(), 1u);
  EXPECT_EQ(sc.histories[0].quantity.ball, 12);
  EXPECT_EQ(evaluate(sc.sim, sc.histories[0].quantity), sc.sim.balls.position[3].x);
  expect_error(kHead + kRod + kClump + history(13), {"history[1].ball", "no ball or pebble with id 13"});
}

TEST(ClumpScenario, ErrorsNameTheKey) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string t = kHead + kRod + kClump;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  expect_error(with("radii = [2.5e-3, 2.5e-3, 2.5e-3]", "radii = [2.5e-3, 2.5e-3]"), {"radii", "one radius per centre"});
  expect_error(with("radii = [2.5e-3, 2.5e-3, 2.5e-3]", "radii = [2.5e-3, -2.5e-3, 2.5e-3]"), {"radii", "(0, 1000)"});
  expect_error(with("size = 10e-3", "size = 10e-3\nellipsoid = [8e-3, 4e-3, 4e-3]"), {"exactly one of"});
  expect_error(with("template = \"rod\"", "template = \"stick\""), {"template", "no [[clump_template]] named \"stick\""});
  expect_error(with("first_id = 10", "first_id = 0"), {"first_id", "ball id 1", "used twice"});
  expect_error(with("orientation = [0.0, 0.0, 0.0, 2.0]", "orientation = [0.0, 0.0, 0.0, 0.0]"), {"orientation", "non-zero"});
  expect_error(with("size = 10e-3", "size = 10e-3\nvolume = 1e-6"), {"centre_of_mass", "all three"});
  expect_error(with("timestep = 1e-6", "timestep = 1e-6\ndensity_scaling = true"), {"density_scaling", "clumps"});
  expect_error(with("name = \"rod\"", "name = \"rod\"\ncolour = 3"), {"colour"});
  std::string egg = kHead + "[[clump_template]]\nname = \"e\"\nmaterial = \"granite\"\nellipsoid = [4e-3, 8e-3, 4e-3]\n";
  expect_error(egg, {"ellipsoid", "a >= b >= c"});
}

// The shapes: a named polyhedron, the hull of vertices and a mesh file beside the scenario give the
// fill's pebbles (the unit cube all three ways), scaled by size.
TEST(ClumpScenario, ShapesAndMeshFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "hilldem_clump_scenario_mesh";
  std::filesystem::create_directories(dir / "shapes");
  {
    std::ofstream obj(dir / "shapes" / "cube.obj");
    obj << "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n"
           "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n"
           "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  }
  const std::string shape_keys = "count = 6\nsmallest_ratio = 0.4\nsize = 8e-3\n";
  const std::string text = kHead + "[[clump_template]]\nname = \"a\"\nmaterial = \"granite\"\npolyhedron = \"cube\"\n" + shape_keys +
                           "[[clump_template]]\nname = \"b\"\nmaterial = \"granite\"\nmesh = \"shapes/cube.obj\"\n" + shape_keys +
                           "[[clump_template]]\nname = \"c\"\nmaterial = \"granite\"\nvertices = [[-0.5, -0.5, -0.5], [0.5, -0.5, -0.5], "
                           "[-0.5, 0.5, -0.5], [0.5, 0.5, -0.5], [-0.5, -0.5, 0.5], [0.5, -0.5, 0.5], [-0.5, 0.5, 0.5], [0.5, 0.5, 0.5]]\n" +
                           shape_keys;
  std::string clumps;
  for (int j = 0; j < 3; ++j)
    clumps += "[[clump]]\ntemplate = \"" + std::string(1, static_cast<char>('a' + j)) + "\"\nfirst_id = " + std::to_string(10 * (j + 1)) +
              "\nposition = [0.0, " + std::to_string(0.03 * (j + 1)) + ", 0.0]\n";
  const Scenario sc = load_scenario(text + clumps, (dir / "case.toml").string());
  FillParams f;
  f.count = 6;
  f.smallest_ratio = 0.4;
  const ClumpTemplate expect = make_template(fill_shape(MeshShape(aggregate_polyhedron("cube")), f).pebbles, 2650.0).scaled(8e-3);
  ASSERT_EQ(expect.pebbles.size(), 6u);
  const ClumpPebbles& p = sc.sim.clumps.pebbles;
  ASSERT_EQ(sc.sim.clumps.size(), 3u);
  ASSERT_EQ(p.size(), 18u);
  EXPECT_EQ(sc.sim.balls.size(), 1u + 18u);
  // (each pebble's distance from the centre of mass and its radius: the cube's fill is nearly
  // isotropic, so the principal frame is not compared)
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_NEAR(norm(p.body_position[k]), norm(expect.pebbles.position[k % 6]), 1e-15) << k;
    EXPECT_NEAR(p.radius[k], expect.pebbles.radius[k % 6], 1e-15) << k;
  }
  EXPECT_NEAR(sc.sim.clumps.state.mass[1], 2650.0 * std::numbers::pi / 6 * 512e-9, 1e-12 * expect.mass);
  // errors name the key and the file
  const std::string bad = kHead + "[[clump_template]]\nname = \"m\"\nmaterial = \"granite\"\nmesh = \"shapes/none.stl\"\n";
  expect_error(bad, {"mesh", "none.stl", "cannot open"});
  const std::string two = kHead + "[[clump_template]]\nname = \"m\"\nmaterial = \"granite\"\npolyhedron = \"cube\"\nellipsoid = [1.0, 1.0, 1.0]\n";
  expect_error(two, {"exactly one of"});
  const std::string name = kHead + "[[clump_template]]\nname = \"m\"\nmaterial = \"granite\"\npolyhedron = \"sphere\"\n";
  expect_error(name, {"polyhedron", "rock"});
  const std::string fid = kHead + "[[clump_template]]\nname = \"m\"\nmaterial = \"granite\"\npolyhedron = \"cube\"\nfidelity = 1.5\n";
  expect_error(fid, {"fidelity", "(0, 1]"});
}

}  // namespace
}  // namespace hilldem
