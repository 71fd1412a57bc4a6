#include "hilldem/io/scenario_clumps.hpp"

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "hilldem/bodies/clump_fill.hpp"
#include "hilldem/bodies/clump_mesh.hpp"
#include "hilldem/core/error.hpp"

namespace hilldem {

ClumpTemplate read_clump_template_shape(TableReader& t, double density) {
  const char* kShapes[] = {"centres", "ellipsoid", "polyhedron", "vertices", "mesh"};
  int shapes = 0;
  for (const char* k : kShapes) shapes += t.has(k);
  if (t.has("radii") && !t.has("centres")) t.fail("radii", "needs 'centres' [m] beside it");
  if (shapes != 1)
    t.fail(shapes == 0 ? "centres" : "mesh",
           "needs exactly one of: 'centres' with 'radii' (the pebbles), or a shape to fill: 'ellipsoid', 'polyhedron', 'vertices' or 'mesh'");
  const bool listed = t.has("centres");
  const char* shape_key = "centres";
  for (const char* k : kShapes)
    if (t.has(k)) shape_key = k;
  Pebbles p;
  if (listed) {
    p.position = t.vec3_list("centres", "[m]");
    p.radius = t.reals("radii", Range::open(0.0, 1e3), "[m]");
    if (p.radius.size() != p.position.size() || p.radius.empty())
      t.fail("radii", "needs one radius per centre (" + std::to_string(p.position.size()) + " centres, " +
                          std::to_string(p.radius.size()) + " radii)");
    if (p.radius.size() > 10000) t.fail("radii", "at most 10000 pebbles in one template");
  } else {
    // A shape filled with pebbles (bodies/clump_fill.hpp): the shape, then the fill's parameters.
    std::unique_ptr<FillShape> shape;
    try {
      if (t.has("ellipsoid")) {
        const Vec3 abc = t.vec3("ellipsoid", std::nullopt, Range::open(0.0, 1e3), "[m] (semi-axes a >= b >= c)");
        if (!(abc.x >= abc.y && abc.y >= abc.z)) t.fail("ellipsoid", "semi-axes must be ordered a >= b >= c [m]");
        shape = std::make_unique<EllipsoidShape>(abc.x, abc.y, abc.z);
      } else if (t.has("polyhedron")) {
        const std::string name = t.choice("polyhedron", std::nullopt, {"cube", "prism", "slab", "rock"});
        shape = std::make_unique<MeshShape>(aggregate_polyhedron(name));
      } else if (t.has("vertices")) {
        shape = std::make_unique<MeshShape>(convex_hull(t.vec3_list("vertices", "[m]")));
      } else {
        const std::filesystem::path file = std::filesystem::path(t.file()).parent_path() / t.string("mesh", std::nullopt);
        shape = std::make_unique<MeshShape>(read_mesh(file.string()));
      }
    } catch (const InputError& e) {
      t.fail(shape_key, e.what());
    }
    FillParams f;
    f.count = static_cast<int>(t.integer("count", f.count, 1, 1000));
    f.smallest_ratio = t.real("smallest_ratio", f.smallest_ratio, Range::open_closed(0.0, 1.0), "[-]");
    f.fidelity = t.real("fidelity", f.fidelity, Range::open_closed(0.0, 1.0), "[-]");
    f.resolution = static_cast<int>(t.integer("resolution", f.resolution, 9, 301));
    try {
      p = fill_shape(*shape, f).pebbles;
    } catch (const InputError& e) {
      t.fail(shape_key, e.what());
    }
  }
  const int columns = static_cast<int>(t.integer("columns", kDefaultColumns, 8, 4096));
  const int user = t.has("volume") + t.has("centre_of_mass") + t.has("inertia");
  if (user != 0 && user != 3)
    t.fail(t.has("volume") ? (t.has("inertia") ? "centre_of_mass" : "inertia") : "volume",
           "user mass properties need all three keys: volume [m^3], centre_of_mass [m], inertia [kg m^2]");
  ClumpTemplate tmpl;
  try {
    if (user == 3) {
      const double v = t.real("volume", std::nullopt, Range::positive(), "[m^3]");
      const Vec3 c = t.vec3("centre_of_mass", std::nullopt, Range::any(), "[m]");
      const std::vector<double> in = t.reals("inertia", Range::any(), "[kg m^2] (Ixx, Iyy, Izz, Ixy, Ixz, Iyz)");
      if (in.size() != 6) t.fail("inertia", "needs six values [kg m^2]: Ixx, Iyy, Izz, Ixy, Ixz, Iyz");
      Mat3 j = Mat3::diagonal({in[0], in[1], in[2]});
      j(0, 1) = j(1, 0) = in[3];
      j(0, 2) = j(2, 0) = in[4];
      j(1, 2) = j(2, 1) = in[5];
      tmpl = make_template_user(p, density, v, c, j);
    } else {
      tmpl = make_template(p, density, columns);
    }
  } catch (const InputError& e) {
    t.fail(listed ? "radii" : shape_key, e.what());
  }
  if (t.has("size")) {
    const double size = t.real("size", std::nullopt, Range::open(0.0, 1e3), "[m] (equal-volume diameter)");
    try {
      tmpl = tmpl.scaled(size);
    } catch (const InputError& e) {
      t.fail("size", e.what());  // (a template too small for its scale factor to be finite)
    }
  }
  return tmpl;
}

void read_clump_placement(TableReader& t, ClumpInit& c) {
  c.position = t.vec3("position", std::nullopt, Range::open(-1e6, 1e6), "[m]");
  if (t.has("orientation")) {
    const std::vector<double> q = t.reals("orientation", Range::closed(-1e6, 1e6), "[-] (w, x, y, z)");
    const double n2 = q.size() == 4 ? q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] : 0.0;
    if (q.size() != 4 || !(n2 > 1e-300)) t.fail("orientation", "needs a non-zero quaternion [w, x, y, z] (it is normalised)");
    c.orientation = normalized(Quat{q[0], q[1], q[2], q[3]});
  }
  c.velocity = t.vec3("velocity", Vec3{}, Range::any(), "[m/s]");
  c.spin = t.vec3("spin", Vec3{}, Range::any(), "[rad/s]");
}

}  // namespace hilldem
