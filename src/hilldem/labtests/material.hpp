// Class 5 materials of the memo (Table 7, docs/spec/hill-model.md §5.3) and the contact-model
// assignment tables of genesis: the frictionless packing table (the material's own grain-grain model,
// μ_CA = 0), and the final table that installs the material (hill or linear between grains, linear to
// the vessel walls).
#pragma once

#include <cstdint>
#include <string>

#include "hilldem/engine/simulation.hpp"

namespace hilldem {

enum class GrainModel { Linear, Hill };
const char* to_string(GrainModel m);  // "linear", "hill"

// Grain-grain properties (Table 7). The grains are granite spheres: density, E and ν are ball
// properties (the hill model reads E and ν from the balls; the linear model ignores them).
struct Class5Material {
  GrainModel model = GrainModel::Hill;
  double density = 2650.0;      // ρ_g [kg/m³]
  double young_mod = 29e9;      // E_g [Pa] (hill)
  double pois_ratio = 0.15;     // ν_g [-] (hill)
  double damp_con = 0.0;        // γ_h [-] (hill)
  double suction = 20e3;        // ψ [Pa] (hill; acts only on wet contacts)
  double linear_emod = 500e6;   // E* [Pa] (linear)
  double linear_kratio = 1.5;   // κ* [-] (linear)
  double fric = 0.4;            // μ [-] (both)
  std::string name(const std::string& grading) const;  // "C5b_Hill"
};

// Grain-wall contacts: linear, E* = 500 MPa (memo); κ* = 1 and frictionless [ours, lab-tests.md §2].
struct WallContact {
  double emod = 500e6;  // E* [Pa]
  double kratio = 1.0;  // κ* [-]
  double fric = 0.0;    // μ [-]
};

// Grain-grain contacts during packing (lab-tests.md §3.2): each material is packed with its own
// model at the packing friction μ_CA = 0 (Table 7) — hill contacts between hill grains (Hertz from
// the grains' E and ν, damping γ_h, dry), linear contacts (E*, κ*) between linear grains.
// Finalization then installs the material's table, which restores the friction μ. The shared
// linear packing (both materials packed with linear contacts, one packed
// specimen per grading) is `model = GrainModel::Linear` for either material: a deviation from the
// memo, kept as an option (StudySettings::pack_linear, `hilldem triaxial --pack-linear`).
struct PackingContact {
  GrainModel model = GrainModel::Hill;  // grain-grain model during packing
  double emod = 500e6;   // E* [Pa] (linear)
  double kratio = 1.5;   // κ* [-] (linear)
  double damp_con = 0.0; // γ_h [-] (hill)
  double fric = 0.0;     // μ_CA [-]
};

// Group names used by the tables: every grain is in "grain", the vessel walls in "vessel".
inline constexpr const char* kGrainGroup = "grain";
inline constexpr const char* kVesselGroup = "vessel";

ModelTable packing_table(Simulation& sim, const PackingContact& grains, const WallContact& walls);
ModelTable material_table(Simulation& sim, const Class5Material& m, const WallContact& walls);

// Installs a new assignment table and re-assigns every existing contact through it (PFC's
// `contact model ... ` over all contacts): the contact store is emptied and rebuilt from the table at
// the current positions. Shear history is lost; call this when it is zero (frictionless packing).
void install_table(Simulation& sim, ModelTable table);

// Sets density, E and ν of every ball to the material's (mass and inertia updated).
void apply_grain_properties(Simulation& sim, const Class5Material& m);

}  // namespace hilldem
