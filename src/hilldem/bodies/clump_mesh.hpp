// Closed triangle meshes as shapes for the sphere fill (issue 32, bodies/clump_fill.hpp): read from
// STL (ASCII or binary) or OBJ, built as the convex hull of vertices, and a few named aggregate
// polyhedra. docs/clumps.md, "Shapes".
#pragma once

#include <array>
#include <string>
#include <vector>

#include "hilldem/bodies/clump_fill.hpp"

namespace hilldem {

// Vertices [m] and triangles (vertex indices, counter-clockwise seen from outside after
// closed_mesh()).
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// The mesh checked closed and oriented outward: every edge shared by exactly two triangles that run
// along it in opposite directions, no triangle of zero area; a mesh whose signed volume is negative
// (oriented inward) is turned over. `source` names it in errors, which say the triangle (0-based, in
// the file's order) and the fault. Throws InputError.
TriangleMesh closed_mesh(TriangleMesh mesh, const std::string& source);

// Reads a mesh file by its extension: .stl (binary when its size is 84 + 50 n bytes for the n
// triangles its header gives, else ASCII starting with "solid"), or .obj (v and f lines; faces of
// more than three vertices as fans; negative indices count back; vt, vn, g, o, s, usemtl, mtllib
// and comments skipped). STL vertices are joined where their coordinates are equal. Coordinates are
// taken in metres. Errors name the file and the line (ASCII) or triangle (binary). The result is
// closed_mesh()'s.
TriangleMesh read_mesh(const std::string& path);

// The convex hull of the points [m] (4 to 200, not all on one plane), its faces split into fans of
// triangles. Throws InputError.
TriangleMesh convex_hull(const std::vector<Vec3>& points);

// Named aggregate polyhedra [m] (convex hulls of their vertices): "cube" (edge 1), "prism" (2 × 1 ×
// 1, an elongated particle: length / width 2), "slab" (1 × 1 × 0.33, a flat particle: thickness /
// width 1/3), "rock" (an irregular convex polyhedron of 12 vertices within about 1.9 × 1.5 × 1.2,
// like a crushed stone). Throws InputError naming the known names.
TriangleMesh aggregate_polyhedron(const std::string& name);
inline constexpr const char* kAggregatePolyhedra = "cube, prism, slab, rock";

// A closed, outward mesh as a fill shape: the distance to its surface is the least distance to its
// triangles (the closest point on each, Ericson, Real-Time Collision Detection, §5.1.5), inside
// where the winding number (the triangles' solid angles over 4π, Van Oosterom & Strackee, IEEE
// Trans. Biomed. Eng. 30, 125, 1983) exceeds 1/2; its volume by the divergence theorem, Σ v0 · (v1 ×
// v2) / 6. A point within 1e-12 of its bounding box's diagonal of the surface counts as on it (distance
// 0). Cost per point: one pass over the triangles.
class MeshShape final : public FillShape {
 public:
  explicit MeshShape(TriangleMesh mesh);
  Vec3 box_min() const override { return lo_; }
  Vec3 box_max() const override { return hi_; }
  double volume() const override { return volume_; }
  double inner_distance(const Vec3& x) const override;

 private:
  TriangleMesh mesh_;
  Vec3 lo_, hi_;
  double volume_ = 0.0;
};

// The signed volume [m³] of a closed mesh, Σ v0 · (v1 × v2) / 6 (positive when oriented outward).
double mesh_volume(const TriangleMesh& mesh);

}  // namespace hilldem
