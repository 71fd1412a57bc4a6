// Clump templates (issue 32): a rigid set of overlapping pebbles and its mass properties. The union
// of the pebbles counts each point once: its volume, centre of mass and inertia tensor come from the
// closed form for one or two pebbles (exact), from column integration for more (accuracy below), or
// from the user. The template is stored in its principal frame, as PFC does: pebble positions are
// relative to the centre of mass along the principal axes, so the inertia tensor is diagonal.
// docs/clumps.md has the equations and the measured accuracies.
#pragma once

#include <vector>

#include "hilldem/core/quaternion.hpp"

namespace hilldem {

// Pebbles as plain arrays: centres [m] in some frame, radii [m] > 0.
struct Pebbles {
  std::vector<Vec3> position;
  std::vector<double> radius;
  std::size_t size() const { return radius.size(); }
};

// The geometric moments of a solid about the frame's origin: V = ∫dV [m³], first moment ∫r dV [m⁴],
// second moment S = ∫ r rᵀ dV [m⁵]. They add for disjoint solids.
struct GeometricMoments {
  double volume = 0.0;
  Vec3 first;
  Mat3 second;
};
GeometricMoments operator+(const GeometricMoments& a, const GeometricMoments& b);
// A solid sphere of radius r [m] centred at c [m].
GeometricMoments sphere_moments(const Vec3& c, double r);
// The union of the pebbles in closed form: one pebble; two pebbles, apart, overlapping (each sphere
// cut by the plane of their intersection circle) or one inside the other. Throws std::invalid_argument
// for more than two.
GeometricMoments union_moments_exact(const Pebbles& p);
// Default columns across the wider of the x and y extents for union_moments_columns: ≤ 1e-3
// relative on the volume and the moments of inertia of a sphere (measured: docs/clumps.md).
inline constexpr int kDefaultColumns = 128;
// The union of any pebbles by column integration: a grid of n columns across the wider of the x,
// y extents of the pebbles' bounding box; in each column (the cell's centre) the union of the pebbles'
// chords along z is found exactly and its moments integrated exactly in z; the columns are summed
// with the cell's area (the midpoint rule in x and y, with the exact cell integral of x² and y²).
// The error comes from the surface's slope within a cell and falls about as n^-2 (measured).
GeometricMoments union_moments_columns(const Pebbles& p, int n = kDefaultColumns);

// The inertia tensor [m⁵, or kg m² times density] about the centroid: ∫ (|r−c|² 1 − (r−c)(r−c)ᵀ) dV.
Mat3 central_inertia(const GeometricMoments& g);

enum class MassMethod { Exact, Columns, User };

// What a clump's size [m] is: the diameter of the sphere of equal volume, (6V/π)^(1/3) (the
// default, and what a grading's sizes mean unless stated otherwise), or the diameter of the
// smallest sphere about the centre of mass that holds every pebble, 2 max_k(|p_k| + r_k).
enum class SizeMeasure { EqualVolumeDiameter, EnclosingDiameter };

struct ClumpTemplate {
  // Pebbles in the principal frame: centres [m] relative to the centre of mass, radii [m].
  Pebbles pebbles;
  double density = 0.0;     // ρ [kg/m³]
  double volume = 0.0;      // V [m³], of the union
  double mass = 0.0;        // ρ V [kg]
  Vec3 principal_inertia;   // I1 ≤ I2 ≤ I3 [kg m²] about the centre of mass
  // Where the principal frame sits in the frame the pebbles were given in: its origin (the centre of
  // mass) [m] and the rotation from it to that frame (columns of its matrix: the principal axes).
  Vec3 centre_of_mass;
  Quat orientation;
  MassMethod method = MassMethod::Exact;
  int columns = 0;  // n of the column integration (method Columns)

  // The diameter of the sphere of equal volume, (6V/π)^(1/3) [m]: the clump's size.
  double equal_volume_diameter() const;
  // The template scaled by factor s [-] about its centre of mass: lengths s, V and m s³, I s⁵.
  ClumpTemplate scaled_by(double s) const;
  // The size [m] by measure.
  double size(SizeMeasure measure = SizeMeasure::EqualVolumeDiameter) const;
  // The template scaled so that its size by measure is size [m] (the size a grading draws).
  ClumpTemplate scaled(double size, SizeMeasure measure = SizeMeasure::EqualVolumeDiameter) const;
  // The template turned by q about the origin of the frame its pebbles were given in (its orientation
  // and centre of mass turn): the orientation a clump made from it starts with. Mass properties
  // unchanged.
  ClumpTemplate rotated(const Quat& q) const;
  // Pebble k's centre [m] in the frame the pebbles were given in (rotated/translated as above).
  Vec3 reference_position(std::size_t k) const;
};

// A template from pebbles (any frame) and ρ [kg/m³]: exact for one or two pebbles, else column
// integration with n columns. Throws InputError for no pebbles, a radius ≤ 0, ρ ≤ 0 or n < 8.
ClumpTemplate make_template(const Pebbles& p, double density, int n = kDefaultColumns);
// Column integration whatever the pebble count (to compare it with the closed form).
ClumpTemplate make_template_columns(const Pebbles& p, double density, int n);
// From the user: volume [m³], centre of mass [m] and inertia tensor about it [kg m²] (symmetric,
// positive definite), in the pebbles' frame.
ClumpTemplate make_template_user(const Pebbles& p, double density, double volume, const Vec3& centre_of_mass,
                                 const Mat3& inertia);

}  // namespace hilldem
