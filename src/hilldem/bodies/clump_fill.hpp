// Sphere filling of shapes for clump templates (issue 32): one method for every shape — ellipsoids,
// polyhedra and triangle meshes (bodies/clump_mesh.hpp). docs/clumps.md, "Shapes", has the method,
// its parameters and the measured fidelities.
#pragma once

#include "hilldem/bodies/clump_template.hpp"

namespace hilldem {

// A solid the fill can sample: its bounding box [m], its volume [m³] and the distance [m] from a
// point to its surface.
class FillShape {
 public:
  virtual ~FillShape() = default;
  virtual Vec3 box_min() const = 0;
  virtual Vec3 box_max() const = 0;
  virtual double volume() const = 0;
  // The distance [m] from x to the surface when x is inside (the radius of the largest sphere about x
  // in the shape); 0 or less when x is on the surface or outside.
  virtual double inner_distance(const Vec3& x) const = 0;
};

// The ellipsoid x²/a² + y²/b² + z²/c² ≤ 1 with semi-axes a ≥ b ≥ c > 0 [m]; the distance to its
// surface is exact (the closest point by bisection on the Lagrange parameter, with the cases of a
// zero coordinate handled apart: D. Eberly, "Distance from a Point to an Ellipse, an Ellipsoid, or a
// Hyperellipsoid", Geometric Tools, 2013). Throws InputError for unordered or non-positive axes.
class EllipsoidShape final : public FillShape {
 public:
  EllipsoidShape(double a, double b, double c);
  Vec3 box_min() const override { return {-a_, -b_, -c_}; }
  Vec3 box_max() const override { return {a_, b_, c_}; }
  double volume() const override;
  double inner_distance(const Vec3& x) const override;

 private:
  double a_, b_, c_;
};

// The fill's parameters. The method (docs/clumps.md): a cubic lattice of `resolution` points across
// the longest extent of the bounding box, centred on its centre (so a symmetric shape's centre is a
// lattice point); every lattice point inside the shape is a sample of its volume and a candidate
// pebble centre, with radius its distance to the surface (a point of the medial region, the pebble
// touching the surface). Candidates smaller than smallest_ratio × the largest candidate's radius are
// dropped. Pebbles are chosen greedily, each the candidate covering the most samples not yet covered
// (ties: the lowest lattice index), until `count` pebbles are chosen or the covered fraction of the
// samples reaches `fidelity` or no candidate adds a sample. Gains only fall as pebbles are added, so
// the greedy choice is evaluated lazily (each candidate's gain recounted only when it could be the
// best), with the same result as the plain greedy.
struct FillParams {
  int count = 10;               // the most pebbles [-], ≥ 1
  double smallest_ratio = 0.5;  // smallest pebble's radius / the largest's [-], in (0, 1]
  double fidelity = 0.98;       // target union volume / shape volume [-], in (0, 1]
  int resolution = 41;          // lattice points across the longest extent [-], in [9, 301]
};

struct FillResult {
  Pebbles pebbles;         // centres [m] (lattice points) and radii [m], in the order chosen
  double sample_fidelity;  // covered samples / samples inside [-]: the lattice's estimate of the fidelity
};

// Fills the shape. A sphere (an ellipsoid a = b = c) is one pebble, the sphere itself. Throws
// InputError for parameters out of range or a shape with no lattice point inside.
FillResult fill_shape(const FillShape& shape, const FillParams& params);

}  // namespace hilldem
